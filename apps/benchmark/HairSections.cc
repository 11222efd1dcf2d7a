// The benchmark's sections of vdbhair's own operations, which OpenVDB has no peer for (Sections.h):
// helicoids, helicoid fields, fitting, interpolation, hair from guides, compare, synthesis.
#include "Harness.h"
#include "Sections.h"

#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/GuideInterpolation.h>
#include <vdbhair/helicoid/HelicoidField.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>
#include <vdbhair/synth/Synthesis.h>

#include <tbb/task_arena.h>

#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

namespace vdbhair::bench {

namespace {

/// A head of hair for the groom and compare sections: 1,000 guides of 16 vertices bending down from
/// a sphere cap of radius 10 (y up), in four groups by quadrant, and @a strands roots on the cap.
struct SphereGroom
{
    StrandSet guides;
    std::vector<std::int32_t> guideGroups;
    InterpolationRoots roots;
    double radius = 10.0;
};

SphereGroom sphereGroom(std::size_t strands)
{
    SphereGroom g;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto onCap = [&]() {
        // Uniform on the sphere above the equator (y up).
        const double y = u(rng), phi = 2.0 * M_PI * u(rng), r = std::sqrt(1.0 - y * y);
        return Vec3d(r * std::cos(phi), y, r * std::sin(phi)) * g.radius;
    };
    for (int i = 0; i < 1000; ++i) {
        const Vec3d root = onCap();
        std::vector<Vec3f> p(16);
        Vec3d x = root, d = root.unit();
        for (int k = 0; k < 16; ++k) {
            p[k] = Vec3f(float(x.x()), float(x.y()), float(x.z()));
            d = (d + Vec3d(0.0, -0.25, 0.0)).unit();  // bends down
            x += d * 1.5;
        }
        g.guides.addStrand(p);
        g.guideGroups.push_back((root.x() > 0.0 ? 1 : 0) + (root.z() > 0.0 ? 2 : 0));
    }
    g.roots.positions.reserve(strands);
    for (std::size_t i = 0; i < strands; ++i) g.roots.positions.push_back(onCap());
    return g;
}

/// Every k-th strand of @a s so that at most @a limit remain (all for 0).
StrandSet strideSubset(const StrandSet& s, std::size_t limit, std::size_t& stride)
{
    stride = (limit == 0 || s.numStrands() <= limit) ? 1 : (s.numStrands() + limit - 1) / limit;
    if (stride == 1) return s;
    StrandSet out;
    for (std::size_t i = 0; i < s.numStrands(); i += stride) out.addStrand(s.data(i), s.size(i));
    return out;
}

/// One row of the fitting table: fit @a strands (best of up to @a reps runs, fewer when a run is
/// slow), print errors, pieces, compression and speed.
void fitRow(const std::string& name, const std::string& vertices, const StrandSet& strands, std::size_t total, std::size_t stride,
            const FitParams& params, int reps)
{
    std::vector<StrandFit> fits;
    std::vector<std::string> errors;
    double best = 1e30, spent = 0.0;
    int runs = 0;
    for (; runs < std::max(1, reps) && (runs == 0 || spent + best < 20.0); ++runs) {
        const double t0 = now();
        fits = fitStrands(strands, params, true, &errors);
        const double t = now() - t0;
        best = std::min(best, t);
        spent += t;
    }
    const FitSummary s = summarizeFits(strands, fits, errors, params.maxError);
    char subset[64] = "all";
    if (stride > 1) std::snprintf(subset, sizeof subset, "every %zuth", stride);
    std::printf("%-9s %-10s %6zu of %6zu (%-10s) %6zu  %6.2f %% %6.2f %% %6zu  %6.2f  %6.1fx  %7.0f  %8.1f  (best of %d)\n", name.c_str(),
                vertices.c_str(), s.fitted, total, subset, s.skipped, 100.0 * s.meanRelative, 100.0 * s.p95Relative, s.overMaxError,
                s.piecesPerStrand, s.fitBytes > 0.0 ? s.pointBytes / s.fitBytes : 0.0, s.evaluationsPerStrand, double(s.fitted) / best, runs);
    std::fflush(stdout);
}

} // namespace

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

void benchmarkInterpolation(int reps)
{
    std::printf("\n== interpolation: 9 p-helicoid guides of ~4 pieces (the paper: 0.67 s for 1,000 strands, ~1 min for 90,000) ==\n");
    Scene scene;
    scene.seed = 1;
    scene.step = 4.0 / 64.0;
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int g = 0; g < 9; ++g) {
        SceneGuide guide;
        guide.root = Vec3d(double(g % 3), double(g / 3), 0.0);
        guide.frame = FrameD::fromTangentNormal(Vec3d(0.2 * u(rng), 0.2 * u(rng), 1.0), Vec3d(1, 0, 0));
        const int pieces = 3 + g % 3;  // 3, 4, 5: four on average
        for (int p = 0; p < pieces; ++p) {
            guide.pieces.push_back({{1.5 + u(rng), 0.3 * u(rng), 0.5 * u(rng), 0.2 * u(rng)}, 4.0 / pieces, 0.3 * u(rng)});
        }
        scene.guides.push_back(guide);
    }
    const StrandSet guideStrands = growScene(scene);
    for (std::size_t count : {std::size_t(1000), std::size_t(90000)}) {
        InterpolationRoots roots;
        for (std::size_t i = 0; i < count; ++i) roots.positions.emplace_back(1.0 + u(rng), 1.0 + u(rng), 0.0);
        StrandSet h, p;
        Scene blended;
        const double tb = timeBest(reps, [&] { blended = interpolateHelicoids(scene, roots, {}); });
        const double tg = timeBest(reps, [&] { h = growScene(blended); });
        const double th = tb + tg;
        const double tp = timeBest(reps, [&] { p = interpolatePoints(guideStrands, roots, {}); });
        std::printf("%6zu strands: helicoid %.4f s (blend %.4f s + grow %.4f s; %.2f us a strand, %zu vertices)  points %.4f s (%.2f us a strand, %zu vertices)  "
                    "helicoid/points %.2fx  vs the paper %.0fx\n",
                    count, th, tb, tg, th / double(count) * 1e6, h.numVertices(), tp, tp / double(count) * 1e6, p.numVertices(), th / tp,
                    0.67e-3 * double(count) / th);
    }
}

void benchmarkGroom(int reps, std::size_t strands)
{
    std::printf("\n== hair from guides: %zu strands from 1,000 guides (16 vertices), 4 groups, clumps; the target is under 5 s ==\n", strands);
    const SphereGroom g = sphereGroom(strands);
    const double radius = g.radius;
    InterpolationGuides in;
    in.strands = &g.guides;
    in.groups = g.guideGroups;
    const InterpolationRoots& roots = g.roots;
    const HeadObstacle sphere = HeadObstacle::sphere(Vec3d(0.0), radius);
    struct Row { const char* name; double clump, curl; bool head; };
    const Row rows[] = {{"points, groups", 0.0, 0.0, false},
                        {"points, groups, clumps (radius 0.5)", 0.5, 0.0, false},
                        {"points, groups, clumps, the head sphere", 0.5, 0.0, true},
                        {"points, groups, clumps, curl, the head sphere", 0.5, 0.15, true}};
    for (const Row& row : rows) {
        InterpolateParams p;
        p.groom.clump.radius = row.clump;
        p.groom.curl.amplitude = row.curl;
        p.groom.curl.frequency = row.curl > 0.0 ? 2.0 : 0.0;
        InterpolateResult r;
        const double t = timeBest(reps, [&] { r = interpolateGuides(in, roots, row.head ? sphere : HeadObstacle::none(), p); });
        rusage usage{};
        getrusage(RUSAGE_SELF, &usage);
        std::printf("%-46s %.2f s  %zu strands, %zu vertices (%.0f MiB), %zu clumps, peak resident %.0f MiB so far\n", row.name, t,
                    r.strands.numStrands(), r.strands.numVertices(), double(r.strands.numVertices()) * 12.0 / double(1 << 20), r.groom.clumps,
                    double(usage.ru_maxrss) / 1024.0);
        std::fflush(stdout);
    }
}

void benchmarkCompare(int reps, std::size_t strands)
{
    std::printf("\n== compare: a head of %zu strands x 100 vertices (cm) against the same and a jittered copy; the target is 100,000 under 3 s ==\n", strands);
    // A head of hair (the groom section's: radius 10 cm, about 14 cm long), strands resampled to 100 points.
    const SphereGroom g = sphereGroom(strands);
    InterpolationGuides in;
    in.strands = &g.guides;
    in.groups = g.guideGroups;
    const StrandSet a = resampleStrands(interpolateGuides(in, g.roots, HeadObstacle::none(), InterpolateParams()).strands, 100);
    StrandSet b = a;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-0.05f, 0.05f);
    for (Vec3f& p : b.positions) p += Vec3f(u(rng), u(rng), u(rng));
    CompareParams params;
    params.metersPerUnit = 0.01;
    for (const auto& [name, other] : {std::pair<const char*, const StrandSet*>{"against itself", &a}, {"against a copy jittered by 0.05", &b}}) {
        HairComparison c;
        const double t = timeBest(reps, [&] { c = compareHairstyles(a, *other, params); });
        std::printf("%-34s %.2f s  F1 at 2 mm %.4f, 4 mm/90 deg %.4f, Chamfer %.4g, position error %.4g, Frechet mean %.4g\n", name, t,
                    c.oriented[0].f1, c.oriented[3].f1, c.chamfer.mean, c.perm.meanPosition, c.frechetMean);
        // Where the time goes: indexing both, then each measure alone on the indices (the
        // Fréchet pairs are most of the rest).
        std::vector<OrientedThreshold> thresholds = hairGsThresholds();
        for (OrientedThreshold& th : thresholds) th.distance /= params.metersPerUnit;
        const double tIndex = timeBest(1, [&] { const StrandIndex ia(a), ib(*other); });
        const StrandIndex ia(a), ib(*other);
        const double tOriented = timeBest(1, [&] { matchOrientedPoints(ib, ia, thresholds); });
        const double tChamfer = timeBest(1, [&] { chamferDistances(ia, ib); });
        const double tPairs = timeBest(1, [&] { strandPairErrors(a, *other); });
        const double tVolume = timeBest(1, [&] { countStrandsLeavingVolume(*other, a, suggestVoxelSize(a)); });
        std::printf("%-34s indexing %.2f s, oriented points %.2f s, Chamfer %.2f s, strand pairs %.2f s, volume %.2f s\n", "", tIndex,
                    tOriented, tChamfer, tPairs, tVolume);
        std::fflush(stdout);
    }
}

void benchmarkHelicoidFields(const std::string& data, const std::string& source)
{
    std::printf("\n== helicoid fields vs tangent fields: retrace every strand from its root (half-voxel step) ==\n"
                "error: mean distance between input and retraced vertices at the same arc length, relative to the mean strand length;\n"
                "ratio: tangent field's error / helicoid field's, with the same integrator for both\n");
    std::printf("%-34s %8s %7s  %9s %9s %6s  %9s %9s %6s\n", "hairstyle", "voxel", "voxels", "tan euler", "hel euler", "ratio",
                "tan rk4", "hel rk4", "ratio");
    struct Set { std::string name; std::string path; };
    const Set sets[] = {{"Fig. 5 curly four-piece (scene)", source + "/scenes/figures/fig5_curly_four_piece.json"},
                        {"Fig. 2 waviness (scene)", source + "/scenes/figures/fig2_waviness.json"},
                        {"Curly_100.ply (curly)", data + "/hair/ply/Curly_100.ply"},
                        {"harolongo.data (wavy)", data + "/hair/usc_data/harolongo.data"}};
    for (const Set& set : sets) {
        if (!std::filesystem::exists(set.path)) {
            std::printf("%-34s (skipped: %s not found)\n", set.name.c_str(), set.path.c_str());
            continue;
        }
        const StrandSet s = set.path.size() > 5 && set.path.substr(set.path.size() - 5) == ".json" ? growScene(readScene(set.path))
                                                                                                 : readStrands(set.path);
        double meanLength = 0.0;
        for (std::size_t i = 0; i < s.numStrands(); ++i) meanLength += polylineLength(s.data(i), s.size(i));
        meanLength /= double(std::max<std::size_t>(1, s.numStrands()));
        const double h0 = suggestVoxelSize(s);
        for (double f : {1.0, 2.0, 4.0}) {
            FieldParams fp;
            fp.voxelSize = h0 * f;
            const TangentField tf = estimateTangentField(s, fp);
            const HelicoidFieldGrids hf = estimateHelicoidField(s, *tf.tangent);
            double e[2][2];  // [integrator][tangent, helicoid]
            for (int i = 0; i < 2; ++i) {
                TraceParams tp;
                tp.integrator = i == 0 ? Integrator::Euler : kHelicoidRetraceIntegrator;
                e[i][0] = meanVertexDisplacement(s, retraceStrands(s, *tf.tangent, tp)) / meanLength;
                e[i][1] = meanVertexDisplacement(s, retraceHelicoidField(s, hf, tp)) / meanLength;
            }
            std::printf("%-34s %8.4g %7zu  %8.2f%% %8.2f%% %5.2fx  %8.2f%% %8.2f%% %5.2fx\n", f == 1.0 ? set.name.c_str() : "",
                        fp.voxelSize, std::size_t(tf.tangent->activeVoxelCount()), 100.0 * e[0][0], 100.0 * e[0][1],
                        e[0][0] / e[0][1], 100.0 * e[1][0], 100.0 * e[1][1], e[1][0] / e[1][1]);
            std::fflush(stdout);
        }
    }
}

void benchmarkFitting(const std::string& data, std::size_t limit, int reps)
{
    std::printf("\n== fitting p-helicoids (Piuze et al. 2011, §5; the paper: about 5 strands/s), %d thread(s) ==\n"
                "errors: discrete Frechet distance of the regrown fit relative to strand length; compression: bytes of points / bytes of fit;\n"
                "strands/s: wall clock of fitStrands; at most %zu strands per row (an evenly strided subset when there are more)\n",
                int(tbb::this_task_arena::max_concurrency()), limit);
    std::printf("%-9s %-10s %-26s %6s  %8s %8s %6s  %6s  %7s  %7s  %8s\n", "data", "vertices", "strands fitted", "skip", "mean", "p95",
                ">max", "pieces", "compr.", "evals", "strands/s");
    struct Set { const char* name; const char* file; };
    const Set sets[] = {{"straight", "hair/cyhair/straight.hair"}, {"wavy", "hair/usc_data/harolongo.data"},
                        {"curly", "hair/ply/Curly_100.ply"}, {"short", "hair/tressfx/binary_v4/Ratboy_mohawk.tfx"}};
    const FitParams params;
    for (const Set& set : sets) {
        const std::string path = data + "/" + set.file;
        if (!std::filesystem::exists(path)) {
            std::printf("%-9s (skipped: %s not found)\n", set.name, path.c_str());
            continue;
        }
        const StrandSet all = readStrands(path);
        std::size_t stride = 1;
        const StrandSet r30 = resampleStrands(all, 30);
        const StrandSet s30 = strideSubset(r30, limit, stride);
        fitRow(set.name, "30", s30, all.numStrands(), stride, params, reps);
        if (std::string(set.name) == "straight") {
            FitParams noRoll = params;
            noRoll.optimizeRoll = false;
            fitRow("straight", "30, roll off", s30, all.numStrands(), stride, noRoll, reps);
        }
        std::size_t lo = all.size(0), hi = all.size(0);
        for (std::size_t i = 0; i < all.numStrands(); ++i) { lo = std::min(lo, all.size(i)); hi = std::max(hi, all.size(i)); }
        const StrandSet full = strideSubset(all, limit, stride);
        fitRow(set.name, lo == hi ? std::to_string(lo) : std::to_string(lo) + "-" + std::to_string(hi), full, all.numStrands(), stride, params, reps);
    }
}

void benchmarkSynthesis(const std::string& data, const std::string& source, std::size_t strands, std::size_t vertices)
{
    std::printf("\n== synthesis (vdbhair synth defaults; %d thread(s)) ==\n", int(tbb::this_task_arena::max_concurrency()));
    std::vector<std::pair<std::string, StrandSet>> inputs;
    for (const char* f : {"hair/cyhair/straight.hair", "hair/usc_data/harolongo.data"}) {
        const std::string path = data + "/" + f;
        if (std::filesystem::exists(path)) inputs.emplace_back(std::filesystem::path(f).filename().string(), readStrands(path));
        else std::printf("(skipped %s: not found)\n", f);
    }
    inputs.emplace_back("jittered ponytail " + std::to_string(strands), jitteredCopies(readStrands(source + "/scenes/default/ponytail.hair"), strands, vertices, 0.3f));
    for (auto& [name, example] : inputs) {
        for (SynthLayout layout : {SynthLayout::Example, SynthLayout::Synthesize}) {
            SynthParams p;
            p.layout = layout;
            p.seed = 1;
            const double t0 = now();
            const SynthResult r = synthesizeHair(example, p);
            const double t = now() - t0;
            std::printf("%-26s %-10s %7zu strands  %7.2f s  peak %7.0f MiB |", name.c_str(), layout == SynthLayout::Example ? "example" : "synthesize",
                        r.strands.numStrands(), t, peakMiB());
            for (const SynthStage& s : r.stages) std::printf(" %s %.2f", s.name.c_str(), s.seconds);
            std::printf("\n");
            std::fflush(stdout);
        }
    }
}

} // namespace vdbhair::bench
