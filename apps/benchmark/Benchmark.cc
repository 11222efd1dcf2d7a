// vdbhair_benchmark: vdbhair against its nearest OpenVDB peer, on the same input in one run.
//
//   field estimation (Wang et al. Eq. 9, 2 iterations)  vs  points::rasterizeTrilinear of
//                                                           per-vertex tangents (one pass)
//   streamline tracing (forward Euler)                  vs  tools::VelocityIntegrator, RK1,
//                                                           same step, same roots, one per thread
//   helicoid tracing and p-helicoid fitting (Piuze et al. 2011, §3-5): no OpenVDB peer; fitting
//   reports error, pieces, compression and strands/s on real strands (straight, wavy, curly,
//   short) at 30 vertices and at full resolution
//   follicles (Witkin & Heckbert repulsion on the    vs  tools::UniformPointScatter in the
//   scalp level set, `vdbhair roots`)                    zero-crossing voxels + projection
//   end to end (--sections e2e, opt-in): the         vs  vdbhair_peer (Peer.cc): the same jobs
//   `vdbhair` verbs info, field, retrace, refine,        with stock OpenVDB and an ifstream
//   refine --mode field, --help as processes, as a       reader, as processes on the same files
//   user times them
//   scale (--sections scale, opt-in): `vdbhair refine` of 1,000,000 strands x 32 vertices grown by
//   `vdbhair grow`: time, peak memory and refine's own memory estimate
//
// Inputs: a real hairstyle from ../shared/data and a 100,000-strand, 64-vertex hairstyle made
// deterministically from the bundled one (jittered copies), and, for reference, as many strands
// in a bundle whose field fits in the cache (the tracers' own work, without a large field's cache
// misses). Speed is measured here, never in tests.
//
// This file reads the options and runs the sections asked for (Sections.h); Harness.h holds the
// timing and process machinery they share.
#include "Sections.h"

#include <vdbhair/io/VdbFile.h>

#include <CLI/CLI.hpp>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <memory>

using namespace vdbhair;
using namespace vdbhair::bench;

int main(int argc, char** argv)
{
    CLI::App app{"vdbhair_benchmark: vdbhair against OpenVDB's nearest peers on the same input, in one run"};
    std::string source = VDBHAIR_SOURCE_DIR;
    std::string data = source + "/../shared/data";
    std::size_t strands = 100000, vertices = 64;
    int reps = 3, threads = 0;
    double voxelSize = 0.0;
    std::string sections = "field,helicoids,helicoid-fields,fit,roots,interpolate,groom,compare,synth";
    int e2eRuns = 5;
    std::string e2eCommand;
    std::size_t fitStrands = 2000;
    std::vector<std::size_t> rootCounts{10000, 100000};
    std::string rootHeads;
    std::vector<std::size_t> scaleStrands{1000000};
    std::size_t groomStrands = 1000000;
    std::size_t compareStrands = 100000;
    app.add_option("--data", data, "The shared data folder (real hairstyles)")->capture_default_str();
    app.add_option("--scene", source, "The vdbhair checkout (for scenes/default)")->capture_default_str();
    app.add_option("--strands", strands, "Strands of the synthetic hairstyle")->capture_default_str();
    app.add_option("--vertices", vertices, "Vertices per synthetic strand")->capture_default_str();
    app.add_option("--reps", reps, "Repetitions (the best time is reported)")->capture_default_str();
    app.add_option("--threads", threads, "Threads (0: all cores)")->capture_default_str();
    app.add_option("--voxel-size", voxelSize, "Voxel size (0: vdbhair's suggestion for each input)");
    app.add_option("--sections", sections, "Sections to run: field, helicoids, helicoid-fields, fit, roots, interpolate, groom, compare, synth, "
                                           "and e2e (the command and a stock-OpenVDB peer as processes) and scale (refine of 1,000,000 strands x 32 vertices: "
                                           "time, peak memory, the memory estimate), both opt-in (comma-separated)")->capture_default_str();
    app.add_option("--e2e-runs", e2eRuns, "Counted runs of each command in the e2e section (after one warm-up)")->capture_default_str();
    app.add_option("--e2e-command", e2eCommand, "The vdbhair command the e2e section runs (default: the one built next to this program; "
                                                "another build's, for before and after)");
    app.add_option("--fit-strands", fitStrands, "Most strands per fitting row (an evenly strided subset; 0: all)")->capture_default_str();
    app.add_option("--root-counts", rootCounts, "Root counts of the follicle rows")->delimiter(',')->capture_default_str();
    app.add_option("--root-heads", rootHeads, "Only the shared heads whose path contains this");
    app.add_option("--groom-strands", groomStrands, "New strands of the groom section (from 1,000 guides)")->capture_default_str();
    app.add_option("--compare-strands", compareStrands, "Strands of each hairstyle of the compare section (100 vertices each)")->capture_default_str();
    app.add_option("--scale-strands", scaleStrands, "Strand counts of the scale section (32 vertices each)")->delimiter(',')->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    auto wants = [&](const char* s) { return ("," + sections + ",").find("," + std::string(s) + ",") != std::string::npos; };
    std::unique_ptr<tbb::global_control> control;
    if (threads > 0) control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    initializeOpenVdb();
    std::printf("vdbhair_benchmark: %d thread(s), best of %d\n", threads > 0 ? threads : int(tbb::this_task_arena::max_concurrency()), reps);

    if (wants("field")) benchmarkFields(data, source, strands, vertices, voxelSize, reps);
    if (wants("helicoids")) benchmarkHelicoids(source, reps);
    if (wants("helicoid-fields")) benchmarkHelicoidFields(data, source);
    if (wants("fit")) benchmarkFitting(data, fitStrands, reps);
    if (wants("roots")) benchmarkRoots(data, rootCounts, rootHeads);
    if (wants("interpolate")) benchmarkInterpolation(reps);
    if (wants("groom")) benchmarkGroom(reps, groomStrands);
    if (wants("compare")) benchmarkCompare(reps, compareStrands);
    if (wants("synth")) benchmarkSynthesis(data, source, strands, vertices);
    if (wants("e2e")) benchmarkEndToEnd(source, strands, vertices, std::max(1, e2eRuns), e2eCommand);
    if (wants("scale")) benchmarkScale(source, scaleStrands, e2eCommand);
    return 0;
}
