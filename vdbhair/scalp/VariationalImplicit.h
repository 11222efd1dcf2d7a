/// @file VariationalImplicit.h
/// @brief Turk and O'Brien's variational implicit surface (Turk & O'Brien 1999, "Shape
/// transformation using variational implicit functions"; 2002, "Modelling with implicit surfaces
/// that interpolate"), which Piuze et al. 2011 (Sec. 4.3) use to make a scalp from scattered
/// constraint points.
///
/// f(x) = sum_j d_j |x - c_j|^3 + p0 + p . x, the thin-plate-like triharmonic spline in 3D. Each
/// boundary point c_j gets f = 0; each normal becomes an off-surface constraint at c_j + eps n_j
/// with f = eps (outside positive, so f is negative inside as a level set is). eps is 1 % of the
/// model size (the bounding-box diagonal), Turk and O'Brien's suggestion of "a small distance".
/// The system [A P; P^T 0] [d; p] = [v; 0] is symmetric indefinite: it is solved by LU with
/// partial pivoting (Eigen), after centring the points and scaling them into the unit box, which
/// keeps its condition number workable.
#pragma once

#include <vdbhair/Types.h>

#include <vector>

namespace vdbhair {

class VariationalImplicit
{
public:
    /// @brief Fit through @a points (f = 0) with off-surface constraints along @a normals.
    /// @param points #P world positions, at least 5, not all on one plane
    /// @param normals #P outward normals (normalized here; zero normals add no constraint)
    /// @param offsetFraction the off-surface distance as a fraction of the bounding-box diagonal
    /// @throw ValueError naming the rule: fewer than 5 points, normals of the wrong count,
    /// coplanar points (the affine part is then undetermined), a singular system.
    VariationalImplicit(const std::vector<Vec3f>& points, const std::vector<Vec3f>& normals,
                        double offsetFraction = 0.01);

    /// @brief f at @a worldPos (world units: f is about a signed distance near the surface).
    double value(const Vec3d& worldPos) const;
    /// @brief f and its gradient at @a worldPos.
    double valueAndGradient(const Vec3d& worldPos, Vec3d& gradient) const;

    std::size_t numCenters() const { return mCenters.size(); }
    /// The model size (bounding-box diagonal, world units) and the off-surface distance used.
    double modelSize() const { return mScale; }
    double offset() const { return mOffset; }
    /// The constraint centres (world units) and the values f must take there.
    const std::vector<Vec3d>& centers() const { return mCenters; }
    const std::vector<double>& targets() const { return mTargets; }
    /// The largest |A x - b| of the solve relative to the largest |b| (an LU sanity figure).
    double relativeResidual() const { return mResidual; }

private:
    std::vector<Vec3d> mCenters;   ///< world units
    std::vector<Vec3d> mUnit;      ///< (c - mOrigin) / mScale
    std::vector<double> mTargets;  ///< world units
    std::vector<double> mWeights;  ///< d_j, in the unit frame
    double mAffine[4] = {0, 0, 0, 0};
    Vec3d mOrigin{0.0};
    double mScale = 1.0, mOffset = 0.0, mResidual = 0.0;
};

} // namespace vdbhair
