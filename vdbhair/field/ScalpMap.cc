#include "ScalpMap.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/Rotation.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/RayIntersector.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {

ScalpMap::ScalpMap(const ScalpSphere& sphere) : mSphere(sphere) { axesFromUp(); }

void ScalpMap::axesFromUp()
{
    // The sphere's own axes, as ScalpSpace.cc builds them (x kept near world x).
    mUp = mSphere.up.unitSafe();
    if (mUp.lengthSqr() == 0.0) mUp = Vec3d(0.0, 1.0, 0.0);
    mSphere.up = mUp;
    Vec3d x(1.0, 0.0, 0.0);
    if (std::abs(mUp.dot(x)) > 0.9) x = Vec3d(0.0, 0.0, -1.0);
    mRight = (x - mUp * mUp.dot(x)).unitSafe();
    mForward = mRight.cross(mUp);
}

ScalpMap::ScalpMap(const ScalpSphere& sphere, const openvdb::FloatGrid& surface, int resolution) : ScalpMap(sphere)
{
    if (surface.getGridClass() != openvdb::GRID_LEVEL_SET)
        throw TypeError("scalp map: grid '" + surface.getName() + "' is not a level set (class " +
                        openvdb::GridBase::gridClassToString(surface.getGridClass()) + ")");
    if (resolution < kMinResolution || resolution > kMaxResolution)
        throw ValueError("scalp map: resolution " + std::to_string(resolution) + " is outside [" + std::to_string(kMinResolution) +
                         ", " + std::to_string(kMaxResolution) + "]");
    using Sampler = openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler>;
    {
        const openvdb::FloatGrid::ConstAccessor acc = surface.getConstAccessor();
        Sampler sampler(acc, surface.transform());
        if (sampler.wsSample(mSphere.center) >= 0.0)
            throw ValueError("scalp map: the parameterization's centre (" + std::to_string(mSphere.center.x()) + ", " +
                             std::to_string(mSphere.center.y()) + ", " + std::to_string(mSphere.center.z()) +
                             ") is not inside the scalp surface: rays from it must cross the scalp once");
    }
    mResolution = resolution;
    const std::size_t count = std::size_t(resolution) * resolution;
    mD.assign(count, 1.0f);
    mNormal.assign(count, Vec3f(0.0f));
    std::vector<std::uint8_t> missed(count, 0);
    const double dx = surface.voxelSize()[0];
    // One intersector per row (it holds accessors); rows are independent, so the table does not
    // depend on the thread count.
    tbb::parallel_for(tbb::blocked_range<int>(0, resolution), [&](const tbb::blocked_range<int>& rows) {
        openvdb::tools::LevelSetRayIntersector<openvdb::FloatGrid> intersector(surface);
        const openvdb::FloatGrid::ConstAccessor acc = surface.getConstAccessor();
        Sampler sampler(acc, surface.transform());
        for (int j = rows.begin(); j != rows.end(); ++j) {
            for (int i = 0; i < resolution; ++i) {
                const double u = M_PI * (i + 0.5) / resolution, v = M_PI * (j + 0.5) / resolution;
                const Vec3d local = unitDirection(u, v);
                const Vec3d dir = (mRight * local.x() + mUp * local.y() + mForward * local.z()).unitSafe();
                const std::size_t k = std::size_t(j) * resolution + i;
                openvdb::math::Ray<double> ray(mSphere.center, dir);
                openvdb::Vec3d hit;
                double t = 0.0;
                Vec3d normal = dir;
                if (intersector.intersectsWS(ray, hit, t) && t > 0.0) {
                    mD[k] = float(t / mSphere.radius);
                    // Central-difference gradient of the level set at the hit.
                    Vec3d g(sampler.wsSample(hit + Vec3d(dx, 0, 0)) - sampler.wsSample(hit - Vec3d(dx, 0, 0)),
                            sampler.wsSample(hit + Vec3d(0, dx, 0)) - sampler.wsSample(hit - Vec3d(0, dx, 0)),
                            sampler.wsSample(hit + Vec3d(0, 0, dx)) - sampler.wsSample(hit - Vec3d(0, 0, dx)));
                    if (g.length() > 1e-12) normal = g.unitSafe();
                } else {
                    missed[k] = 1;
                }
                mNormal[k] = Vec3f(normal);
            }
        }
    });
    for (std::uint8_t m : missed) mMisses += m;
}

ScalpMap::ScalpMap(const ScalpSphere& sphere, std::vector<float> distances, int resolution) : ScalpMap(sphere)
{
    if (resolution < kMinResolution || resolution > kMaxResolution)
        throw ValueError("scalp map: resolution " + std::to_string(resolution) + " is outside [" + std::to_string(kMinResolution) +
                         ", " + std::to_string(kMaxResolution) + "]");
    const std::size_t count = std::size_t(resolution) * resolution;
    if (distances.size() != count)
        throw ValueError("scalp map: " + std::to_string(distances.size()) + " distances for a table of " + std::to_string(resolution) +
                         "² = " + std::to_string(count) + " nodes");
    for (std::size_t k = 0; k < count; ++k) {
        if (!(distances[k] > 0.0f) || !std::isfinite(distances[k]))
            throw ValueError("scalp map: distance " + std::to_string(distances[k]) + " at node " + std::to_string(k) +
                             " is not a positive finite number");
    }
    mResolution = resolution;
    mD = std::move(distances);
    mNormal.assign(count, Vec3f(0.0f));
    // The tabulated surface's points, and each node's normal from central differences along u and
    // v (one-sided at the table's edges), turned outward.
    const auto point = [&](int i, int j) {
        const Vec3d local = unitDirection(M_PI * (i + 0.5) / resolution, M_PI * (j + 0.5) / resolution);
        return (mRight * local.x() + mUp * local.y() + mForward * local.z()).unitSafe() * double(mD[std::size_t(j) * resolution + i]);
    };
    for (int j = 0; j < resolution; ++j) {
        for (int i = 0; i < resolution; ++i) {
            const Vec3d du = point(std::min(i + 1, resolution - 1), j) - point(std::max(i - 1, 0), j);
            const Vec3d dv = point(i, std::min(j + 1, resolution - 1)) - point(i, std::max(j - 1, 0));
            const Vec3d radial = point(i, j).unitSafe();
            Vec3d n = du.cross(dv).unitSafe();
            if (n.lengthSqr() == 0.0) n = radial;
            if (n.dot(radial) < 0.0) n = -n;
            mNormal[std::size_t(j) * resolution + i] = Vec3f(n);
        }
    }
}

Vec3d ScalpMap::unitDirection(double u, double v) const
{
    const double cu = 1.0 / std::tan(u), cv = 1.0 / std::tan(v);
    const double h = 2.0 / (cu * cu + cv * cv + 1.0);
    return Vec3d(h * cu, h - 1.0, h * cv);
}

void ScalpMap::lookup(double u, double v, double& d, Vec3d& normal) const
{
    const double fu = std::clamp(u / M_PI * mResolution - 0.5, 0.0, double(mResolution - 1));
    const double fv = std::clamp(v / M_PI * mResolution - 0.5, 0.0, double(mResolution - 1));
    const int i0 = std::min(int(fu), mResolution - 2), j0 = std::min(int(fv), mResolution - 2);
    const double a = fu - i0, b = fv - j0;
    const auto at = [&](int i, int j) { return std::size_t(j) * mResolution + i; };
    const double w[4] = {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b};
    const std::size_t k[4] = {at(i0, j0), at(i0 + 1, j0), at(i0, j0 + 1), at(i0 + 1, j0 + 1)};
    d = 0.0;
    normal = Vec3d(0.0);
    for (int q = 0; q < 4; ++q) {
        d += w[q] * mD[k[q]];
        normal += w[q] * Vec3d(mNormal[k[q]]);
    }
    normal = normal.unitSafe();
}

double ScalpMap::scalpDistance(double u, double v) const
{
    if (mD.empty()) return 1.0;
    double d;
    Vec3d n;
    lookup(u, v, d, n);
    return d;
}

Vec3d ScalpMap::toScalp(const Vec3d& worldPos) const
{
    Vec3d s = worldToScalp(mSphere, worldPos);  // w = |p'| - 1
    if (!mD.empty()) s.z() += 1.0 - scalpDistance(s.x(), s.y());
    return s;
}

Vec3d ScalpMap::toWorld(const Vec3d& uvw) const
{
    const double d = scalpDistance(uvw.x(), uvw.y());
    return scalpToWorld(mSphere, Vec3d(uvw.x(), uvw.y(), uvw.z() + d - 1.0));
}

ScalpFrame ScalpMap::frame(double u, double v) const
{
    Vec3d n;
    if (mD.empty()) {
        const Vec3d local = unitDirection(u, v);
        n = (mRight * local.x() + mUp * local.y() + mForward * local.z()).unitSafe();
    } else {
        double d;
        lookup(u, v, d, n);
    }
    // The shortest rotation taking the sphere's up (the paper's +y) onto n, applied to its x and z;
    // n opposite up: half a turn about x, as Rodrigues' formula at cosine -1, sine 0 (halfTurn()'s
    // exact reflection can differ from it in the sign of a zero).
    ScalpFrame f;
    f.n = n;
    Vec3d axis;
    double c, s;
    if (shortestRotation(mUp, n, axis, c, s)) {
        f.t = rotateAbout(mRight, axis, c, s);
        f.b = rotateAbout(mForward, axis, c, s);
    } else if (c > 0.0) {
        f.t = mRight;
        f.b = mForward;
    } else {
        f.t = rotateAbout(mRight, mRight, -1.0, 0.0);
        f.b = rotateAbout(mForward, mRight, -1.0, 0.0);
    }
    return f;
}

std::shared_ptr<ScalpMap> scalpMapOfPoints(const std::vector<Vec3f>& roots, const Vec3d& up, openvdb::FloatGrid::ConstPtr surface,
                                           Vec3d* upUsed, int resolution)
{
    ScalpSphere sphere = fitScalpSphere(roots, up.length() > 0.0 ? up : Vec3d(0.0, 1.0, 0.0));
    if (up.length() == 0.0) {
        Vec3d mean(0.0);
        for (const Vec3f& r : roots) mean += (Vec3d(r) - sphere.center).unitSafe();
        if (mean.length() > 1e-9 * double(roots.size())) sphere.up = mean.unitSafe();
    }
    if (upUsed) *upUsed = sphere.up;
    return surface ? std::make_shared<ScalpMap>(sphere, *surface, resolution) : std::make_shared<ScalpMap>(sphere);
}

std::shared_ptr<ScalpMap> hairScalpMap(const StrandSet& strands, const Vec3d& up, openvdb::FloatGrid::ConstPtr surface,
                                       Vec3d* upUsed, int resolution)
{
    std::vector<Vec3f> roots(strands.numStrands());
    for (std::size_t s = 0; s < roots.size(); ++s) roots[s] = strands.root(s);
    return scalpMapOfPoints(roots, up, std::move(surface), upUsed, resolution);
}

StrandSet moveToScalp(const StrandSet& strands, const ScalpMap& from, const ScalpMap& to, double turn, bool threaded)
{
    StrandSet out = strands;
    const double scale = to.radius() / from.radius(), c = std::cos(turn), s = std::sin(turn);
    // A turn about the sphere's up (+y in its frame): x' = c x + s z, z' = -s x + c z.
    const auto turnY = [&](const Vec3d& v) { return Vec3d(c * v.x() + s * v.z(), v.y(), -s * v.x() + c * v.z()); };
    const ScalpSphere unit;  // (u, v) <-> unit directions in a sphere's own frame
    forEachIndex(strands.numStrands(), threaded, [&](std::size_t i) {
        const std::size_t b = strands.begin(i), e = strands.end(i);
        if (b == e) return;
        const Vec3d root(strands.positions[b]);
        const Vec3d uvw = from.toScalp(root);
        Vec3d uv2 = uvw;
        if (turn != 0.0) {
            const Vec3d turned = worldToScalp(unit, turnY(scalpToWorld(unit, Vec3d(uvw.x(), uvw.y(), 0.0))));
            uv2 = Vec3d(turned.x(), turned.y(), uvw.z());
        }
        const ScalpFrame f = from.frame(uvw.x(), uvw.y()), g = to.frame(uv2.x(), uv2.y());
        const Vec3d newRoot = to.toWorld(uv2);
        for (std::size_t k = b; k < e; ++k)
            out.positions[k] = Vec3f(newRoot + g.toWorld(turnY(f.toLocal(Vec3d(strands.positions[k]) - root))) * scale);
    });
    return out;
}

} // namespace vdbhair
