#include "HelicoidField.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/MetaKeys.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/SegmentWalk.h>
#include <vdbhair/field/SamplerRetrace.h>
#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/HelicoidFieldSampler.h>
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
            throw LookupError(std::string(e.what()) + " (a helicoid field holds the grids estimateHelicoidField makes)");
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

StrandSet retraceHelicoidField(const StrandSet& in, const HelicoidFieldGrids& field, const TraceParams& params,
                               TraceStats* stats, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const char* where = "retraceHelicoidField";
    params.validate(where);
    const double voxelSize = field.k->voxelSize().x();
    const double step = resolveStepLength(params.step, voxelSize, where);
    StrandSet out;
    std::vector<StopReason> reasons;
    std::vector<std::size_t> steps;
    retraceWithSampler(in, params, step, voxelSize, [&] { return HelicoidFieldSampler(field, params.vanishThreshold); }, out,
                       reasons, steps, threaded, interrupter, "tracing through the helicoid field", where);
    if (stats) *stats = TraceStats::count(reasons, steps);
    return out;
}

} // namespace vdbhair
