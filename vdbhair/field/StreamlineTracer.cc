#include "StreamlineTracer.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/FieldSampler.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/openvdb.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
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
    Tracer(const TreeT& tree, const FieldMapping& map, double threshold, int margin)
        : mSampler(tree), mMap(map), mThreshold(threshold), mMargin(margin) {}

    /// Unit field direction at a world point.
    Sample direction(const Vec3d& world, Vec3d& dir)
    {
        Vec3d v;
        const Vec3d ip = mMap.worldToIndex(world);
        double active = mSampler.sample(ip, v);
        if (!(active > 0.0)) {
            if (mMargin <= 0) return kLeft;
            active = mSampler.extrapolate(ip, mMargin, v);
            if (!(active > 0.0)) return kLeft;
        }
        const double len = v.length();
        if (!(len > mThreshold * active)) return kVanished;
        dir = v / len;
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
    int mMargin;
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
    const std::size_t nS = in.numStrands();
    const bool inputMode = params.vertices == RetraceVertices::Input;

    // Input mode writes into the input's layout (compacted afterwards if a strand stops early);
    // step mode collects each strand's points.
    std::vector<Vec3f> positions(inputMode ? in.numVertices() : 0);
    std::vector<std::uint32_t> used(nS, 0);
    std::vector<std::vector<Vec3f>> stepPoints(inputMode ? 0 : nS);
    std::vector<StopReason> reasons(nS, StopReason::FullLength);
    std::vector<std::size_t> steps(nS, 0);
    std::atomic<bool> stop{false};

    auto traceRange = [&](const tbb::blocked_range<std::size_t>& r) {
        Tracer<TreeT> tracer(grid.tree(), map, params.vanishThreshold, params.margin);
        std::vector<double> target;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (interrupter && (i & 255) == 0 && interrupter->wasInterrupted()) { stop = true; return; }
            if (stop) return;
            const std::size_t n = in.size(i), b = in.begin(i);
            target.resize(n);
            arcLengths(in.data(i), n, target.data());
            const double length = target[n - 1];
            Vec3f* out = inputMode ? positions.data() + b : nullptr;
            std::vector<Vec3f>* pts = inputMode ? nullptr : &stepPoints[i];
            auto emit = [&](const Vec3d& p) {
                const Vec3f v(float(p.x()), float(p.y()), float(p.z()));
                if (inputMode) out[used[i]++] = v;
                else pts->push_back(v);
            };
            Vec3d p(in.root(i));
            emit(p);
            std::size_t j = 1;  // next input vertex (input mode)
            double s = 0.0;
            std::size_t k = 0;
            const double eps = 1e-9 * std::max(length, step);
            StopReason reason = StopReason::FullLength;
            while (length - s > eps) {
                if (params.maxSteps && k >= params.maxSteps) { reason = StopReason::MaxSteps; break; }
                const double h = std::min(step, length - s);
                Vec3d q;
                const Sample st = tracer.advance(params.integrator, p, h, q);
                if (st != kOk) { reason = toReason(st); break; }
                const double ds = (q - p).length();
                ++k;
                if (inputMode) {
                    while (j < n && target[j] <= s + ds) {
                        const double f = ds > 0.0 ? (target[j] - s) / ds : 1.0;
                        emit(p + f * (q - p));
                        ++j;
                    }
                } else {
                    emit(q);
                }
                p = q;
                s += ds;
                if (ds <= 0.0) { reason = StopReason::Vanished; break; }
            }
            if (reason == StopReason::FullLength) {
                while (inputMode && j < n) { emit(p); ++j; }  // rounding at the tip
            } else if (inputMode) {
                // Keep what was traced: the vertices passed (fewer than n, since the length was
                // not reached), then the point where it stopped; at least two vertices.
                const Vec3f last(float(p.x()), float(p.y()), float(p.z()));
                if (out[used[i] - 1] != last) out[used[i]++] = last;
                if (used[i] < 2) out[used[i]++] = last;
            } else if (pts->size() < 2) {
                pts->push_back(pts->back());
            }
            reasons[i] = reason;
            steps[i] = k;
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 64), traceRange);
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
            for (std::size_t i = 0; i < nS; ++i) {
                const std::size_t b = in.begin(i), u = used[i];
                out.positions.insert(out.positions.end(), positions.begin() + std::ptrdiff_t(b), positions.begin() + std::ptrdiff_t(b + u));
                out.offsets.push_back(std::uint32_t(out.positions.size()));
                if (!in.thickness.empty()) out.thickness.insert(out.thickness.end(), in.thickness.begin() + std::ptrdiff_t(b), in.thickness.begin() + std::ptrdiff_t(b + u));
                if (!in.transparency.empty()) out.transparency.insert(out.transparency.end(), in.transparency.begin() + std::ptrdiff_t(b), in.transparency.begin() + std::ptrdiff_t(b + u));
                if (!in.color.empty()) out.color.insert(out.color.end(), in.color.begin() + std::ptrdiff_t(b), in.color.begin() + std::ptrdiff_t(b + u));
            }
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
        auto body = [&](const tbb::blocked_range<std::size_t>& r) {
            Tracer<TreeT> tracer(grid.tree(), map, 1e-3, 0);  // the field where it is defined
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
