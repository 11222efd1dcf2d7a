#include "HeadObstacle.h"

#include <vdbhair/Exceptions.h>

#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>

#include <cmath>
#include <limits>
#include <sstream>

namespace vdbhair {

HeadObstacle HeadObstacle::none()
{
    HeadObstacle h;
    h.mKind = Kind::Disabled;
    return h;
}

HeadObstacle HeadObstacle::sphere(const Vec3d& center, double radius, HeadPolicy policy)
{
    if (!(radius > 0.0) || !std::isfinite(radius)) {
        throw ValueError("head sphere: radius " + std::to_string(radius) + " must be positive and finite");
    }
    for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(center[k])) throw ValueError("head sphere: the centre must be finite");
    }
    HeadObstacle h;
    h.mKind = Kind::Sphere;
    h.mPolicy = policy;
    h.mCenter = center;
    h.mRadius = radius;
    return h;
}

namespace {
/// How far into the interior a head's level set is extended beyond its band (voxels): 24 in all,
/// a quarter of a head of 100 voxels across (vdbhair scalp's default), deeper than hair lies in
/// the shared heads; beyond it every depth reads alike.
constexpr int kInteriorVoxels = 21;
} // namespace

HeadObstacle HeadObstacle::levelSet(openvdb::FloatGrid::ConstPtr grid, HeadPolicy policy)
{
    if (!grid) throw ValueError("head level set: no grid");
    if (grid->getGridClass() != openvdb::GRID_LEVEL_SET) {
        throw TypeError("head level set '" + grid->getName() + "': grid class is '" +
                        openvdb::GridBase::gridClassToString(grid->getGridClass()) + "', not a level set");
    }
    if (grid->activeVoxelCount() == 0) throw ValueError("head level set '" + grid->getName() + "': no active voxels");
    HeadObstacle h;
    h.mKind = Kind::LevelSet;
    h.mPolicy = policy;
    h.mGrid = grid;
    // Depth beyond the narrow band, into the interior (fast sweeping): within the band alone every
    // deeper point would read as the band's half width, and "no deeper than the input" could not
    // tell a vertex 4 voxels deep from one 20 voxels deep.
    {
        openvdb::FloatGrid::Ptr filled = openvdb::tools::dilateSdf(*grid, kInteriorVoxels, openvdb::tools::NN_FACE_EDGE, 1,
                                                                   openvdb::tools::FastSweepingDomain::SWEEP_LESS_THAN_ISOVALUE);
        if (filled) {
            filled->setGridClass(openvdb::GRID_LEVEL_SET);
            filled->setName(grid->getName());
            h.mGrid = filled;
        }
    }
    // The band's centre: where the normal points away from when a point is outside the band.
    Vec3d sum(0.0);
    double n = 0.0;
    for (auto it = grid->cbeginValueOn(); it; ++it) {
        if (!it.isVoxelValue()) continue;
        sum += grid->indexToWorld(it.getCoord());
        n += 1.0;
    }
    h.mCenter = n > 0.0 ? sum / n : Vec3d(0.0);
    return h;
}

std::string HeadObstacle::describe(bool withPolicy) const
{
    std::ostringstream s;
    switch (mKind) {
    case Kind::None:
    case Kind::Disabled: s << "none"; break;
    case Kind::Sphere:
        s << "sphere (" << mCenter.x() << ", " << mCenter.y() << ", " << mCenter.z() << ") radius " << mRadius;
        break;
    case Kind::LevelSet: s << "level set '" << mGrid->getName() << "' (voxel " << mGrid->voxelSize()[0] << ")"; break;
    }
    if (!mLabel.empty()) s << ", " << mLabel;
    if (!empty() && withPolicy) s << (mPolicy == HeadPolicy::NoDeeper ? ", no vertex deeper inside than the input's" : ", every vertex kept outside");
    return s.str();
}

HeadObstacle::Probe::Probe(const HeadObstacle& head) : mHead(head)
{
    if (head.mKind == Kind::LevelSet) mAcc.reset(new openvdb::FloatGrid::ConstAccessor(head.mGrid->getConstAccessor()));
}

double HeadObstacle::Probe::distance(const Vec3d& p)
{
    switch (mHead.mKind) {
    case Kind::None:
    case Kind::Disabled: return std::numeric_limits<double>::infinity();
    case Kind::Sphere: return (p - mHead.mCenter).length() - mHead.mRadius;
    case Kind::LevelSet:
        return double(openvdb::tools::BoxSampler::sample(*mAcc, mHead.mGrid->worldToIndex(p)));
    }
    return std::numeric_limits<double>::infinity();
}

double HeadObstacle::Probe::distance(const Vec3d& p, Vec3d& direction)
{
    direction = Vec3d(0.0);
    switch (mHead.mKind) {
    case Kind::None:
    case Kind::Disabled: return std::numeric_limits<double>::infinity();
    case Kind::Sphere: {
        const Vec3d r = p - mHead.mCenter;
        const double l = r.length();
        if (l > 0.0) direction = r / l;
        return l - mHead.mRadius;
    }
    case Kind::LevelSet: {
        const Vec3d x = mHead.mGrid->worldToIndex(p);
        const openvdb::Coord c(openvdb::Coord::floor(x));
        const Vec3d f = x - Vec3d(c.x(), c.y(), c.z());
        double v[2][2][2];
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j)
                for (int k = 0; k < 2; ++k) v[i][j][k] = double(mAcc->getValue(c.offsetBy(i, j, k)));
        auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
        // The value and the partial derivatives of the trilinear cell, in index space.
        const double y0z0 = lerp(v[0][0][0], v[1][0][0], f.x()), y1z0 = lerp(v[0][1][0], v[1][1][0], f.x());
        const double y0z1 = lerp(v[0][0][1], v[1][0][1], f.x()), y1z1 = lerp(v[0][1][1], v[1][1][1], f.x());
        const double z0 = lerp(y0z0, y1z0, f.y()), z1 = lerp(y0z1, y1z1, f.y());
        const double value = lerp(z0, z1, f.z());
        double gx = 0.0;
        for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k) gx += (v[1][j][k] - v[0][j][k]) * (j ? f.y() : 1.0 - f.y()) * (k ? f.z() : 1.0 - f.z());
        double gy = 0.0;
        for (int i = 0; i < 2; ++i)
            for (int k = 0; k < 2; ++k) gy += (v[i][1][k] - v[i][0][k]) * (i ? f.x() : 1.0 - f.x()) * (k ? f.z() : 1.0 - f.z());
        const double gz = z1 - z0;
        // Index-space gradient to world space (the inverse transpose of the map's Jacobian).
        const Vec3d g = mHead.mGrid->transform().baseMap()->applyIJT(Vec3d(gx, gy, gz), x);
        const double l = g.length();
        direction = l > 0.0 ? g / l : (p - mHead.mCenter).unitSafe();  // flat cell (beyond the band): away from its centre
        return value;
    }
    }
    return std::numeric_limits<double>::infinity();
}

Vec3d HeadObstacle::Probe::normal(const Vec3d& p)
{
    Vec3d g(0.0);
    switch (mHead.mKind) {
    case Kind::None:
    case Kind::Disabled: return g;
    case Kind::Sphere: g = p - mHead.mCenter; break;
    case Kind::LevelSet: {
        // Central differences of the trilinear distance, half a voxel apart.
        const double h = 0.5 * mHead.mGrid->voxelSize()[0];
        for (int k = 0; k < 3; ++k) {
            Vec3d a = p, b = p;
            a[k] -= h;
            b[k] += h;
            g[k] = distance(b) - distance(a);
        }
        if (!(g.lengthSqr() > 0.0)) g = p - mHead.mCenter;  // outside the band, or a flat spot
        break;
    }
    }
    const double len = g.length();
    return len > 0.0 ? g / len : Vec3d(0.0);
}

bool HeadObstacle::Probe::pushOut(Vec3d& p, double minDistance)
{
    if (mHead.empty()) return false;
    // A little beyond the floor, so that the float output vertex is not rounded back inside.
    const double scale = mHead.mKind == Kind::Sphere ? mHead.mRadius : mHead.mGrid->voxelSize()[0];
    const double target = minDistance + 1e-4 * scale;
    bool moved = false;
    // Exact for a sphere in one step; Newton steps on a level set, whose distance is only
    // approximately a distance, and beyond whose narrow band it is the band's half width: a
    // point deep inside moves out by that much a step until it reaches the band.
    const int iterations = mHead.mKind == Kind::Sphere ? 2 : 256;
    for (int iter = 0; iter < iterations; ++iter) {
        const double d = distance(p);
        if (!(d < minDistance) && (iter == 0 || !(d < target))) break;
        const Vec3d n = normal(p);
        if (n.lengthSqr() == 0.0) break;
        p += (target - d) * n;
        moved = true;
    }
    return moved;
}

const char* headPolicyName(HeadPolicy policy)
{
    return policy == HeadPolicy::NoDeeper ? "no-deeper" : "outside";
}

HeadPolicy headPolicyFromName(const std::string& name)
{
    if (name == "no-deeper") return HeadPolicy::NoDeeper;
    if (name == "outside") return HeadPolicy::KeepOutside;
    throw ValueError("head policy '" + name + "' is not one of no-deeper, outside");
}

} // namespace vdbhair
