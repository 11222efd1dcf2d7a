#include "ScalpSpace.h"

#include <vdbhair/Exceptions.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace vdbhair {

namespace {

/// Rotation taking +y to @a up (columns: images of x, y, z).
void frameOf(const Vec3d& up, Vec3d& ex, Vec3d& ey, Vec3d& ez)
{
    ey = up.unitSafe();
    if (ey.lengthSqr() == 0.0) ey = Vec3d(0.0, 1.0, 0.0);
    // Keep x as close to world x as possible (identity when up = +y).
    Vec3d x(1.0, 0.0, 0.0);
    if (std::abs(ey.dot(x)) > 0.9) x = Vec3d(0.0, 0.0, -1.0);
    ex = (x - ey * ey.dot(x)).unitSafe();
    ez = ex.cross(ey);
}

double acosSafe(double c) { return std::acos(std::max(-1.0, std::min(1.0, c))); }

} // namespace

Vec3d worldToScalp(const ScalpSphere& scalp, const Vec3d& world)
{
    Vec3d ex, ey, ez;
    frameOf(scalp.up, ex, ey, ez);
    const Vec3d d = (world - scalp.center) / scalp.radius;
    const Vec3d p(d.dot(ex), d.dot(ey), d.dot(ez));
    const double r = p.length();
    if (r == 0.0) return Vec3d(0.5 * M_PI, 0.5 * M_PI, -1.0);
    const Vec3d q = p / r;
    const double yy = q.y() + 1.0;
    const double nu = std::sqrt(q.x() * q.x() + yy * yy), nv = std::sqrt(q.z() * q.z() + yy * yy);
    const double u = nu > 0.0 ? acosSafe(q.x() / nu) : 0.5 * M_PI;
    const double v = nv > 0.0 ? acosSafe(q.z() / nv) : 0.5 * M_PI;
    return Vec3d(u, v, r - 1.0);
}

Vec3d scalpToWorld(const ScalpSphere& scalp, const Vec3d& uvw)
{
    Vec3d ex, ey, ez;
    frameOf(scalp.up, ex, ey, ez);
    const double cu = 1.0 / std::tan(uvw.x()), cv = 1.0 / std::tan(uvw.y());
    const double h = 2.0 / (cu * cu + cv * cv + 1.0);
    const Vec3d q(h * cu, h - 1.0, h * cv);
    const Vec3d p = (uvw.z() + 1.0) * q;
    return scalp.center + scalp.radius * (p.x() * ex + p.y() * ey + p.z() * ez);
}

ScalpSphere fitScalpSphere(const std::vector<Vec3f>& points, const Vec3d& up)
{
    if (points.size() < 4) {
        throw ValueError("fitScalpSphere: " + std::to_string(points.size()) + " points; a sphere needs at least 4");
    }
    // Centre the points for conditioning, then solve |p|² = 2 c·p + k in least squares.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Vec3f& p : points) mean += Eigen::Vector3d(p.x(), p.y(), p.z());
    mean /= double(points.size());
    Eigen::MatrixXd A(points.size(), 4);
    Eigen::VectorXd b(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector3d p = Eigen::Vector3d(points[i].x(), points[i].y(), points[i].z()) - mean;
        A.row(Eigen::Index(i)) << 2.0 * p.x(), 2.0 * p.y(), 2.0 * p.z(), 1.0;
        b(Eigen::Index(i)) = p.squaredNorm();
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    if (qr.rank() < 4) throw ValueError("fitScalpSphere: the points lie on a plane or a line; no unique sphere");
    const Eigen::Vector4d x = qr.solve(b);
    const Eigen::Vector3d c = x.head<3>();
    const double r2 = x(3) + c.squaredNorm();
    if (!(r2 > 0.0) || !std::isfinite(r2)) throw ValueError("fitScalpSphere: the fit has no real radius");
    ScalpSphere s;
    s.center = Vec3d(c.x() + mean.x(), c.y() + mean.y(), c.z() + mean.z());
    s.radius = std::sqrt(r2);
    s.up = up.unitSafe();
    return s;
}

} // namespace vdbhair
