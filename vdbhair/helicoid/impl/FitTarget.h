/// @file FitTarget.h
/// @brief The strand a fit aims at (HelicoidFit.h): its distinct points, arc lengths and the
/// profiles the fit reads (curvature, Frenet normals, turning). Internal to the fitter.
#pragma once

#include <vdbhair/Types.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace vdbhair {
namespace fit {

inline Vec3f toFloat(const Vec3d& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }

/// @brief The target strand: distinct points, their arc lengths, and its curvature profile.
struct FitTarget
{
    std::vector<Vec3d> pts;
    std::vector<double> arc;       ///< arc length of each point from the root
    std::vector<float> curvature;  ///< curvatureProfile() (Measures.h)
    std::vector<Vec3d> normal;     ///< discrete Frenet normals (Frames.h)
    Vec3d rootTangent{0.0};        ///< the discrete Frenet tangent at the root (Frames.h)
    std::vector<double> turning;   ///< turning angle at each vertex (radians; 0 at the ends)
    double length = 0.0;

    /// @brief The first vertex at arc length @a s or beyond (pts.size() past the end).
    std::size_t indexAtArc(double s) const
    {
        return std::size_t(std::lower_bound(arc.begin(), arc.end(), s) - arc.begin());
    }
    /// @brief The length of the fragment [a, b] (world units).
    double fragmentLength(std::size_t a, std::size_t b) const { return arc[b] - arc[a]; }
};

/// @brief The target of @a n points: repeated consecutive points removed, then arc lengths,
/// curvature (Measures.h), Frenet normals (Frames.h) and turning angles.
FitTarget makeFitTarget(const Vec3f* points, std::size_t n);

} // namespace fit
} // namespace vdbhair
