// The benchmark's sections against OpenVDB's peers, in process (Sections.h): field estimation and
// tracing, follicles.
#include "Harness.h"
#include "Sections.h"

#include <vdbhair/Quantile.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpSampler.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointRasterizeTrilinear.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tools/PointScatter.h>
#include <openvdb/tools/VelocityFields.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

namespace vdbhair::bench {

namespace {

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

/// The voxel size of a run: --voxel-size, or (0) the library's suggestion for @a strands.
double voxelSizeFor(const StrandSet& strands, double voxelSize)
{
    FieldParams fp;
    fp.voxelSize = voxelSize;
    return resolveVoxelSize(strands, fp);
}

/// Field estimation and tracing on @a strands at @a voxelSize: vdbhair against its peers.
void benchmarkField(const std::string& name, const StrandSet& strands, double voxelSize, int reps)
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
    const double gapMedian = upperMedian(tipGap);
    const double gapP95 = orderStatistic(tipGap, tipGap.size() * 95 / 100);  // floor(0.95 n), within the sample
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

/// Points for tools::UniformPointScatter.
struct PointList
{
    std::vector<Vec3d> points;
    void add(const openvdb::Vec3R& p) { points.emplace_back(p); }
};

} // namespace

void benchmarkFields(const std::string& data, const std::string& source, std::size_t strands, std::size_t vertices,
                     double voxelSize, int reps)
{
    const std::string real = data + "/hair/cyhair/straight.hair";
    if (std::filesystem::exists(real)) {
        const StrandSet s = readStrands(real);
        benchmarkField("real: straight.hair (Cem Yuksel)", s, voxelSizeFor(s, voxelSize), reps);
    } else {
        std::printf("\n(skipped the real hairstyle: %s not found)\n", real.c_str());
    }
    const StrandSet base = readStrands(source + "/scenes/default/ponytail.hair");
    const StrandSet big = jitteredCopies(base, strands, vertices, 0.3f);
    benchmarkField("synthetic: jittered copies of the bundled ponytail", big, voxelSizeFor(big, voxelSize), reps);
    // The tracing target's reference: the same counts on a field held in the cache, where a
    // step costs only arithmetic, for the tracer and the peer alike (docs/performance.md).
    benchmarkField("reference: a bundle whose field fits in the cache", bundleInCache(strands, vertices), 1.0, reps);
}

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

} // namespace vdbhair::bench
