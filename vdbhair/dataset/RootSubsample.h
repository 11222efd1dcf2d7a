/// @file RootSubsample.h
/// @brief A subset of a hairstyle's strands whose roots are spread evenly: farthest-point sampling
/// of the roots (Eldar et al. 1997), the deterministic form of Poisson-disk selection.
///
/// The first root taken is the one nearest the roots' centroid; each next one is the root farthest
/// from every root taken so far (ties to the lower strand index). After k roots, every root of the
/// hairstyle lies within the last distance d_k of a taken root, and no two taken roots are closer
/// than d_k: the subset covers the scalp as a Poisson-disk set of radius d_k does, and its
/// smallest spacing is at least half the best any subset of k roots can have (Gonzalez 1985).
/// The distance is the straight line between roots (on a scalp, the chord).
#pragma once

#include <vdbhair/strands/StrandSet.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vdbhair {

struct RootSelection
{
    std::vector<std::uint32_t> strands;  ///< the strands taken, in increasing index order
    /// Smallest distance between two taken roots (world units; 0 for fewer than two).
    double minSpacing = 0.0;
    /// Largest distance from any root of the hairstyle to its nearest taken root (world units).
    double coverageRadius = 0.0;
};

/// @brief @a count strands of @a strands with evenly spread roots (see above); every strand when
/// @a count is at least the strand count. In parallel; the same for any thread count.
/// Costs O(#S x @a count) distance evaluations.
RootSelection selectEvenRoots(const StrandSet& strands, std::size_t count, bool threaded = true);

/// @brief The strands selectEvenRoots() takes, with their attributes, in their original order.
StrandSet subsampleStrands(const StrandSet& strands, std::size_t count, RootSelection* selection = nullptr,
                           bool threaded = true);

} // namespace vdbhair
