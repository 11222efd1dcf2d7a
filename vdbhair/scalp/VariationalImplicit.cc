#include "VariationalImplicit.h"

#include <vdbhair/Format.h>

#include <vdbhair/Exceptions.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {


VariationalImplicit::VariationalImplicit(const std::vector<Vec3f>& points, const std::vector<Vec3f>& normals,
                                         double offsetFraction)
{
    const std::string where = "VariationalImplicit";
    if (points.size() < 5) {
        throw ValueError(where + ": " + std::to_string(points.size()) +
                         " constraint points; the implicit needs at least 5 (4 fix its affine part)");
    }
    if (normals.size() != points.size()) {
        throw ValueError(where + ": " + std::to_string(normals.size()) + " normals for " + std::to_string(points.size()) +
                         " points; every constraint point needs its normal");
    }
    if (!(offsetFraction > 0.0) || !std::isfinite(offsetFraction)) {
        throw ValueError(where + ": offset fraction " + formatNumber(offsetFraction) + " must be positive");
    }

    // Centre and scale: the unit frame has the bounding box's centre at 0 and diagonal 1.
    BBox box;
    for (const Vec3f& p : points) box.expand(p);
    mOrigin = Vec3d(0.5 * (Vec3d(box.min) + Vec3d(box.max)));
    mScale = Vec3d(box.extent()).length();
    if (!(mScale > 0.0)) throw ValueError(where + ": all " + std::to_string(points.size()) + " constraint points are at one position");

    // Coplanar points leave the affine part undetermined: the smallest principal extent of the
    // points must be more than 1e-6 of the largest.
    {
        Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (const Vec3f& p : points) mean += Eigen::Vector3d(p.x(), p.y(), p.z());
        mean /= double(points.size());
        for (const Vec3f& p : points) {
            const Eigen::Vector3d d = Eigen::Vector3d(p.x(), p.y(), p.z()) - mean;
            cov += d * d.transpose();
        }
        const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues();
        if (!(std::sqrt(std::max(ev(0), 0.0)) > 1e-6 * std::sqrt(ev(2)))) {
            throw ValueError(where + ": the " + std::to_string(points.size()) +
                             " constraint points lie on one plane (principal extents " + formatNumber(std::sqrt(std::max(ev(0), 0.0))) + " and " +
                             formatNumber(std::sqrt(ev(2))) + "); a surface through them is undetermined");
        }
    }

    // Constraints: boundary points (f = 0) and one off-surface point per normal (f = eps).
    mOffset = offsetFraction * mScale;
    for (std::size_t i = 0; i < points.size(); ++i) {
        mCenters.emplace_back(points[i]);
        mTargets.push_back(0.0);
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
        Vec3d n(normals[i]);
        const double len = n.length();
        if (!(len > 0.0) || !std::isfinite(len)) continue;
        mCenters.push_back(Vec3d(points[i]) + n * (mOffset / len));
        mTargets.push_back(mOffset);
    }
    const std::size_t m = mCenters.size();
    mUnit.resize(m);
    for (std::size_t i = 0; i < m; ++i) mUnit[i] = (mCenters[i] - mOrigin) / mScale;

    // The system [A P; P^T 0] [d; p] = [v; 0], A_ij = |c_i - c_j|^3, P_i = (1, c_i) (unit frame).
    const Eigen::Index n = Eigen::Index(m) + 4;
    Eigen::MatrixXd sys = Eigen::MatrixXd::Zero(n, n);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    for (std::size_t i = 0; i < m; ++i) {
        for (std::size_t j = 0; j < i; ++j) {
            const double r = (mUnit[i] - mUnit[j]).length();
            sys(Eigen::Index(i), Eigen::Index(j)) = sys(Eigen::Index(j), Eigen::Index(i)) = r * r * r;
        }
        const Eigen::Index row = Eigen::Index(i), col = Eigen::Index(m);
        sys(row, col) = sys(col, row) = 1.0;
        for (int k = 0; k < 3; ++k) sys(row, col + 1 + k) = sys(col + 1 + k, row) = mUnit[i][k];
        rhs(row) = mTargets[i] / mScale;
    }
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(sys);
    const Eigen::VectorXd x = lu.solve(rhs);
    const double bMax = std::max(rhs.cwiseAbs().maxCoeff(), 1e-300);
    mResidual = (sys * x - rhs).cwiseAbs().maxCoeff() / bMax;
    if (!x.allFinite() || !(mResidual < 1e-6)) {
        throw ValueError(where + ": the system of " + std::to_string(m) + " constraints is singular (relative residual " +
                         formatNumber(mResidual) + "); are some points repeated?");
    }
    mWeights.assign(x.data(), x.data() + m);
    for (int k = 0; k < 4; ++k) mAffine[k] = x(Eigen::Index(m) + k);
}

double VariationalImplicit::value(const Vec3d& worldPos) const
{
    const Vec3d u = (worldPos - mOrigin) / mScale;
    double f = mAffine[0] + mAffine[1] * u.x() + mAffine[2] * u.y() + mAffine[3] * u.z();
    for (std::size_t j = 0; j < mUnit.size(); ++j) {
        const double r = (u - mUnit[j]).length();
        f += mWeights[j] * r * r * r;
    }
    return f * mScale;
}

double VariationalImplicit::valueAndGradient(const Vec3d& worldPos, Vec3d& gradient) const
{
    const Vec3d u = (worldPos - mOrigin) / mScale;
    double f = mAffine[0] + mAffine[1] * u.x() + mAffine[2] * u.y() + mAffine[3] * u.z();
    Vec3d g(mAffine[1], mAffine[2], mAffine[3]);
    for (std::size_t j = 0; j < mUnit.size(); ++j) {
        const Vec3d d = u - mUnit[j];
        const double r = d.length();
        f += mWeights[j] * r * r * r;
        g += d * (3.0 * mWeights[j] * r);  // grad |d|^3 = 3 |d| d
    }
    gradient = g;  // d(scale f_unit)/dx = grad_u f_unit
    return f * mScale;
}

} // namespace vdbhair
