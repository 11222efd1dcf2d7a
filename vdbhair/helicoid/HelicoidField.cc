#include "HelicoidField.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/MetaKeys.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/SegmentWalk.h>
#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/strands/Frames.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tree/LeafManager.h>

#include <Eigen/Dense>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

namespace vdbhair {

namespace {

using openvdb::Coord;
using openvdb::Vec3d;
using openvdb::Vec3f;

Vec3f toF(const Vec3d& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }

void copyMeta(const openvdb::GridBase& from, openvdb::GridBase& to, const std::string& name)
{
    for (auto it = from.beginMeta(); it != from.endMeta(); ++it) {
        if (isVdbhairMetaKey(it->first) || it->first == "creator") to.insertMeta(it->first, *it->second);
    }
    to.setName(name);
    to.setTransform(from.transform().copy());
    to.insertMeta("vdbhair_helicoid_fit", openvdb::StringMetadata("Eq. 1 to first order, least squares over the 26 neighbours"));
}

} // namespace

HelicoidFieldGrids estimateHelicoidField(const openvdb::Vec3SGrid& tangent, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    if (FieldMapping::fromGrid(tangent).space() != FieldSpace::World || !FieldMapping(tangent.constTransformPtr()).isAxisAlignedWorld()) {
        throw ValueError("estimateHelicoidField: grid '" + tangent.getName() + "' is not an axis-aligned world-space field");
    }
    const double h = tangent.voxelSize().x();
    HelicoidFieldGrids out;
    out.k = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
    out.alpha = openvdb::FloatGrid::create(0.f);
    out.frameT = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
    out.frameN = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
    out.k->setTree(openvdb::Vec3STree::Ptr(new openvdb::Vec3STree(tangent.tree(), openvdb::Vec3f(0.f), openvdb::TopologyCopy())));
    out.alpha->setTree(openvdb::FloatTree::Ptr(new openvdb::FloatTree(tangent.tree(), 0.f, openvdb::TopologyCopy())));
    out.frameT->setTree(openvdb::Vec3STree::Ptr(new openvdb::Vec3STree(tangent.tree(), openvdb::Vec3f(0.f), openvdb::TopologyCopy())));
    out.frameN->setTree(openvdb::Vec3STree::Ptr(new openvdb::Vec3STree(tangent.tree(), openvdb::Vec3f(0.f), openvdb::TopologyCopy())));

    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(out.k->tree());
    ProgressCounter progress(interrupter, "estimating the helicoid field", leaves.leafCount(), "blocks");
    leaves.foreach([&](openvdb::Vec3STree::LeafNodeType& kLeaf, std::size_t) {
        if (progress.active() && (progress.stopped() || progress.add(1))) return;
        openvdb::tree::ValueAccessor<const openvdb::Vec3STree> acc(tangent.tree());
        auto* aLeaf = out.alpha->tree().probeLeaf(kLeaf.origin());
        auto* tLeaf = out.frameT->tree().probeLeaf(kLeaf.origin());
        auto* nLeaf = out.frameN->tree().probeLeaf(kLeaf.origin());
        for (auto it = kLeaf.beginValueOn(); it; ++it) {
            const Coord ijk = it.getCoord();
            const Vec3d T = Vec3d(acc.getValue(ijk));
            if (!(T.lengthSqr() > 0.0)) continue;
            const Vec3d t = T.unit();
            // Curvature vector (T·∇)T by central differences one voxel along T (index units).
            const Vec3d ip = ijk.asVec3d();
            openvdb::Vec3f ahead(0.f), behind(0.f);
            openvdb::tools::BoxSampler::sample(acc, ip + t, ahead);
            openvdb::tools::BoxSampler::sample(acc, ip - t, behind);
            Vec3d curv = (Vec3d(ahead).unitSafe() - Vec3d(behind).unitSafe()) / (2.0 * h);
            curv -= t * curv.dot(t);
            Vec3d n;
            if (curv.length() * h > 1e-3) n = curv.unit();
            else {
                const Vec3f pf = perpendicularTo(toF(t));
                n = Vec3d(pf.x(), pf.y(), pf.z());
            }
            const Vec3d b = t.cross(n);
            // Least squares over the neighbours.
            Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
            Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
            double tt = 0.0, tp = 0.0;
            int used = 0;
            for (int dx = -1; dx <= 1; ++dx) {
                for (int dy = -1; dy <= 1; ++dy) {
                    for (int dz = -1; dz <= 1; ++dz) {
                        if (!dx && !dy && !dz) continue;
                        const Coord c = ijk.offsetBy(dx, dy, dz);
                        openvdb::Vec3f v;
                        if (!acc.probeValue(c, v) || !(v.lengthSqr() > 0.f)) continue;
                        const Vec3d d = Vec3d(v).unit();
                        const double a = d.dot(t);
                        if (a <= 0.0) continue;
                        const Vec3d off = Vec3d(dx, dy, dz) * h;
                        const Eigen::Vector3d y(off.dot(t), off.dot(n), off.dot(b));
                        const double theta = std::atan2(d.dot(n), a);
                        const double phi = std::asin(std::max(-1.0, std::min(1.0, d.dot(b))));
                        A += y * y.transpose();
                        rhs += theta * y;
                        tt += theta * theta;
                        tp += theta * phi;
                        ++used;
                    }
                }
            }
            Eigen::Vector3d k = Eigen::Vector3d::Zero();
            double alpha = 0.0;
            if (used >= 3) {
                A += Eigen::Matrix3d::Identity() * (1e-6 * A.trace() + 1e-30);
                k = A.ldlt().solve(rhs);
                if (tt > 1e-12) alpha = tp / tt;
                if (!k.allFinite()) k.setZero();
                if (!std::isfinite(alpha)) alpha = 0.0;
            }
            it.setValue(openvdb::Vec3f(float(k(0)), float(k(1)), float(k(2))));
            aLeaf->setValueOnly(it.pos(), float(alpha));
            tLeaf->setValueOnly(it.pos(), toF(t));
            nLeaf->setValueOnly(it.pos(), toF(n));
        }
    }, threaded);
    if (progress.stopped()) throw InterruptedError("estimateHelicoidField: interrupted");

    copyMeta(tangent, *out.k, "helicoid_k");
    copyMeta(tangent, *out.alpha, "helicoid_alpha");
    copyMeta(tangent, *out.frameT, "frame_T");
    copyMeta(tangent, *out.frameN, "frame_N");
    out.k->setVectorType(openvdb::VEC_INVARIANT);
    out.frameT->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    out.frameN->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    for (openvdb::GridBase* g : {static_cast<openvdb::GridBase*>(out.k.get()), static_cast<openvdb::GridBase*>(out.alpha.get()),
                                 static_cast<openvdb::GridBase*>(out.frameT.get()), static_cast<openvdb::GridBase*>(out.frameN.get())}) {
        g->setGridClass(openvdb::GRID_UNKNOWN);
    }
    return out;
}

HelicoidFieldGrids readHelicoidField(const std::string& path)
{
    const std::string where = "readHelicoidField(" + path + ")";
    auto get = [&](const char* name) {
        openvdb::GridBase::Ptr g;
        try {
            g = readVdbGrid(path, name, where);
        } catch (const LookupError& e) {
            throw LookupError(std::string(e.what()) + " (write a helicoid field with 'vdbhair field --helicoid')");
        }
        return g;
    };
    HelicoidFieldGrids f;
    f.k = openvdb::GridBase::grid<openvdb::Vec3SGrid>(get("helicoid_k"));
    f.alpha = openvdb::GridBase::grid<openvdb::FloatGrid>(get("helicoid_alpha"));
    f.frameT = openvdb::GridBase::grid<openvdb::Vec3SGrid>(get("frame_T"));
    f.frameN = openvdb::GridBase::grid<openvdb::Vec3SGrid>(get("frame_N"));
    if (!f.k || !f.alpha || !f.frameT || !f.frameN) {
        throw TypeError(where + ": helicoid_k, frame_T and frame_N must be vec3s grids and helicoid_alpha a float grid");
    }
    return f;
}

namespace {

/// The blended helicoid direction at world points (one per thread).
class HelicoidSampler
{
public:
    explicit HelicoidSampler(const HelicoidFieldGrids& f)
        : mK(f.k->tree()), mA(f.alpha->tree()), mT(f.frameT->tree()), mN(f.frameN->tree()),
          mInv(1.0 / f.k->voxelSize().x()), mH(f.k->voxelSize().x()), mOff(f.k->transform().indexToWorld(Vec3d(0.0))) {}

    /// @return the summed weight of the active corners (0: outside the field).
    double direction(const Vec3d& world, double threshold, Vec3d& dir)
    {
        const Vec3d ip = (world - mOff) * mInv;
        const int bx = floorToInt(ip.x()), by = floorToInt(ip.y()), bz = floorToInt(ip.z());
        const double fx = ip.x() - bx, fy = ip.y() - by, fz = ip.z() - bz;
        Vec3d sum(0.0);
        double active = 0.0;
        for (int i = 0; i < 8; ++i) {
            const int dx = i >> 2, dy = (i >> 1) & 1, dz = i & 1;
            const Coord c(bx + dx, by + dy, bz + dz);
            openvdb::Vec3f k;
            if (!mK.probeValue(c, k)) continue;
            const double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
            if (w <= 0.0) continue;
            Helicoid hel;
            hel.k = {k.x(), k.y(), k.z(), mA.getValue(c)};
            const Vec3d t(mT.getValue(c)), n(mN.getValue(c));
            if (!(t.lengthSqr() > 0.0)) continue;
            hel.q.t = t;
            hel.q.n = n;
            hel.q.b = t.cross(n);
            hel.p0 = mOff + c.asVec3d() * mH;
            double th = 0.0;
            sum += w * hel.tangent(world, th);
            active += w;
        }
        if (!(active > 0.0)) return 0.0;
        const double len = sum.length();
        if (!(len > threshold * active)) return -1.0;
        dir = sum / len;
        return active;
    }

private:
    openvdb::tree::ValueAccessor<const openvdb::Vec3STree> mK;
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> mA;
    openvdb::tree::ValueAccessor<const openvdb::Vec3STree> mT, mN;
    double mInv, mH;
    Vec3d mOff;
};

} // namespace

StrandSet retraceHelicoidField(const StrandSet& in, const HelicoidFieldGrids& field, const TraceParams& params,
                               TraceStats* stats, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const double step = params.step > 0.0 ? params.step : 0.5 * field.k->voxelSize().x();
    const double marginLength = double(params.margin) * field.k->voxelSize().x();
    const std::size_t nS = in.numStrands();
    std::vector<std::vector<Vec3f>> traced(nS);
    std::vector<StopReason> reasons(nS, StopReason::FullLength);
    std::vector<std::size_t> steps(nS, 0);
    ProgressCounter progress(interrupter, "tracing through the helicoid field", nS, "strands");
    auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        if (progress.stopped()) return;
        HelicoidSampler sampler(field);
        std::vector<double> target;
        std::vector<Vec3d> pts;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t n = in.size(i);
            target.resize(n);
            arcLengths(in.data(i), n, target.data());
            const double length = target.back();
            const std::size_t needed = stepCount(length, step);
            const std::size_t limit = params.maxSteps ? std::min(needed, params.maxSteps) : needed;
            pts.assign(1, Vec3d(in.root(i)));
            Vec3d p = pts[0], last(0.0);
            double outside = 0.0;
            StopReason reason = limit == needed ? StopReason::FullLength : StopReason::MaxSteps;
            auto dirAt = [&](const Vec3d& x, Vec3d& d) {
                const double a = sampler.direction(x, params.vanishThreshold, d);
                return a > 0.0 ? 0 : (a == 0.0 ? 1 : 2);  // 0 ok, 1 left, 2 vanished
            };
            for (std::size_t k = 0; k < limit; ++k) {
                const double h = k + 1 == needed ? length - double(needed - 1) * step : step;
                Vec3d k1, k2, k3, k4, q;
                int st = dirAt(p, k1);
                if (st == 0 && params.integrator == Integrator::RK2) {
                    st = dirAt(p + 0.5 * h * k1, k2);
                    q = p + h * k2;
                } else if (st == 0 && params.integrator == Integrator::RK4) {
                    st = dirAt(p + 0.5 * h * k1, k2);
                    if (st == 0) st = dirAt(p + 0.5 * h * k2, k3);
                    if (st == 0) st = dirAt(p + h * k3, k4);
                    q = p + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                } else {
                    q = p + h * k1;
                }
                if (st == 0) {
                    last = (q - p) / h;
                    outside = 0.0;
                } else if (st == 1 && k > 0 && outside + h <= marginLength * (1.0 + 1e-9)) {
                    q = p + h * last;  // past the active region, within the margin: straight on
                    outside += h;
                } else {
                    reason = st == 1 ? StopReason::LeftField : StopReason::Vanished;
                    break;
                }
                p = q;
                pts.push_back(p);
                steps[i] = k + 1;
            }
            if (steps[i] < limit && reason == StopReason::FullLength) reason = StopReason::LeftField;
            // Output vertices at the input's arc lengths (step m spans [m·step, (m+1)·step]).
            std::vector<Vec3f>& out = traced[i];
            const std::size_t taken = pts.size() - 1;
            const double reached = taken == needed ? length : double(taken) * step;
            for (std::size_t j = 0; j < n && target[j] <= reached + 1e-12 * length; ++j) {
                if (taken == 0) { out.push_back(toF(pts[0])); continue; }
                const std::size_t m = std::min(std::size_t(target[j] / step), taken - 1);
                const double seg = m + 1 == needed ? length - double(needed - 1) * step : step;
                const double f = std::min(1.0, std::max(0.0, (target[j] - double(m) * step) / seg));
                out.push_back(toF(pts[m] + f * (pts[m + 1] - pts[m])));
            }
            if (reason == StopReason::FullLength) out.back() = toF(pts.back());
            else if (out.back() != toF(pts.back())) out.push_back(toF(pts.back()));
            if (out.size() < 2) out.push_back(out.back());
            if (out.size() > n) out.resize(n);
            reasons[i] = reason;
        }
    };
    // Blocks of 64 strands, each counted when done (the whole range at once would never report).
    auto counted = [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t b = r.begin(); b < r.end(); b += 64) {
            const std::size_t e = std::min(r.end(), b + 64);
            body(tbb::blocked_range<std::size_t>(b, e));
            if (progress.add(e - b)) return;
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 64), counted);
    else counted(tbb::blocked_range<std::size_t>(0, nS));
    if (progress.stopped()) throw InterruptedError("retraceHelicoidField: interrupted");

    StrandSet out;
    out.defaults = in.defaults;
    for (std::size_t i = 0; i < nS; ++i) out.addStrand(traced[i]);
    if (stats) {
        *stats = TraceStats();
        stats->strands = nS;
        for (std::size_t i = 0; i < nS; ++i) {
            stats->steps += steps[i];
            stats->fullLength += reasons[i] == StopReason::FullLength;
            stats->vanished += reasons[i] == StopReason::Vanished;
            stats->leftField += reasons[i] == StopReason::LeftField;
            stats->maxSteps += reasons[i] == StopReason::MaxSteps;
        }
    }
    return out;
}

} // namespace vdbhair
