// vdbhair_benchmark: vdbhair against its nearest OpenVDB peer, on the same input in one run.
//
//   field estimation (Wang et al. Eq. 9, 2 iterations)  vs  points::rasterizeTrilinear of
//                                                           per-vertex tangents (one pass)
//   streamline tracing (forward Euler)                  vs  tools::VelocityIntegrator, RK1,
//                                                           same step, same roots, one per thread
//
// Inputs: a real hairstyle from ../shared/data and a 100,000-strand, 64-vertex hairstyle made
// deterministically from the bundled one (jittered copies). Speed is measured here, never in tests.
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>

#include <CLI/CLI.hpp>

#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointRasterizeTrilinear.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tools/VelocityFields.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>

using namespace vdbhair;

namespace {

double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double peakMiB()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;
}

/// Best of @a reps runs of @a fn (seconds).
template<typename Fn>
double timeBest(int reps, Fn&& fn)
{
    double best = 1e30;
    for (int r = 0; r < reps; ++r) {
        const double t0 = now();
        fn();
        best = std::min(best, now() - t0);
    }
    return best;
}

/// @a count strands of @a vertices vertices: copies of @a base (resampled), each strand moved by a
/// seeded random offset (deterministic: seeded by the copy and strand index).
StrandSet jitteredCopies(const StrandSet& base, std::size_t count, std::size_t vertices, float jitter)
{
    const StrandSet b = resampleStrands(base, vertices);
    StrandSet out;
    out.reserve(count, count * vertices);
    std::normal_distribution<float> n(0.f, jitter);
    for (std::size_t i = 0; i < count; ++i) {
        const std::size_t src = i % b.numStrands();
        std::mt19937 rng(std::uint32_t(i * 2654435761u + 17u));
        const Vec3f d(n(rng), n(rng), n(rng));
        std::vector<Vec3f> pts(b.data(src), b.data(src) + vertices);
        for (Vec3f& p : pts) p += d;
        out.addStrand(pts);
    }
    return out;
}

struct Row
{
    std::string what;
    double ours, peer;
    std::string unit;
};

void benchmark(const std::string& name, const StrandSet& strands, double voxelSize, int reps)
{
    const std::size_t nS = strands.numStrands(), nV = strands.numVertices(), nSeg = nV - nS;
    std::printf("\n== %s: %zu strands, %zu vertices, %zu segments, voxel size %.4g ==\n", name.c_str(), nS, nV, nSeg, voxelSize);

    // --- vdbhair: robust field estimation (2 iterations).
    FieldParams fp;
    fp.voxelSize = voxelSize;
    fp.iterations = 2;
    TangentField field;
    const double tOurs = timeBest(reps, [&] { field = estimateTangentField(strands, fp); });
    const double memAfterOurs = peakMiB();

    // --- peer: rasterizeTrilinear of per-vertex tangents (points built first, not timed in the ratio).
    namespace pts = openvdb::points;
    const std::vector<Vec3f> tangents = computeTangents(strands);
    const openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(voxelSize);
    const double tb0 = now();
    const pts::PointAttributeVector<openvdb::Vec3f> pw(strands.positions);
    auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(pw, *xform);
    auto points = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, pw, *xform);
    pts::appendAttribute<openvdb::Vec3f>(points->tree(), "T");
    pts::populateAttribute(points->tree(), index->tree(), "T", pts::PointAttributeVector<openvdb::Vec3f>(tangents));
    const double tBuild = now() - tb0;
    openvdb::Vec3STree::Ptr splat;
    const double tPeer = timeBest(reps, [&] { splat = pts::rasterizeTrilinear<false, openvdb::Vec3f>(points->tree(), "T"); });

    std::printf("field estimation       vdbhair %.3f s (%.1f M segments/s, %llu voxels)   rasterizeTrilinear %.3f s (%.1f M points/s, %llu voxels)\n"
                "                       ratio peer/ours %.2fx for the splat alone; %.2fx counting the %.3f s to build the VDB points from the strands first\n",
                tOurs, double(nSeg) / tOurs / 1e6, (unsigned long long)field.tangent->activeVoxelCount(), tPeer,
                double(nV) / tPeer / 1e6, (unsigned long long)splat->activeVoxelCount(), tPeer / tOurs, (tPeer + tBuild) / tOurs, tBuild);

    // --- tracing through the same field, same roots, same step, forward Euler / RK1.
    TraceParams tp;
    tp.step = 0.5 * voxelSize;
    TraceStats stats;
    StrandSet traced;
    const double tTrace = timeBest(reps, [&] { traced = retraceStrands(strands, *field.tangent, tp, &stats); });
    const std::vector<float> lengths = strandLengths(strands);
    std::size_t peerSteps = 0;
    for (float L : lengths) peerSteps += std::size_t(std::ceil(double(L) / tp.step));
    const openvdb::Vec3SGrid& grid = *field.tangent;
    std::vector<openvdb::Vec3d> ends(nS);
    const double tPeerTrace = timeBest(reps, [&] {
        tbb::enumerable_thread_specific<openvdb::tools::VelocityIntegrator<openvdb::Vec3SGrid>> integrators(grid);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 64), [&](const tbb::blocked_range<std::size_t>& r) {
            auto& integ = integrators.local();
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                openvdb::Vec3d p(strands.root(i).x(), strands.root(i).y(), strands.root(i).z());
                const std::size_t n = std::size_t(std::ceil(double(lengths[i]) / tp.step));
                for (std::size_t k = 0; k < n; ++k) integ.rungeKutta<1>(tp.step, p);
                ends[i] = p;
            }
        });
    });
    const double oursRate = double(stats.steps) / tTrace, peerRate = double(peerSteps) / tPeerTrace;
    std::printf("tracing (Euler, step %.4g)  vdbhair %.3f s (%.1f M steps/s, %zu steps, %zu/%zu full length)   VelocityIntegrator %.3f s (%.1f M steps/s, %zu steps)   ratio ours/peer %.2fx steps/s\n",
                tp.step, tTrace, oursRate / 1e6, stats.steps, stats.fullLength, nS, tPeerTrace, peerRate / 1e6, peerSteps, oursRate / peerRate);
    std::printf("estimated + retraced   vdbhair %.3f s together\n", tOurs + tTrace);
    std::printf("peak memory            %.0f MiB after vdbhair's estimation, %.0f MiB at the end (process peak)\n", memAfterOurs, peakMiB());
}

/// Helicoid tracing speed: strands per second for a four-piece p-helicoid of 64 steps (one guide
/// and its wisps), and for the bundled default head scene.
void benchmarkHelicoids(const std::string& source, int reps)
{
    std::printf("\n== generalized helicoids (Piuze et al. 2011, Eq. 3; the paper: 0.7 ms a strand) ==\n");
    Scene scene;
    scene.seed = 1;
    scene.step = 4.0 / 64.0;
    SceneGuide g;
    g.frame = FrameD::fromTangentNormal(Vec3d(0, -1, 0), Vec3d(1, 0, 0));
    g.pieces = {{{6.0, 0.2, 0.6, 0.10}, 1.0, 0.0}, {{5.6, -0.2, 0.8, 0.12}, 1.0, 0.4},
                {{6.4, 0.1, 0.5, 0.09}, 1.0, 0.3}, {{6.0, 0.0, 0.7, 0.11}, 1.0, 0.5}};
    g.wisp = WispParams{99999, 0.05, 0.02};
    scene.guides.push_back(g);
    StrandSet s;
    const double t = timeBest(reps, [&] { s = growScene(scene); });
    std::printf("four-piece p-helicoid, 64 steps: %zu strands in %.3f s: %.2f us a strand (%.1f M strands/s, %.1f M steps/s)\n",
                s.numStrands(), t, t / double(s.numStrands()) * 1e6, double(s.numStrands()) / t / 1e6,
                double(s.numVertices() - s.numStrands()) / t / 1e6);
    const Scene head = readScene(source + "/scenes/default/head.json");
    const double th = timeBest(reps, [&] { s = growScene(head); });
    std::printf("default head scene: %zu strands, %zu vertices in %.3f s: %.2f us a strand\n", s.numStrands(), s.numVertices(), th,
                th / double(s.numStrands()) * 1e6);
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"vdbhair_benchmark: vdbhair against OpenVDB's nearest peers on the same input, in one run"};
    std::string source = std::filesystem::path(__FILE__).parent_path().parent_path().parent_path().string();
    std::string data = source + "/../shared/data";
    std::size_t strands = 100000, vertices = 64;
    int reps = 3, threads = 0;
    double voxelSize = 0.0;
    app.add_option("--data", data, "The shared data folder (real hairstyles)")->capture_default_str();
    app.add_option("--scene", source, "The vdbhair checkout (for scenes/default)")->capture_default_str();
    app.add_option("--strands", strands, "Strands of the synthetic hairstyle")->capture_default_str();
    app.add_option("--vertices", vertices, "Vertices per synthetic strand")->capture_default_str();
    app.add_option("--reps", reps, "Repetitions (the best time is reported)")->capture_default_str();
    app.add_option("--threads", threads, "Threads (0: all cores)")->capture_default_str();
    app.add_option("--voxel-size", voxelSize, "Voxel size (0: vdbhair's suggestion for each input)");
    CLI11_PARSE(app, argc, argv);
    std::unique_ptr<tbb::global_control> control;
    if (threads > 0) control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    initializeOpenVdb();
    std::printf("vdbhair_benchmark: %d thread(s), best of %d\n", threads > 0 ? threads : int(tbb::this_task_arena::max_concurrency()), reps);

    const std::string real = data + "/hair/cyhair/straight.hair";
    if (std::filesystem::exists(real)) {
        const StrandSet s = readStrands(real);
        benchmark("real: straight.hair (Cem Yuksel)", s, voxelSize > 0.0 ? voxelSize : suggestVoxelSize(s), reps);
    } else {
        std::printf("\n(skipped the real hairstyle: %s not found)\n", real.c_str());
    }
    const StrandSet base = readStrands(source + "/scenes/default/ponytail.hair");
    const StrandSet big = jitteredCopies(base, strands, vertices, 0.3f);
    benchmark("synthetic: jittered copies of the bundled ponytail", big, voxelSize > 0.0 ? voxelSize : suggestVoxelSize(big), reps);
    benchmarkHelicoids(source, reps);
    return 0;
}
