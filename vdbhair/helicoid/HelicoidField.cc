#include "HelicoidField.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parameters.h>
#include <vdbhair/Progress.h>
#include <vdbhair/SegmentWalk.h>
#include <vdbhair/Version.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/SamplerRetrace.h>
#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/HelicoidFieldSampler.h>
#include <vdbhair/io/MetaKeys.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/strands/Frames.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tree/LeafManager.h>

#include <Eigen/Dense>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>
#include <vector>

namespace vdbhair {

namespace {

using openvdb::Coord;
using openvdb::Vec3d;
using openvdb::Vec3f;

Vec3f toF(const Vec3d& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }

void copyMeta(const openvdb::GridBase& from, openvdb::GridBase& to, const std::string& name, const char* fit)
{
    for (auto it = from.beginMeta(); it != from.endMeta(); ++it) {
        if (isVdbhairMetaKey(it->first) || it->first == "creator") to.insertMeta(it->first, *it->second);
    }
    to.setName(name);
    to.setTransform(from.transform().copy());
    to.insertMeta("vdbhair_helicoid_fit", openvdb::StringMetadata(fit));
}


/// Output grids with the tangent field's topology.
HelicoidFieldGrids createHelicoidGrids(const openvdb::Vec3SGrid& tangent)
{
    HelicoidFieldGrids out;
    out.k = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
    out.alpha = openvdb::FloatGrid::create(0.f);
    out.frameT = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
    out.frameN = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
    out.k->setTree(openvdb::Vec3STree::Ptr(new openvdb::Vec3STree(tangent.tree(), openvdb::Vec3f(0.f), openvdb::TopologyCopy())));
    out.alpha->setTree(openvdb::FloatTree::Ptr(new openvdb::FloatTree(tangent.tree(), 0.f, openvdb::TopologyCopy())));
    out.frameT->setTree(openvdb::Vec3STree::Ptr(new openvdb::Vec3STree(tangent.tree(), openvdb::Vec3f(0.f), openvdb::TopologyCopy())));
    out.frameN->setTree(openvdb::Vec3STree::Ptr(new openvdb::Vec3STree(tangent.tree(), openvdb::Vec3f(0.f), openvdb::TopologyCopy())));
    return out;
}

/// Names, metadata (with the fit that made them), vector types and classes.
void finishHelicoidGrids(const openvdb::Vec3SGrid& tangent, HelicoidFieldGrids& out, const char* fit)
{
    copyMeta(tangent, *out.k, "helicoid_k", fit);
    copyMeta(tangent, *out.alpha, "helicoid_alpha", fit);
    copyMeta(tangent, *out.frameT, "frame_T", fit);
    copyMeta(tangent, *out.frameN, "frame_N", fit);
    out.k->setVectorType(openvdb::VEC_INVARIANT);
    out.frameT->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    out.frameN->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    for (openvdb::GridBase* g : {static_cast<openvdb::GridBase*>(out.k.get()), static_cast<openvdb::GridBase*>(out.alpha.get()),
                                 static_cast<openvdb::GridBase*>(out.frameT.get()), static_cast<openvdb::GridBase*>(out.frameN.get())}) {
        g->setGridClass(openvdb::GRID_UNKNOWN);
    }
}

/// One piece of a strand segment inside one voxel (the tangent field's walk, SegmentWalk.h):
/// the world midpoint of the piece, the strand's unit tangent there (the vertex tangents
/// interpolated along the segment) and the piece's length (world units).
struct SegmentPiece
{
    Coord ijk;
    Vec3d worldPos;
    Vec3d dir;
    double length;
};

/// Every piece of every segment of @a strands, ordered by voxel and, within a voxel, by strand
/// and segment (so what follows does not depend on the thread count).
std::vector<SegmentPiece> collectPieces(const StrandSet& strands, const openvdb::math::Transform& xform, bool threaded)
{
    const std::size_t n = strands.numStrands();
    std::vector<std::vector<SegmentPiece>> perStrand(n);
    auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<Vec3d> chord, vtan;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3f* p = strands.data(i);
            const std::size_t m = strands.size(i);
            if (m < 2) continue;
            chord.assign(m - 1, Vec3d(0.0));
            for (std::size_t j = 0; j + 1 < m; ++j) chord[j] = (Vec3d(p[j + 1]) - Vec3d(p[j])).unitSafe();
            // Vertex tangents: the mean of the adjacent chords (the chord at the ends).
            vtan.assign(m, Vec3d(0.0));
            for (std::size_t j = 0; j < m; ++j) {
                const Vec3d before = j > 0 ? chord[j - 1] : Vec3d(0.0), after = j + 1 < m ? chord[j] : Vec3d(0.0);
                vtan[j] = (before + after).unitSafe();
            }
            std::vector<SegmentPiece>& out = perStrand[i];
            for (std::size_t j = 0; j + 1 < m; ++j) {
                const Vec3d a(p[j]), b(p[j + 1]);
                const double len = (b - a).length();
                if (!(len > 0.0)) continue;
                walkSegment(xform.worldToIndex(a), xform.worldToIndex(b), [&](const Coord& ijk, double t0, double t1) {
                    const double u = 0.5 * (t0 + t1);
                    Vec3d d = (1.0 - u) * vtan[j] + u * vtan[j + 1];
                    d = d.lengthSqr() > 1e-12 ? d.unit() : chord[j];
                    out.push_back({ijk, a + (b - a) * u, d, (t1 - t0) * len});
                });
            }
        }
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), body);
    else body(tbb::blocked_range<std::size_t>(0, n));
    std::vector<SegmentPiece> all;
    std::size_t total = 0;
    for (const auto& v : perStrand) total += v.size();
    all.reserve(total);
    for (auto& v : perStrand) {
        all.insert(all.end(), v.begin(), v.end());
        std::vector<SegmentPiece>().swap(v);
    }
    std::stable_sort(all.begin(), all.end(), [](const SegmentPiece& x, const SegmentPiece& y) { return x.ijk < y.ijk; });
    return all;
}

struct CoordHash
{
    std::size_t operator()(const Coord& c) const
    {
        return std::size_t(std::uint32_t(c.x()) * 73856093u ^ std::uint32_t(c.y()) * 19349663u ^ std::uint32_t(c.z()) * 83492791u);
    }
};

/// The helicoid that fits the strand pieces around one voxel (see estimateHelicoidField()).
struct PieceFit
{
    Vec3d t, n;
    Eigen::Vector3d k = Eigen::Vector3d::Zero();
};

/// Fit (see the header): pieces @a near (world positions relative to the voxel centre in @a rel),
/// starting from the tangent field's direction @a t0 at the voxel; @a h the voxel size.
PieceFit fitPieces(const std::vector<const SegmentPiece*>& near, const std::vector<Vec3d>& rel, const Vec3d& t0, double h)
{
    // Measured on the benchmark's helicoid-field section (issue 19; docs/helicoids.md, "Helicoid fields in VDB").
    constexpr int kPasses = 3;         // Eq. 9 weights against the tangent field, then twice against the fit
    constexpr double kRidge = 0.01;    // on the gradient, relative to the weight: unresolved directions -> 0
    constexpr double kSupport = 1.5;   // tent weights reach zero 1.5 voxels from the centre on each axis
    constexpr double kPower = 16.0;    // Eq. 9's weight to this power: a strand 30 degrees off keeps 0.47, 60 degrees off 0.01
    const std::size_t m = near.size();
    std::vector<double> spatial(m);
    for (std::size_t j = 0; j < m; ++j) {
        double w = near[j]->length;
        for (int a = 0; a < 3; ++a) w *= std::max(0.0, 1.0 - std::abs(rel[j][a]) / (kSupport * h));
        spatial[j] = w;
    }
    Vec3d t = t0, n, b;
    {
        const Vec3f pf = perpendicularTo(toF(t));
        n = Vec3d(pf.x(), pf.y(), pf.z());
        b = t.cross(n);
    }
    Eigen::Vector4d pT = Eigen::Vector4d::Zero(), pP = Eigen::Vector4d::Zero();  // theta, phi = c + g . y / h
    Vec3d pt = t, pn = n, pb = b;  // the frame pT, pP were fitted in
    for (int pass = 0; pass < kPasses; ++pass) {
        Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
        Eigen::Vector4d rT = Eigen::Vector4d::Zero(), rP = Eigen::Vector4d::Zero();
        for (std::size_t j = 0; j < m; ++j) {
            if (!(spatial[j] > 0.0)) continue;
            const Vec3d& d = near[j]->dir;
            // Eq. 9 weight against the direction predicted at the piece (the field's at first).
            Vec3d pred = t0;
            if (pass > 0) {
                const Eigen::Vector4d x(1.0, rel[j].dot(pt) / h, rel[j].dot(pn) / h, rel[j].dot(pb) / h);
                const double th = pT.dot(x), ph = pP.dot(x);
                pred = std::cos(ph) * std::cos(th) * pt + std::cos(ph) * std::sin(th) * pn + std::sin(ph) * pb;
            }
            const double w = spatial[j] * std::pow(0.5 * (d.dot(pred) + 1.0), kPower);
            const double a = d.dot(t);
            if (!(w > 0.0) || a <= 0.0) continue;
            const Eigen::Vector4d x(1.0, rel[j].dot(t) / h, rel[j].dot(n) / h, rel[j].dot(b) / h);
            const double theta = std::atan2(d.dot(n), a);
            const double phi = std::asin(std::max(-1.0, std::min(1.0, d.dot(b))));
            A += w * x * x.transpose();
            rT += (w * theta) * x;
            rP += (w * phi) * x;
        }
        if (!(A(0, 0) > 0.0)) break;
        for (int a = 1; a < 4; ++a) A(a, a) += kRidge * A(0, 0);
        const auto ldlt = A.ldlt();
        const Eigen::Vector4d sT = ldlt.solve(rT), sP = ldlt.solve(rP);
        if (!sT.allFinite() || !sP.allFinite()) break;
        pT = sT;
        pP = sP;
        pt = t;
        pn = n;
        pb = b;
        // Re-centre the frame on the fitted direction at the voxel centre.
        const Vec3d tc = std::cos(pP(0)) * std::cos(pT(0)) * t + std::cos(pP(0)) * std::sin(pT(0)) * n + std::sin(pP(0)) * b;
        if (tc.lengthSqr() > 0.5) {
            t = tc.unit();
            n = (n - t * n.dot(t)).unit();
            b = t.cross(n);
        }
    }
    PieceFit fit;
    fit.t = t;
    // Rank-1 gradient (Eq. 1 to first order: d(y) = t + theta(y) N with theta = k . y): the
    // largest singular pair of the 2x3 gradient of (theta, phi), in the fitted frame pt, pn, pb.
    Eigen::Matrix<double, 2, 3> G;
    G << pT(1), pT(2), pT(3), pP(1), pP(2), pP(3);
    G /= h;
    Eigen::JacobiSVD<Eigen::Matrix<double, 2, 3>> svd(G, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const double sigma = svd.singularValues()(0);
    Vec3d nWorld;
    Eigen::Vector3d kFit = Eigen::Vector3d::Zero();
    if (sigma * h > 1e-3 && std::isfinite(sigma)) {
        Eigen::Vector2d u = svd.matrixU().col(0);
        Eigen::Vector3d v = svd.matrixV().col(0);
        // Sign: theta grows along the flow where it curves (kT >= 0), else along the largest component.
        Eigen::Index lead = 0;
        if (!(std::abs(v(0)) * 4.0 > v.cwiseAbs().maxCoeff())) v.cwiseAbs().maxCoeff(&lead);
        if (v(lead) < 0.0) { u = -u; v = -v; }
        nWorld = u(0) * pn + u(1) * pb;
        const Vec3d kWorld = sigma * (v(0) * pt + v(1) * pn + v(2) * pb);  // the gradient of theta
        nWorld = (nWorld - t * nWorld.dot(t)).unitSafe();
        if (nWorld.lengthSqr() > 0.5) {
            const Vec3d bWorld = t.cross(nWorld);
            kFit = Eigen::Vector3d(kWorld.dot(t), kWorld.dot(nWorld), kWorld.dot(bWorld));
        }
    }
    if (!(nWorld.lengthSqr() > 0.5)) {
        const Vec3f pf = perpendicularTo(toF(t));
        nWorld = Vec3d(pf.x(), pf.y(), pf.z());
        kFit.setZero();
    }
    fit.n = nWorld;
    fit.k = kFit;
    return fit;
}

} // namespace

namespace {

using TangentAccessor = openvdb::tree::ValueAccessor<const openvdb::Vec3STree>;

/// A voxel's helicoid: k = (kT, kN, kB), alpha, and its frame (T, N).
struct VoxelHelicoid
{
    Eigen::Vector3d k;
    double alpha;
    Vec3d t, n;
};

/// @throw ValueError unless @a tangent is an axis-aligned world-space field (both estimators).
void checkHelicoidTangent(const openvdb::Vec3SGrid& tangent)
{
    if (FieldMapping::fromGrid(tangent).space() != FieldSpace::World || !FieldMapping(tangent.constTransformPtr()).isAxisAlignedWorld()) {
        throw ValueError("estimateHelicoidField: grid '" + tangent.getName() + "' is not an axis-aligned world-space field");
    }
}

/// Fill @a out at every voxel where @a tangent has a direction, leaves in parallel: @a makeFit()
/// gives each leaf its own fitting function, (ijk, T, accessor) -> VoxelHelicoid.
template<typename MakeFit>
void fillPerVoxel(const openvdb::Vec3SGrid& tangent, HelicoidFieldGrids& out, bool threaded,
                  openvdb::util::NullInterrupter* interrupter, const MakeFit& makeFit)
{
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(out.k->tree());
    ProgressCounter progress(interrupter, "estimating the helicoid field", leaves.leafCount(), "blocks");
    leaves.foreach([&](openvdb::Vec3STree::LeafNodeType& kLeaf, std::size_t) {
        if (progress.active() && (progress.stopped() || progress.add(1))) return;
        TangentAccessor acc(tangent.tree());
        auto* aLeaf = out.alpha->tree().probeLeaf(kLeaf.origin());
        auto* tLeaf = out.frameT->tree().probeLeaf(kLeaf.origin());
        auto* nLeaf = out.frameN->tree().probeLeaf(kLeaf.origin());
        auto fit = makeFit();
        for (auto it = kLeaf.beginValueOn(); it; ++it) {
            const Coord ijk = it.getCoord();
            const Vec3d T = Vec3d(acc.getValue(ijk));
            if (!(T.lengthSqr() > 0.0)) continue;
            const VoxelHelicoid v = fit(ijk, T, acc);
            it.setValue(openvdb::Vec3f(float(v.k(0)), float(v.k(1)), float(v.k(2))));
            aLeaf->setValueOnly(it.pos(), float(v.alpha));
            tLeaf->setValueOnly(it.pos(), toF(v.t));
            nLeaf->setValueOnly(it.pos(), toF(v.n));
        }
    }, threaded);
    if (progress.stopped()) throw InterruptedError("estimateHelicoidField: interrupted");
}

} // namespace

HelicoidFieldGrids estimateHelicoidField(const openvdb::Vec3SGrid& tangent, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    checkHelicoidTangent(tangent);
    const double h = tangent.voxelSize().x();
    HelicoidFieldGrids out = createHelicoidGrids(tangent);
    fillPerVoxel(tangent, out, threaded, interrupter, [&] {
        return [&](const Coord& ijk, const Vec3d& T, TangentAccessor& acc) {
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
            return VoxelHelicoid{k, alpha, t, n};
        };
    });
    finishHelicoidGrids(tangent, out, "Eq. 1 to first order, least squares over the 26 neighbours' field directions");
    return out;
}

HelicoidFieldGrids estimateHelicoidField(const StrandSet& strands, const openvdb::Vec3SGrid& tangent, bool threaded,
                                         openvdb::util::NullInterrupter* interrupter)
{
    checkHelicoidTangent(tangent);
    const double h = tangent.voxelSize().x();
    HelicoidFieldGrids out = createHelicoidGrids(tangent);

    // The strand pieces in every voxel, and where each voxel's run of them starts and ends.
    const std::vector<SegmentPiece> pieces = collectPieces(strands, tangent.transform(), threaded);
    std::unordered_map<Coord, std::pair<std::size_t, std::size_t>, CoordHash> runs;
    runs.reserve(std::size_t(tangent.activeVoxelCount()) + 1);
    for (std::size_t i = 0; i < pieces.size();) {
        std::size_t j = i + 1;
        while (j < pieces.size() && pieces[j].ijk == pieces[i].ijk) ++j;
        runs.emplace(pieces[i].ijk, std::make_pair(i, j));
        i = j;
    }

    // Each leaf gathers the nearby pieces into scratch of its own.
    fillPerVoxel(tangent, out, threaded, interrupter, [&] {
        return [&, near = std::vector<const SegmentPiece*>(), rel = std::vector<Vec3d>()](const Coord& ijk, const Vec3d& T, TangentAccessor&) mutable {
            const Vec3d centre = tangent.transform().indexToWorld(ijk);
            near.clear();
            rel.clear();
            for (int dx = -1; dx <= 1; ++dx) {
                for (int dy = -1; dy <= 1; ++dy) {
                    for (int dz = -1; dz <= 1; ++dz) {
                        const auto r = runs.find(ijk.offsetBy(dx, dy, dz));
                        if (r == runs.end()) continue;
                        for (std::size_t i = r->second.first; i < r->second.second; ++i) {
                            near.push_back(&pieces[i]);
                            rel.push_back(pieces[i].worldPos - centre);
                        }
                    }
                }
            }
            const PieceFit fit = fitPieces(near, rel, T.unit(), h);
            return VoxelHelicoid{fit.k, 0.0, fit.t, fit.n};
        };
    });
    finishHelicoidGrids(tangent, out, "Eq. 1 to first order, weighted least squares over the strand pieces within a voxel (Eq. 9 weights)");
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
            // What makes them: the command line's `field --helicoid`, the library's function.
            throw ParamError<LookupError>({std::string(e.what()) + " (a helicoid field holds the grids ",
                                           ParamName{"'vdbhair field --helicoid'", "estimateHelicoidField"}, " makes)"});
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
