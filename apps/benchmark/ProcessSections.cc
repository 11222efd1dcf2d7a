// The benchmark's sections that run the `vdbhair` command as processes (Sections.h): end to end
// against the stock-OpenVDB peer program (Peer.cc), and refine at scale.
#include "Harness.h"
#include "Sections.h"

#include <vdbhair/Quantile.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/JsonFile.h>
#include <vdbhair/io/StrandIO.h>

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace vdbhair::bench {

void benchmarkEndToEnd(const std::string& source, std::size_t strands, std::size_t vertices, int runs, std::string ours)
{
    const std::filesystem::path bin = std::filesystem::read_symlink("/proc/self/exe").parent_path();
    if (ours.empty()) ours = (bin / "vdbhair").string();
    const std::string peer = (bin / "vdbhair_peer").string();
    if (!std::filesystem::exists(ours) || !std::filesystem::exists(peer)) {
        std::printf("\n(skipped the end-to-end section: %s or %s not found)\n", ours.c_str(), peer.c_str());
        return;
    }
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("vdbhair_e2e_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    const std::string hair = (dir / "hair.data").string(), field = (dir / "field.vdb").string();
    char voxel[32];
    {
        // Freed before any child runs: a child's peak memory counts what it shares of this
        // process when it is forked.
        const StrandSet big = jitteredCopies(readStrands(source + "/scenes/default/ponytail.hair"), strands, vertices, 0.3f);
        writeStrands(hair, big);
        std::snprintf(voxel, sizeof voxel, "%.9g", suggestVoxelSize(big));
    }
    malloc_trim(0);
    runProcess({ours, "field", hair, "-o", field, "--voxel-size", voxel});  // the field both retraces follow
    std::printf("\n== end to end: %zu strands x %zu vertices (%.0f MB .data), voxel size %s, %d run(s) each, interleaved ==\n",
                strands, vertices, double(std::filesystem::file_size(hair)) / 1e6, voxel, runs);

    struct Verb
    {
        const char* name;
        std::vector<std::string> ours, peer;
    };
    auto out = [&](const char* name) { return (dir / name).string(); };
    const std::vector<Verb> verbs = {
        {"info", {ours, "info", hair}, {peer, "info", hair}},
        {"field", {ours, "field", hair, "-o", out("f_ours.vdb"), "--voxel-size", voxel},
         {peer, "field", hair, "-o", out("f_peer.vdb"), "--voxel-size", voxel}},
        {"retrace", {ours, "retrace", hair, "--field", field, "-o", out("r_ours.data")},
         {peer, "retrace", hair, "--field", field, "-o", out("r_peer.data")}},
        {"refine", {ours, "refine", hair, "-o", out("rf_ours.data"), "--voxel-size", voxel},
         {peer, "refine", hair, "-o", out("rf_peer.data"), "--voxel-size", voxel}},
        // The paper's refinement (Wang et al.: the field, then every strand retraced through it),
        // the same job as the peer's; the default (consistent) mode above does more.
        {"refine --mode field", {ours, "refine", hair, "-o", out("rff_ours.data"), "--voxel-size", voxel, "--mode", "field"},
         {peer, "refine", hair, "-o", out("rff_peer.data"), "--voxel-size", voxel}},
        {"--help", {ours, "--help"}, {peer, "--help"}},
    };
    std::printf("%-19s | %-32s | %-32s | %s\n", "verb", "vdbhair: wall, CPU, peak", "peer: wall, CPU, peak", "peer/vdbhair wall (CPU)");
    for (const Verb& v : verbs) {
        std::vector<double> wall[2], cpu[2], rss[2];
        int failed = 0;
        for (int r = -1; r < runs; ++r) {  // run -1: the warm-up (page cache, lazy binding), not counted
            for (int k = 0; k < 2; ++k) {
                const ProcessRun p = runProcess(k == 0 ? v.ours : v.peer);
                if (p.status != 0) ++failed;
                if (r < 0) continue;
                wall[k].push_back(p.wall);
                cpu[k].push_back(p.cpu);
                rss[k].push_back(p.peakMiB);
            }
        }
        char a[64], b[64];
        std::snprintf(a, sizeof a, "%7.3f s %7.3f s %6.0f MiB", median(wall[0]), median(cpu[0]), median(rss[0]));
        std::snprintf(b, sizeof b, "%7.3f s %7.3f s %6.0f MiB", median(wall[1]), median(cpu[1]), median(rss[1]));
        std::printf("%-19s | %-32s | %-32s | %.2fx (%.2fx)%s\n", v.name, a, b, median(wall[1]) / median(wall[0]),
                    median(cpu[1]) / median(cpu[0]), failed ? "   (some runs failed: exit status not 0)" : "");
        std::fflush(stdout);
    }
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
}

void benchmarkScale(const std::string& source, const std::vector<std::size_t>& sizes, std::string ours)
{
    const std::filesystem::path bin = std::filesystem::read_symlink("/proc/self/exe").parent_path();
    if (ours.empty()) ours = (bin / "vdbhair").string();
    if (!std::filesystem::exists(ours)) {
        std::printf("\n(skipped the scale section: %s not found)\n", ours.c_str());
        return;
    }
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("vdbhair_scale_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    nlohmann::json scene = readJsonFile(source + "/scenes/default/head.json", 64, "a scene");
    const std::size_t guides = scene["guides"].size();
    std::printf("\n== scale: vdbhair refine at its defaults, N strands x 32 vertices grown from the default head scene ==\n");
    std::printf("%9s %10s %7s | %9s %9s %9s | %10s %7s\n", "strands", "vertices", "leaves", "wall", "CPU", "peak", "estimate", "est/peak");
    for (std::size_t n : sizes) {
        const std::size_t perGuide = std::max<std::size_t>(1, (n + guides - 1) / guides);
        scene["step"] = 1.0;
        for (auto& g : scene["guides"]) g["wisp"]["count"] = perGuide - 1;  // the guide and its wisp
        const std::string sceneFile = (dir / "scene.json").string(), grown = (dir / "grown.data").string(),
                          hair = (dir / "hair.data").string(), refined = (dir / "refined.data").string(),
                          report = (dir / "report.json").string();
        writeFileAtomic(sceneFile, scene.dump(), "benchmark");
        if (runProcess({ours, "grow", sceneFile, "-o", grown, "-q"}).status != 0 ||
            runProcess({ours, "convert", grown, hair, "--resample", "32", "-q"}).status != 0) {
            std::printf("%9zu (skipped: grow or convert failed)\n", n);
            continue;
        }
        std::filesystem::remove(grown);
        const ProcessRun r = runProcess({ours, "refine", hair, "-o", refined, "--json"}, report);
        nlohmann::json j;
        try {
            j = readJsonFile(report, 64, "a report");
        } catch (const std::exception&) {
        }
        if (r.status != 0 || !j.contains("memory")) {
            std::printf("%9zu (refine failed: exit status %d, %.1f s, peak %.0f MiB)\n", perGuide * guides, r.status, r.wall, r.peakMiB);
            continue;
        }
        const double estimate = double(j["memory"]["estimate_bytes"].get<std::uint64_t>()) / double(1 << 20);
        const std::size_t strands = j["strands"].get<std::size_t>();
        std::printf("%9zu %10zu %7llu | %7.1f s %7.1f s %5.0f MiB | %6.0f MiB %7.2f\n", strands, strands * 32,
                    static_cast<unsigned long long>(j["memory"]["leaves"][0].get<std::uint64_t>()), r.wall, r.cpu, r.peakMiB, estimate,
                    estimate / r.peakMiB);
        std::fflush(stdout);
        for (const std::string& f : {hair, refined}) std::filesystem::remove(f);
    }
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
}

} // namespace vdbhair::bench
