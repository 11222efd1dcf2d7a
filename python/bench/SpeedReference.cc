// The C++ side of python/bench/speed.py: reads a strand file and times the library calls the
// Python module wraps (read, estimateTangentField, retraceStrands), with the parameters the
// Python functions use by default, best of N. Prints one JSON object.
//   vdbhair_python_speed FILE VOXEL_SIZE REPS THREADS
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>

namespace {

template <typename F>
double timeBest(int reps, F&& f)
{
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < reps; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        f();
        best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    return best;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 5) {
        std::fprintf(stderr, "usage: vdbhair_python_speed FILE VOXEL_SIZE REPS THREADS\n");
        return 2;
    }
    const std::string path = argv[1];
    const double voxelSize = std::atof(argv[2]);
    const int reps = std::atoi(argv[3]), threads = std::atoi(argv[4]);
    std::unique_ptr<tbb::global_control> cap;
    if (threads > 0) cap = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    vdbhair::initializeOpenVdb();
    try {
        vdbhair::StrandSet strands;
        const double tRead = timeBest(reps, [&] { strands = vdbhair::readStrands(path); });
        vdbhair::FieldParams fp;
        fp.voxelSize = voxelSize;
        vdbhair::TangentField field;
        const double tField = timeBest(reps, [&] { field = vdbhair::estimateTangentField(strands, fp); });
        const vdbhair::TraceParams tp;
        vdbhair::StrandSet traced;
        const double tRetrace = timeBest(reps, [&] { traced = vdbhair::retraceStrands(strands, *field.tangent, tp); });
        std::printf("{\"strands\": %zu, \"vertices\": %zu, \"read\": %.6f, \"field\": %.6f, \"retrace\": %.6f}\n", strands.numStrands(),
                    strands.numVertices(), tRead, tField, tRetrace);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vdbhair_python_speed: %s\n", e.what());
        return 1;
    }
    return 0;
}
