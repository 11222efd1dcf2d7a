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
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/HelicoidField.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/GuideInterpolation.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/JsonFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpSampler.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>
#include <vdbhair/synth/Synthesis.h>

#include <CLI/CLI.hpp>

#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointRasterizeTrilinear.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tools/PointScatter.h>
#include <openvdb/tools/VelocityFields.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <fcntl.h>
#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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

/// @brief A reference hairstyle whose field fits in the processor's cache: @a count gently wavy
/// strands of @a vertices vertices half a unit apart, running along x with roots in a 6 × 6 × 6
/// unit cube (seeded, deterministic). At voxel size 1 (used whatever --voxel-size says) its field
/// is one leaf across and a few long (5 leaves at 64 vertices), so tracing it measures the
/// tracers' own work, without the cache misses of a large field.
StrandSet bundleInCache(std::size_t count, std::size_t vertices)
{
    StrandSet out;
    out.reserve(count, count * vertices);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(1.f, 7.f);
    std::vector<Vec3f> pts(vertices);
    for (std::size_t i = 0; i < count; ++i) {
        const float y = u(rng), z = u(rng), x0 = u(rng);
        for (std::size_t k = 0; k < vertices; ++k) {
            const float t = 0.5f * float(k);
            pts[k] = Vec3f(x0 + t, y + 0.3f * std::sin(0.2f * t + y), z + 0.3f * std::cos(0.15f * t + z));
        }
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

/// The voxel size of a run: --voxel-size, or (0) the library's suggestion for @a strands.
double voxelSizeFor(const StrandSet& strands, double voxelSize)
{
    FieldParams fp;
    fp.voxelSize = voxelSize;
    return resolveVoxelSize(strands, fp);
}

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
    tp.step = kDefaultStepVoxels * voxelSize;  // the default step, the peer's too
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
                // As vdbhair traces a strand: whole steps, the last one shortened to end at the length.
                const std::size_t n = stepCount(double(lengths[i]), tp.step);
                for (std::size_t k = 0; k + 1 < n; ++k) integ.rungeKutta<1>(tp.step, p);
                if (n > 0) integ.rungeKutta<1>(double(lengths[i]) - double(n - 1) * tp.step, p);
                ends[i] = p;
            }
        });
    });
    // The same retrace into an output whose storage is reused (retraceStrandsInto, as refine's
    // levels do): the difference is the cost of mapping fresh memory for the output.
    StrandSet reused;
    retraceStrandsInto(strands, *field.tangent, tp, reused);
    const double tInto = timeBest(reps, [&] { retraceStrandsInto(strands, *field.tangent, tp, reused); });
    const double oursRate = double(stats.steps) / tTrace, peerRate = double(peerSteps) / tPeerTrace;
    const double intoRate = double(stats.steps) / tInto;
    // The peer's end points (`ends`) against the tips of vdbhair's full-length strands, in voxels
    // (the peer's last step shortened as vdbhair's is, so both trace the same length).
    std::vector<double> tipGap;
    const std::vector<float> tracedLengths = strandLengths(traced);
    for (std::size_t i = 0; i < nS; ++i) {
        const Vec3f& tip = traced.positions[traced.end(i) - 1];
        if (std::abs(double(tracedLengths[i]) - double(lengths[i])) > 1e-3 * double(lengths[i])) continue;  // stopped early
        tipGap.push_back((openvdb::Vec3d(tip.x(), tip.y(), tip.z()) - ends[i]).length() / voxelSize);
    }
    std::sort(tipGap.begin(), tipGap.end());
    const double gapMedian = tipGap.empty() ? 0.0 : tipGap[tipGap.size() / 2];
    const double gapP95 = tipGap.empty() ? 0.0 : tipGap[std::min(tipGap.size() - 1, tipGap.size() * 95 / 100)];
    std::printf("tracing (Euler, step %.4g)  vdbhair %.3f s (%.1f M steps/s, %zu steps, %zu/%zu full length)   VelocityIntegrator %.3f s (%.1f M steps/s, %zu steps)   ratio ours/peer %.2fx steps/s\n"
                "                       into a reused output: vdbhair %.3f s (%.1f M steps/s), ratio ours/peer %.2fx (the %.0f MB output's fresh pages cost %.3f s above)\n",
                tp.step, tTrace, oursRate / 1e6, stats.steps, stats.fullLength, nS, tPeerTrace, peerRate / 1e6, peerSteps, oursRate / peerRate,
                tInto, intoRate / 1e6, intoRate / peerRate, double(traced.positions.size() * sizeof(Vec3f)) / 1e6, tTrace - tInto);
    // Not the same rule: the peer steps by the interpolated vector, shorter where neighbouring
    // directions disagree or an inactive (zero) voxel takes part; vdbhair by the unit direction of
    // the active corners. They agree inside a uniform field (the reference bundle).
    std::printf("                       agreement: the tips of vdbhair's %zu full-length strands lie %.3g voxel (median), %.3g (95th percentile) from VelocityIntegrator's\n"
                "                       (the peer steps by the interpolated vector, shorter where directions disagree or inactive voxels take part)\n",
                tipGap.size(), gapMedian, gapP95);
    // The streamline engine's general path on the same job (TraceKernel::Scalar, one streamline at
    // a time in double): what the lane kernel, its fast path, buys.
    TraceParams scalar = tp;
    scalar.kernel = TraceKernel::Scalar;
    TraceStats scalarStats;
    const double tScalar = timeBest(reps, [&] { retraceStrands(strands, *field.tangent, scalar, &scalarStats); });
    std::printf("                       the engine's general path (scalar kernel): %.3f s (%.1f M steps/s, %zu steps); lanes / scalar %.2fx steps/s\n",
                tScalar, double(scalarStats.steps) / tScalar / 1e6, scalarStats.steps, oursRate / (double(scalarStats.steps) / tScalar));
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

/// Interpolation (Piuze et al. 2011, §4.2): the paper's setup, 9 p-helicoid guides of about 4
/// pieces (3 to 5) on a 3 by 3 patch, 64 Euler steps a strand, interpolated at 1,000 and 90,000
/// random roots on the patch (the paper: 0.67 s for 1,000 on one 2.4 GHz core, about a minute for
/// 90,000), against blending the guides' points (Blender's Interpolate Curves) at the same vertex
/// count. Times include growing the strands.
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

/// Hair from guides at production scale (the guides issue, item 7): 1,000 guides of 16 vertices on
/// a head sphere's upper half, hanging down it, in four groups (two partings), and 1,000,000 new
/// roots on the same cap, through `interpolateGuides()` at its defaults with clumps (and with curl),
/// without a head and with the sphere as the head. Peak memory is the process's (getrusage).
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

/// `compare` (issue 54): a head of strands x 100 vertices against the same and against a jittered
/// copy, every measure (HairGS's four thresholds at centimetres, Chamfer, strand pairs, Fréchet,
/// the volume). The target is 100,000 strands against the same under 3 s
/// (--compare-strands 100000).
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

/// What a helicoid field buys over a plain tangent field (issues 4 and 19): curly and wavy
/// strands retraced from their roots through each, at vdbhair's suggested voxel size and coarser,
/// with forward Euler (TraceParams' default) and with RK4 (retrace --helicoid's default,
/// kHelicoidRetraceIntegrator) for both fields, and the mean vertex error against the input (same
/// arc lengths), relative to the mean strand length.
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

/// Fitting p-helicoids to real strands (issue 5's targets: >= 1000 strands/s with a mean error of
/// at most 2 % of the length on straight and wavy hair at 30 vertices).
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


/// Points for tools::UniformPointScatter.
struct PointList
{
    std::vector<Vec3d> points;
    void add(const openvdb::Vec3R& p) { points.emplace_back(p); }
};

/// Follicles on the shared heads: vdbhair's particle system against the quick alternative a user
/// would write, UniformPointScatter in the voxels the zero level set crosses, projected onto it.
void benchmarkRoots(const std::string& data, const std::vector<std::size_t>& counts, const std::string& only)
{
    std::printf("\n== follicles on the shared heads (voxel size 1/100 of the head; %d thread(s)) ==\n"
                "NN CV: coefficient of variation of each root's distance to its nearest neighbour (lower is more regular)\n",
                int(tbb::this_task_arena::max_concurrency()));
    std::printf("%-28s %8s  %9s %7s %6s  %9s %7s  %7s\n", "head", "roots", "vdbhair s", "NN CV", "iters", "scatter s", "NN CV", "time x");
    const char* heads[] = {"scalp/ct2hair/Bangs_head.ply", "scalp/usc_hairsalon/head_model.ply", "scalp/cem_yuksel/woman_head.ply",
                           "scalp/sintel/sintel.obj", "scalp/tressfx/head_max4.obj", "scalp/tressfx/ruby_head.obj"};
    for (const char* head : heads) {
        const std::string path = data + "/" + head;
        if (!only.empty() && std::string(head).find(only) == std::string::npos) continue;
        if (!std::filesystem::exists(path)) {
            std::printf("%-28s (skipped: not found)\n", head);
            continue;
        }
        ScalpParams sp;
        const openvdb::FloatGrid::Ptr surface = scalpFromMesh(readTriangleMesh(path), sp);
        const ScalpSampler sampler(surface);
        openvdb::BoolGrid::Ptr mask = openvdb::BoolGrid::create(false);
        mask->setTransform(surface->transform().copy());
        {
            auto acc = mask->getAccessor();
            for (auto it = surface->cbeginValueOn(); it; ++it) {
                if (it.isVoxelValue() && std::abs(*it) < float(surface->voxelSize().x())) acc.setValueOn(it.getCoord(), true);
            }
        }
        const std::string name = std::filesystem::path(head).filename().string();
        for (std::size_t count : counts) {
            FollicleParams fp;
            fp.count = count;
            double t0 = now();
            const Follicles f = sampleFollicles(surface, nullptr, fp);
            const double tv = now() - t0;
            const FollicleStats sv = measureFollicles(f.positions);
            t0 = now();
            PointList list;
            std::mt19937 rng(1);
            openvdb::tools::UniformPointScatter<PointList, std::mt19937> scatter(list, openvdb::Index64(count), rng);
            scatter(*mask);
            std::vector<Vec3f> projected(list.points.size());
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, list.points.size()), [&](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t i = r.begin(); i != r.end(); ++i) projected[i] = Vec3f(sampler.project(list.points[i]));
            });
            const double ts = now() - t0;
            const FollicleStats ss = measureFollicles(projected);
            std::printf("%-28s %8zu  %9.3f %7.3f %6d  %9.3f %7.3f  %7.1f\n", name.c_str(), f.positions.size(), tv, sv.nnCV, f.iterations, ts,
                        ss.nnCV, ts > 0.0 ? tv / ts : 0.0);
            std::fflush(stdout);
        }
    }
}

/// Example-based synthesis (Wang et al. 2009; the paper: a 100,000-strand hairstyle in under two
/// minutes on a Pentium 4, clustering 50 %, texture optimization 20 %, refinement 20 %): time per
/// stage and peak memory, on real hairstyles and the 100,000-strand jittered set, both layouts.
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

/// One finished child process: wall seconds, CPU seconds (user + system), peak resident MiB.
struct ProcessRun
{
    double wall = 0.0, cpu = 0.0, peakMiB = 0.0;
    int status = 0;
};

/// @brief Run @a args (a program and its arguments) as a process with stdout and stderr sent to
/// /dev/null (stdout to @a stdoutPath if given), and measure it from the outside (wait4's rusage:
/// the child's own CPU and peak RSS).
ProcessRun runProcess(const std::vector<std::string>& args, const std::string& stdoutPath = std::string())
{
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const double t0 = now();
    const pid_t pid = fork();
    if (pid == 0) {
        const int devNull = open("/dev/null", O_WRONLY);
        const int out = stdoutPath.empty() ? devNull : open(stdoutPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(out, 1);
        dup2(devNull, 2);
        execv(argv[0], argv.data());
        _exit(127);
    }
    ProcessRun r;
    rusage u{};
    if (pid < 0 || wait4(pid, &r.status, 0, &u) != pid) {
        r.status = -1;
        return r;
    }
    r.wall = now() - t0;
    r.cpu = double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
    r.peakMiB = double(u.ru_maxrss) / 1024.0;
    return r;
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

/// @brief The end-to-end section: the `vdbhair` command and the stock-OpenVDB peer program
/// (apps/benchmark/Peer.cc, the same operations as the library rows above, with an ifstream
/// reader) as processes on the same files, as a user runs them from the shell: each verb and its
/// peer in turn (A B A B ...), @a runs times after a warm-up, median wall and CPU time, peak
/// resident memory, and the ratio of the peer's wall time to vdbhair's.
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

/// @brief The scale section (issue 22, item 7): `vdbhair refine` at its defaults on hairstyles of
/// @a sizes strands x 32 vertices, made by vdbhair itself at benchmark time (the default head
/// scene's 400 guides, each grown into a wisp of size / 400 strands at step 1 by `vdbhair grow`,
/// resampled to 32 vertices by `vdbhair convert`) in a scratch folder removed afterwards: wall
/// and CPU time and peak resident memory from the outside (wait4), against the memory estimate
/// refine checks before it allocates (its --json report).
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

} // namespace

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

    if (wants("field")) {
        const std::string real = data + "/hair/cyhair/straight.hair";
        if (std::filesystem::exists(real)) {
            const StrandSet s = readStrands(real);
            benchmark("real: straight.hair (Cem Yuksel)", s, voxelSizeFor(s, voxelSize), reps);
        } else {
            std::printf("\n(skipped the real hairstyle: %s not found)\n", real.c_str());
        }
        const StrandSet base = readStrands(source + "/scenes/default/ponytail.hair");
        const StrandSet big = jitteredCopies(base, strands, vertices, 0.3f);
        benchmark("synthetic: jittered copies of the bundled ponytail", big, voxelSizeFor(big, voxelSize), reps);
        // The tracing target's reference: the same counts on a field held in the cache, where a
        // step costs only arithmetic, for the tracer and the peer alike (docs/performance.md).
        benchmark("reference: a bundle whose field fits in the cache", bundleInCache(strands, vertices), 1.0, reps);
    }
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
