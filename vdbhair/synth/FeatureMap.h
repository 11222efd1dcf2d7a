/// @file FeatureMap.h
/// @brief Feature maps on the scalp (Wang et al. 2009, §5.1): a regular grid over scalp space
/// (u, v) whose pixels hold feature vectors interpolated from the strands' roots, with a validity
/// mask marking where the scalp has hair.
///
/// Interpolation (the paper does not say how): Shepard weights 1/d² over the four roots nearest a
/// pixel in (u, v) (a pixel on a root takes that root's vector). Validity: a pixel is valid when
/// some root of the *mask* set (the finest level's roots, so the region is the hairstyle's, not
/// the coarse level's) lies within @c maskRadius of it in (u, v).
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/synth/FeatureImage.h>
#include <vdbhair/field/ScalpMap.h>

#include <cstdint>
#include <vector>

namespace vdbhair {

/// @brief Pixel (x, y) is at (u, v) = (u0 + x spacing, v0 + y spacing).
struct UvGrid
{
    double u0 = 0.0, v0 = 0.0, spacing = 0.02;
    int width = 0, height = 0;

    double u(double x) const { return u0 + x * spacing; }
    double v(double y) const { return v0 + y * spacing; }
    /// Nearest pixel of (u, v), clamped into the grid.
    void pixelOf(double u, double v, int& x, int& y) const;
};

/// @brief The grid of @a spacing covering the (u, v) of @a scalpCoords with @a padPixels of margin,
/// kept inside (0, π)².
/// @throw ValueError for a non-positive spacing or no coordinates; LimitError beyond 4096² pixels.
UvGrid uvGridAround(const std::vector<Vec3d>& scalpCoords, double spacing, int padPixels = 2);

/// @brief The distance in (u, v) from each coordinate to its nearest other one (all 0 for fewer than 2).
std::vector<double> nearestUvDistances(const std::vector<Vec3d>& scalpCoords, bool threaded = true);

/// @brief The median of nearestUvDistances() (0 for fewer than 2).
double medianUvSpacing(const std::vector<Vec3d>& scalpCoords);

/// @brief Interpolate @a channels-wide feature rows (one per root, #N × channels) onto @a grid,
/// valid within @a maskRadius (u, v units) of a coordinate of @a maskCoords.
FeatureImage buildFeatureMap(const UvGrid& grid, const std::vector<Vec3d>& rootCoords, const float* features,
                             int channels, const std::vector<Vec3d>& maskCoords, double maskRadius);

/// @brief Pixels of @a grid within @a radius (u, v units) of a coordinate of @a coords: 1, else 0
/// (row-major, as FeatureImage::valid).
std::vector<std::uint8_t> uvMask(const UvGrid& grid, const std::vector<Vec3d>& coords, double radius);

/// @brief The feature vector of the valid pixel nearest to (u, v) (the paper's "spatially closest
/// feature vector"), into @a out (channels floats). @return false if the map has no valid pixel.
bool nearestFeature(const FeatureImage& map, const UvGrid& grid, double u, double v, float* out);

} // namespace vdbhair
