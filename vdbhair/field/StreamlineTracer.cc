#include "StreamlineTracer.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/FieldSampler.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/openvdb.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <memory>
#include <cmath>
#include <numeric>

namespace vdbhair {

using openvdb::Vec3d;

Integrator integratorFromName(const std::string& name)
{
    if (name == "euler") return Integrator::Euler;
    if (name == "rk2") return Integrator::RK2;
    if (name == "rk4") return Integrator::RK4;
    throw ValueError("integrator '" + name + "' is not one of euler, rk2, rk4");
}

const char* integratorName(Integrator integrator)
{
    switch (integrator) {
    case Integrator::RK2: return "rk2";
    case Integrator::RK4: return "rk4";
    default: return "euler";
    }
}

namespace {

enum Sample { kOk, kLeft, kVanished };

/// Streamline integration through one grid; one per thread.
template<typename TreeT>
class Tracer
{
public:
    Tracer(const BrickedField<TreeT>& bricks, const FieldMapping& map, double threshold)
        : mSampler(bricks), mMap(map), mThreshold(threshold) {}

    /// Unit field direction at a world point.
    Sample direction(const Vec3d& world, Vec3d& dir)
    {
        const Vec3d ip = mMap.worldToIndex(world);
        const Float4 r = mSampler.sample(ip);
        if (!(r[3] > 0.f)) return kLeft;
        const float len2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        const float limit = float(mThreshold) * r[3];
        if (!(len2 > limit * limit)) return kVanished;
        const float inv = 1.f / std::sqrt(len2);
        dir = Vec3d(r[0] * inv, r[1] * inv, r[2] * inv);
        return kOk;
    }

    /// One step of length h from p; returns the stage that failed, if any.
    Sample advance(Integrator integ, const Vec3d& p, double h, Vec3d& q)
    {
        Vec3d k1, k2, k3, k4;
        Sample s = direction(p, k1);
        if (s != kOk) return s;
        switch (integ) {
        case Integrator::Euler:
            q = p + h * k1;
            return kOk;
        case Integrator::RK2:
            if ((s = direction(p + 0.5 * h * k1, k2)) != kOk) return s;
            q = p + h * k2;
            return kOk;
        case Integrator::RK4:
            if ((s = direction(p + 0.5 * h * k1, k2)) != kOk) return s;
            if ((s = direction(p + 0.5 * h * k2, k3)) != kOk) return s;
            if ((s = direction(p + h * k3, k4)) != kOk) return s;
            q = p + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            return kOk;
        }
        return kLeft;
    }

private:
    FieldSampler<TreeT> mSampler;
    const FieldMapping& mMap;
    double mThreshold;
};

StopReason toReason(Sample s) { return s == kLeft ? StopReason::LeftField : StopReason::Vanished; }

/// Retrace all strands through the tree of a Vec3 grid.
template<typename GridT>
StrandSet retraceTyped(const StrandSet& in, const GridT& grid, const TraceParams& params, double step,
                       TraceStats* stats, std::vector<StopReason>* reasonsOut, bool threaded,
                       openvdb::util::NullInterrupter* interrupter)
{
    using TreeT = typename GridT::TreeType;
    const FieldMapping map = FieldMapping::fromGrid(grid);
    const BrickedField<TreeT> bricks(grid.tree());
    const std::size_t nS = in.numStrands();
    // Strands in spatial order: consecutive strands share bricks, which stay in cache.
    const std::vector<std::uint32_t> order = spatialOrder(in);
    const bool inputMode = params.vertices == RetraceVertices::Input;

    // Input mode writes into the input's layout (compacted afterwards if a strand stops early);
    // step mode collects each strand's points.
    std::vector<Vec3f> positions(inputMode ? in.numVertices() : 0);
    std::vector<std::uint32_t> used(nS, 0);
    std::vector<std::vector<Vec3f>> stepPoints(inputMode ? 0 : nS);
    std::vector<StopReason> reasons(nS, StopReason::FullLength);
    std::vector<std::size_t> steps(nS, 0);
    std::atomic<bool> stop{false};

    // Each thread traces kLanes strands at once, one step of each in turn. A step is a chain of
    // dependent operations (map, sample, normalize, move); independent lanes let the processor
    // overlap their latencies, provided the loop has no unpredictable branches. So a lane only
    // records its step points; the arc-length bookkeeping (output vertices at the input's arc
    // lengths) happens once per strand, afterwards. Step k lies at arc length k·h along the
    // streamline (the integrators move at unit speed), the last step being shortened to land on
    // the strand's length.
    constexpr int kLanes = 8;
    struct Lane
    {
        bool busy = false;
        std::size_t strand = 0;
        std::size_t k = 0;       ///< steps taken
        std::size_t needed = 0;  ///< steps to the full length
        std::size_t limit = 0;   ///< steps allowed: needed, or fewer under maxSteps
        double length = 0.0, lastStep = 0.0;
        Vec3d p{0.0};
        Vec3d dir{0.0};        ///< direction of the last step
        double outside = 0.0;  ///< length travelled in a row past the active region
        std::vector<double> target;  ///< the input's vertex arc lengths
        std::vector<Vec3f> points;   ///< points[m] at arc length m·step (points[needed]: the length)
    };

    auto traceRange = [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<std::unique_ptr<Tracer<TreeT>>> tracers;
        for (int l = 0; l < kLanes; ++l) tracers.emplace_back(new Tracer<TreeT>(bricks, map, params.vanishThreshold));
        Lane lanes[kLanes];
        std::size_t next = r.begin();

        auto start = [&](Lane& lane) {
            lane.busy = false;
            if (next >= r.end() || stop) return;
            const std::size_t i = order[next++];
            if (interrupter && (next & 255) == 0 && interrupter->wasInterrupted()) { stop = true; return; }
            lane.target.resize(in.size(i));
            arcLengths(in.data(i), in.size(i), lane.target.data());
            lane.length = lane.target.back();
            // Whole steps, the last one shortened to land on the length (none for zero length).
            lane.needed = lane.length > 0.0 ? std::max<std::size_t>(1, std::size_t(std::ceil(lane.length / step - 1e-9))) : 0;
            lane.limit = params.maxSteps ? std::min(lane.needed, params.maxSteps) : lane.needed;
            lane.lastStep = lane.needed ? lane.length - double(lane.needed - 1) * step : 0.0;
            lane.busy = true;
            lane.strand = i;
            lane.k = 0;
            lane.p = Vec3d(in.root(i));
            lane.dir = Vec3d(0.0);
            lane.outside = 0.0;
            if (lane.points.size() < lane.limit + 1) lane.points.resize(lane.limit + 1);
            lane.points[0] = in.root(i);
        };
        // Arc length of step point m, and of the step that starts there.
        auto arcAt = [&](const Lane& lane, std::size_t m) { return m == lane.needed ? lane.length : double(m) * step; };
        auto stepAt = [&](const Lane& lane, std::size_t m) { return m + 1 == lane.needed ? lane.lastStep : step; };

        auto finish = [&](Lane& lane, StopReason reason) {
            const std::size_t i = lane.strand;
            const Vec3f* pts = lane.points.data();  // pts[0 .. taken]
            const std::size_t taken = lane.k;
            if (!inputMode) {
                stepPoints[i].assign(pts, pts + taken + 1);
                if (taken == 0) stepPoints[i].push_back(pts[0]);
            } else {
                const std::size_t n = in.size(i);
                const std::vector<double>& target = lane.target;
                const double reached = arcAt(lane, taken);
                Vec3f* out = positions.data() + in.begin(i);
                std::size_t u = 0;
                if (taken == 0) {
                    out[u++] = pts[0];
                } else {
                    // Vertices on whole steps: step m spans [m·step, (m+1)·step]. The last step of
                    // a full-length trace is shorter; vertices on it are placed separately.
                    const bool shortLast = taken == lane.needed;
                    const std::size_t whole = shortLast ? taken - 1 : taken;
                    const double wholeEnd = double(whole) * step, invStep = 1.0 / step;
                    std::size_t j = 0;
                    for (; j < n && target[j] <= wholeEnd; ++j) {
                        const double x = target[j] * invStep;
                        const std::size_t m = std::min(std::size_t(x), whole - (whole > 0));
                        out[u++] = pts[m] + (pts[m + 1] - pts[m]) * float(x - double(m));
                    }
                    for (; j < n && target[j] <= reached; ++j) {  // on the last, shorter step
                        const double f = std::min(1.0, (target[j] - wholeEnd) / lane.lastStep);
                        out[u++] = pts[whole] + (pts[whole + 1] - pts[whole]) * float(f);
                    }
                }
                if (reason == StopReason::FullLength) {
                    out[n - 1] = pts[taken];  // exactly the traced tip
                } else {
                    // Keep what was traced: the vertices passed, then the point where it stopped
                    // (fewer than n vertices, since the length was not reached), at least two.
                    const Vec3f last = pts[taken];
                    if (out[u - 1] != last) out[u++] = last;
                    if (u < 2) out[u++] = last;
                }
                used[i] = std::uint32_t(u);
            }
            reasons[i] = reason;
            steps[i] = taken;
            start(lane);
        };

        // Forward Euler in an axis-aligned world grid takes a branch-free path over the lanes:
        // each stage runs for all lanes before the next, so their chains overlap. Anything
        // unusual (outside a brick, past the active region, a vanishing field) falls back to the
        // lane's Tracer, which handles every case.
        const bool fast = params.integrator == Integrator::Euler && map.isAxisAlignedWorld();
        const Vec3d off = map.offset(), inv = map.invScale();
        const float threshold = float(params.vanishThreshold);
        openvdb::Coord origin[kLanes];
        const typename BrickedField<TreeT>::Brick* brick[kLanes] = {};
        for (int l = 0; l < kLanes; ++l) origin[l] = openvdb::Coord(std::numeric_limits<int>::max());

        const double marginLength = double(params.margin) * map.worldVoxelSize();
        auto slowStep = [&](int l) {
            Lane& lane = lanes[l];
            const double h = stepAt(lane, lane.k);
            Vec3d q;
            const Sample st = tracers[std::size_t(l)]->advance(params.integrator, lane.p, h, q);
            if (st == kOk) {
                lane.outside = 0.0;
                lane.dir = (q - lane.p) / h;
            } else if (st == kLeft && lane.k > 0 && lane.outside + h <= marginLength * (1.0 + 1e-9)) {
                // Past the active region, within the margin: continue straight.
                q = lane.p + h * lane.dir;
                lane.outside += h;
            } else {
                finish(lane, toReason(st));
                return;
            }
            ++lane.k;
            lane.p = q;
            lane.points[lane.k] = Vec3f(float(q.x()), float(q.y()), float(q.z()));
        };

        for (Lane& lane : lanes) start(lane);
        for (bool any = true; any;) {
            any = false;
            bool go[kLanes];
            for (int l = 0; l < kLanes; ++l) {
                Lane& lane = lanes[l];
                go[l] = false;
                if (!lane.busy) continue;
                any = true;
                if (lane.k == lane.limit) {
                    finish(lane, lane.limit == lane.needed ? StopReason::FullLength : StopReason::MaxSteps);
                    if (!lane.busy) continue;
                }
                go[l] = true;
            }
            if (!fast) {
                for (int l = 0; l < kLanes; ++l) if (go[l]) slowStep(l);
                continue;
            }
            Float4 r[kLanes];
            bool slow[kLanes];
            for (int l = 0; l < kLanes; ++l) {
                slow[l] = false;
                if (!go[l]) continue;
                if (lanes[l].k + 1 == lanes[l].needed) { slow[l] = true; continue; }  // the shortened last step
                const Vec3d& p = lanes[l].p;
                const double ix = (p.x() - off.x()) * inv.x(), iy = (p.y() - off.y()) * inv.y(), iz = (p.z() - off.z()) * inv.z();
                const int bx = floorToInt(ix), by = floorToInt(iy), bz = floorToInt(iz);
                const Float4* c = bricks.cell(bx, by, bz, origin[l], brick[l]);
                if (!c) { slow[l] = true; continue; }
                r[l] = BrickedField<TreeT>::blend(c, float(ix - bx), float(iy - by), float(iz - bz));
            }
            for (int l = 0; l < kLanes; ++l) {
                if (!go[l] || slow[l]) continue;
                const Float4 v = r[l];
                const float len2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2], limit = threshold * v[3];
                if (!(v[3] > 0.f) || !(len2 > limit * limit)) { slow[l] = true; continue; }
                Lane& lane = lanes[l];
                const double s = 1.0 / std::sqrt(double(len2));
                lane.dir = Vec3d(s * v[0], s * v[1], s * v[2]);
                lane.p += step * lane.dir;
                lane.outside = 0.0;
                ++lane.k;
                lane.points[lane.k] = Vec3f(float(lane.p.x()), float(lane.p.y()), float(lane.p.z()));
            }
            for (int l = 0; l < kLanes; ++l) if (slow[l]) slowStep(l);
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 256), traceRange);
    else traceRange(tbb::blocked_range<std::size_t>(0, nS));
    if (stop) throw InterruptedError("retraceStrands: interrupted");

    // Assemble.
    StrandSet out;
    out.defaults = in.defaults;
    out.rootUV = in.rootUV;
    out.strandId = in.strandId;
    if (inputMode) {
        bool compact = false;
        for (std::size_t i = 0; i < nS && !compact; ++i) compact = used[i] != in.size(i);
        if (!compact) {
            out.positions = std::move(positions);
            out.offsets = in.offsets;
            out.thickness = in.thickness;
            out.transparency = in.transparency;
            out.color = in.color;
        } else {
            // Each strand keeps the prefix of its vertices it traced.
            out.offsets.assign(nS + 1, 0);
            for (std::size_t i = 0; i < nS; ++i) out.offsets[i + 1] = out.offsets[i] + used[i];
            const std::size_t total = out.offsets[nS];
            out.positions.resize(total);
            if (!in.thickness.empty()) out.thickness.resize(total);
            if (!in.transparency.empty()) out.transparency.resize(total);
            if (!in.color.empty()) out.color.resize(total);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t i = r.begin(); i != r.end(); ++i) {
                    const std::size_t b = in.begin(i), o = out.offsets[i], u = used[i];
                    std::copy_n(positions.begin() + std::ptrdiff_t(b), u, out.positions.begin() + std::ptrdiff_t(o));
                    if (!in.thickness.empty()) std::copy_n(in.thickness.begin() + std::ptrdiff_t(b), u, out.thickness.begin() + std::ptrdiff_t(o));
                    if (!in.transparency.empty()) std::copy_n(in.transparency.begin() + std::ptrdiff_t(b), u, out.transparency.begin() + std::ptrdiff_t(o));
                    if (!in.color.empty()) std::copy_n(in.color.begin() + std::ptrdiff_t(b), u, out.color.begin() + std::ptrdiff_t(o));
                }
            });
        }
    } else {
        for (std::size_t i = 0; i < nS; ++i) out.addStrand(stepPoints[i]);
    }

    if (stats) {
        *stats = TraceStats();
        stats->strands = nS;
        for (std::size_t i = 0; i < nS; ++i) {
            stats->steps += steps[i];
            switch (reasons[i]) {
            case StopReason::FullLength: ++stats->fullLength; break;
            case StopReason::Vanished: ++stats->vanished; break;
            case StopReason::LeftField: ++stats->leftField; break;
            case StopReason::MaxSteps: ++stats->maxSteps; break;
            }
        }
    }
    if (reasonsOut) *reasonsOut = std::move(reasons);
    return out;
}

template<typename Fn>
void applyVec3(const openvdb::GridBase& field, const char* where, Fn&& fn)
{
    if (const auto* g = dynamic_cast<const openvdb::Vec3SGrid*>(&field)) return fn(*g);
    if (const auto* g = dynamic_cast<const openvdb::Vec3DGrid*>(&field)) return fn(*g);
    throw TypeError(std::string(where) + ": grid '" + field.getName() + "' holds " + field.valueType() +
                    " values; tracing needs a vector grid (vec3s or vec3d)");
}

} // namespace

double resolveStep(const openvdb::GridBase& field, const TraceParams& params)
{
    if (params.step < 0.0 || !std::isfinite(params.step)) {
        throw ValueError("step " + std::to_string(params.step) + " must be a positive finite length (0 picks half a voxel)");
    }
    if (params.step > 0.0) return params.step;
    return 0.5 * FieldMapping::fromGrid(field).worldVoxelSize();
}

StrandSet retraceStrands(const StrandSet& strands, const openvdb::GridBase& field, const TraceParams& params,
                         TraceStats* stats, std::vector<StopReason>* reasons, bool threaded,
                         openvdb::util::NullInterrupter* interrupter)
{
    if (params.margin < 0 || params.margin > 16) {
        throw ValueError("margin " + std::to_string(params.margin) + " voxels must be between 0 and 16");
    }
    if (params.vanishThreshold < 0.0 || !(params.vanishThreshold < 1.0)) {
        throw ValueError("vanish threshold " + std::to_string(params.vanishThreshold) + " must be in [0, 1)");
    }
    const double step = resolveStep(field, params);
    StrandSet out;
    applyVec3(field, "retraceStrands", [&](const auto& grid) {
        out = retraceTyped(strands, grid, params, step, stats, reasons, threaded, interrupter);
    });
    return out;
}

double meanTangentAngleDeg(const StrandSet& strands, const openvdb::GridBase& field, std::size_t* counted, bool threaded)
{
    const std::size_t nS = strands.numStrands();
    std::vector<double> sum(nS, 0.0);
    std::vector<std::size_t> count(nS, 0);
    applyVec3(field, "meanTangentAngleDeg", [&](const auto& grid) {
        using TreeT = typename std::decay_t<decltype(grid)>::TreeType;
        const FieldMapping map = FieldMapping::fromGrid(grid);
        const BrickedField<TreeT> bricks(grid.tree());
        auto body = [&](const tbb::blocked_range<std::size_t>& r) {
            Tracer<TreeT> tracer(bricks, map, 1e-3);
            std::vector<Vec3f> t;
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                t.resize(strands.size(i));
                computeTangents(strands.data(i), strands.size(i), t.data());
                for (std::size_t k = 0; k < t.size(); ++k) {
                    Vec3d dir;
                    if (t[k].lengthSqr() == 0.f) continue;
                    if (tracer.direction(Vec3d(strands.positions[strands.begin(i) + k]), dir) != kOk) continue;
                    const double c = std::max(-1.0, std::min(1.0, dir.dot(Vec3d(t[k]))));
                    sum[i] += std::acos(c);
                    ++count[i];
                }
            }
        };
        if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 64), body);
        else body(tbb::blocked_range<std::size_t>(0, nS));
    });
    double total = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < nS; ++i) { total += sum[i]; n += count[i]; }  // fixed order
    if (counted) *counted = n;
    return n ? total / double(n) * 180.0 / M_PI : 0.0;
}

double meanVertexDisplacement(const StrandSet& a, const StrandSet& b, bool threaded)
{
    if (a.numStrands() != b.numStrands()) {
        throw ValueError("meanVertexDisplacement: " + std::to_string(a.numStrands()) + " strands against " +
                         std::to_string(b.numStrands()) + "; the sets must correspond strand by strand");
    }
    const std::size_t nS = a.numStrands();
    std::vector<double> sum(nS, 0.0);
    std::vector<std::size_t> count(nS, 0);
    auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<double> sa, sb;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t na = a.size(i), nb = b.size(i);
            sa.resize(na);
            sb.resize(nb);
            arcLengths(a.data(i), na, sa.data());
            arcLengths(b.data(i), nb, sb.data());
            const Vec3f* pb = b.data(i);
            std::size_t j = 0;
            for (std::size_t k = 0; k < na; ++k) {
                const double s = sa[k];
                if (s > sb[nb - 1] + 1e-6 * std::max(1.0, sb[nb - 1])) break;
                while (j + 2 < nb && sb[j + 1] < s) ++j;
                const double len = sb[j + 1] - sb[j];
                const double f = len > 0.0 ? std::min(1.0, std::max(0.0, (s - sb[j]) / len)) : 0.0;
                const Vec3d q = Vec3d(pb[j]) + f * (Vec3d(pb[j + 1]) - Vec3d(pb[j]));
                sum[i] += (Vec3d(a.positions[a.begin(i) + k]) - q).length();
                ++count[i];
            }
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 64), body);
    else body(tbb::blocked_range<std::size_t>(0, nS));
    double total = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < nS; ++i) { total += sum[i]; n += count[i]; }
    return n ? total / double(n) : 0.0;
}

} // namespace vdbhair
