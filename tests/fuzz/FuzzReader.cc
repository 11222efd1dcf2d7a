// libFuzzer harness for one vdbhair reader (issue 22). tests/fuzz/CMakeLists.txt links this one
// object into one executable per reader, fuzz_<reader> (fuzz_hair, fuzz_ply, ...): the reader is
// chosen by the executable's name.
//
// Every input is written to a file (the readers take paths, as the command does) and read. A
// reader may succeed or throw vdbhair::Error (a typed, one-line error); anything else - a crash,
// a sanitizer report, another exception, a hang (-timeout) or an allocation beyond
// -malloc_limit_mb - is a finding.
#include <vdbhair/Exceptions.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/AbcFile.h>
#include <vdbhair/io/BinFile.h>
#include <vdbhair/io/ConvdataFile.h>
#include <vdbhair/io/DataFile.h>
#include <vdbhair/io/HairFile.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/ObjFile.h>
#include <vdbhair/io/PlyFile.h>
#include <vdbhair/io/TfxFile.h>
#include <vdbhair/io/UsdFile.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbPoints.h>
#include <vdbhair/io/VdbStrands.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace {

std::string sReader;  // "hair", "ply", ... from the executable's name
std::string sPath;    // where each input is written

/// The file extension the reader expects (the mesh reader picks PLY or OBJ by the input).
std::string extensionFor(const std::uint8_t* data, std::size_t size)
{
    if (sReader == "mesh") return size >= 3 && std::string(reinterpret_cast<const char*>(data), 3) == "ply" ? ".ply" : ".obj";
    if (sReader == "scene") return ".json";
    return "." + sReader;
}

void readOnce(const std::string& path)
{
    using namespace vdbhair;
    ReadOptions opts;
    ReadReport report;
    if (sReader == "hair") readHair(path, opts, &report);
    else if (sReader == "data") readData(path, opts, &report);
    else if (sReader == "bin") readBin(path, opts, &report);
    else if (sReader == "obj") {
        readObj(path, opts, &report);
        ReadOptions samples;  // free-form curves at an explicit count, as well as automatic (issue 50)
        samples.curveSamples = 9;
        readObj(path, samples, &report);
    }
    else if (sReader == "ply") {
        try {
            readPly(path, opts, &report);
        } catch (const vdbhair::Error&) {
            // A PLY of points only (issue 50) is read again in runs of 4 points.
        }
        ReadOptions runs;
        runs.pointsPerStrand = 4;
        readPly(path, runs, &report);
    }
    else if (sReader == "tfx") readTfx(path, opts, &report);
    else if (sReader == "convdata") readConvdata(path, opts, &report);
    else if (sReader == "usda") readUsda(path, opts, &report);
    else if (sReader == "abc") {
        readAbc(path, opts, &report);
        ReadOptions samples;  // cubic curves at an explicit count too
        samples.curveSamples = 5;
        readAbc(path, samples, &report);
    }
    else if (sReader == "vdb") {
        // Every grid of any type (fields, level sets, points), as `info`, `inspect` and the field
        // verbs read them, and the points' columns as Python's Grid.point_attributes() reads them
        // (within the file's read budget: uniform arrays may stand for more points than memory
        // holds, which the function checks against the machine's memory, not libFuzzer's limit);
        // then the strands reader on the same bytes.
        try {
            for (const openvdb::GridBase::Ptr& grid : readVdbGrids(path, path)) {
                try {
                    withinReadBudget(path, path, [&] { pointColumns(*grid); });
                } catch (const vdbhair::Error&) {
                }
            }
        } catch (const vdbhair::Error&) {
        }
        readVdbStrands(path, opts, &report);
    }
    else if (sReader == "mesh") readTriangleMesh(path);
    else if (sReader == "scene") readScene(path);
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv)
{
    const std::string self = *argc > 0 ? (*argv)[0] : "";
    const std::size_t at = self.rfind("fuzz_");
    sReader = at == std::string::npos ? "" : self.substr(at + 5);
    const char* known[] = {"hair", "data", "bin", "obj", "ply", "tfx", "convdata", "usda", "abc", "vdb", "mesh", "scene"};
    bool ok = false;
    for (const char* k : known) ok = ok || sReader == k;
    if (!ok) {
        std::fprintf(stderr, "vdbhair fuzz: '%s' names no reader; run it as fuzz_<hair|data|bin|obj|ply|tfx|convdata|usda|abc|vdb|mesh|scene>\n", self.c_str());
        std::exit(2);
    }
    sPath = "/tmp/vdbhair-fuzz-" + sReader + "-" + std::to_string(::getpid());
    vdbhair::initializeOpenVdb();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string path = sPath + extensionFor(data, size);
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    try {
        readOnce(path);
    } catch (const vdbhair::Error&) {
        // A typed error with its one-line message: the reader did its job.
    }
    std::remove(path.c_str());
    return 0;
}
