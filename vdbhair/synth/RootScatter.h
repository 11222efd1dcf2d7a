/// @file RootScatter.h
/// @brief New hair roots on a scalp region (Wang et al. 2009, §5.1: "randomly generate hair roots
/// within a user specified scalp region, and apply the relaxation procedure in [Turk 2001]").
///
/// The region is the valid pixels of a feature map's (u, v) grid. 1. Each pixel's world area is
/// |∂P/∂u × ∂P/∂v| spacing² (central differences of the scalp map). 2. Root i draws a pixel in
/// proportion to its area and a uniform point inside it from the random stream (seed, stream, i),
/// and is placed on the scalp (w = 0). 3. Turk's relaxation: every root is pushed away from its six
/// nearest neighbours within r = 2 d (d the hexagonal spacing sqrt(2A / (√3 N)) of the region's
/// area A), by (r − |δ|)/r · d/4 along δ each, the sum capped at d/2; it moves back onto the scalp
/// through (u, v) and stays put if that leaves the region. All roots move at once from the previous
/// positions (Jacobi) for @c iterations rounds, so the result does not depend on the thread count.
/// With a @c density image (rootDensity()), step 2 draws pixels in proportion to it instead of their
/// area, and step 3's spacing d is each root's local one, from the density at its pixel: the output
/// then has the example's denser and sparser parts (a short layered crown, a thin nape) where the
/// example has them, not one even density (Ruby's short hair: crown 77 % of the strands in the
/// example, 63 % evenly).
/// A much faster and somewhat less regular alternative to Follicles.h's particle system (seconds
/// for 100,000 roots there): synthesis needs a root per strand at every level.
#pragma once

#include <vdbhair/synth/FeatureMap.h>

#include <cstdint>
#include <vector>

namespace vdbhair {

struct RootScatterParams
{
    std::size_t count = 0;
    int iterations = 10;  ///< relaxation rounds (Turk 2001 relaxes until visually even; 10 measured enough)
    std::uint64_t seed = 0;
    std::uint64_t stream = 0;  ///< distinguishes the draws of different levels
};

struct ScatteredRoots
{
    std::vector<Vec3d> positions;  ///< #N world roots on the scalp
    std::vector<Vec3d> scalp;      ///< #N (u, v, 0)
    double area = 0.0;             ///< region area, world units²
};

/// @brief The world area of the valid pixels of @a mask on @a grid.
double regionArea(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask);

/// @brief The density of @a coords on @a grid as expected points per pixel (one channel): at each
/// pixel of @a region, the points in the box of pixels around it over the box's pixels in @a region
/// (so the region's edge is not thinned), the box's half-width holding about 32 points on average
/// (at least one pixel). Pixels outside @a region are invalid.
/// @throw ValueError for no coordinates or a region with no valid pixel.
FeatureImage rootDensity(const UvGrid& grid, const std::vector<Vec3d>& coords, const FeatureImage& region);

/// @param density expected roots per pixel (rootDensity(), defined on every valid pixel of
/// @a mask), or null for an even density over the region's area
/// @throw ValueError (a count of 0), LookupError (no valid pixel).
ScatteredRoots scatterRoots(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask,
                            const RootScatterParams& params, bool threaded = true, const FeatureImage* density = nullptr);

/// How far from an example root scatterAroundRoots() draws a new one: this fraction of the
/// distance to the example root's nearest neighbour, in (u, v). Six grooms on their heads, seeds
/// 0-2 (region figures within 10 % of the example's): 0.3 made 2.2 % of Ruby's short strands
/// copies of the example's (synth's "new" check fails above 1 %), 0.5 none over 0.5 %; 0.7 kept
/// fewer region figures (519 of 648 against 533).
constexpr double kAroundReach = 0.5;

/// @brief New roots where the example's are (--root-density example on the example's own region):
/// the example's roots of the level taken in a random order (round again while more are wanted),
/// each new root at a uniform point of the disc of kAroundReach times the distance to its example
/// root's nearest neighbour, in (u, v), on the example's root where that disc leaves @a mask.
/// Every part of the scalp then gets the example's share of the roots exactly up to the jitter
/// (a scatter by density, above, moved roots from a dense crown into the sparser regions around
/// it and into the band the region's mask adds at its edge: Ruby's short crown 77 % → 74 %, the
/// HairNet blend's lowest 10° of roots 4 % → 8 %). Not relaxed, so the example's own spacing is
/// kept; when there are more new roots than example roots, relaxed as scatterRoots() with the
/// example's rootDensity(). Deterministic and identical for any thread count.
/// @param exampleCoords the example's roots of the level, (u, v, 0)
/// @throw ValueError (a count of 0, no example roots), LookupError (no valid pixel).
ScatteredRoots scatterAroundRoots(const ScalpMap& map, const UvGrid& grid, const FeatureImage& mask,
                                  const std::vector<Vec3d>& exampleCoords, const RootScatterParams& params, bool threaded = true);

} // namespace vdbhair
