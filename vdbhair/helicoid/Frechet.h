/// @file Frechet.h
/// @brief Similarity of polylines for fitting (Piuze et al. 2011, §5.1).
///
/// - The discrete Fréchet distance (Eiter & Mannila 1994): the shortest leash that lets a man and
///   his dog walk their polylines vertex by vertex, neither going back: over monotone couplings,
///   the smallest maximum of the coupled distances.
/// - The Fréchet coupling, the paper's fitting measure: over the same monotone couplings, the
///   smallest *total* leash length (the sum of the coupled distances), which weighs the whole
///   curve and still respects the order of the points.
/// Both by dynamic programming in O(pq) time and O(q) memory; the discrete Fréchet distance visits
/// only the cells within an upper bound (the largest distance along the staircase coupling closest
/// to the diagonal), a narrow band for close curves, and is still exact.
#pragma once

#include <vdbhair/Types.h>

#include <cstddef>
#include <vector>

namespace vdbhair {

/// @brief Discrete Fréchet distance between polylines of @a p and @a q points (world units).
double discreteFrechet(const Vec3d* a, std::size_t p, const Vec3d* b, std::size_t q);

/// @brief Whether discreteFrechet(a, p, b, q) <= @a eps, without computing it: the decision
/// version (Eiter & Mannila's free-space reachability), which visits only the cells reachable
/// within @a eps, a narrow band along the diagonal when the polylines are close; false as soon as
/// a row has no reachable cell. Fitting asks this of every candidate piece.
bool discreteFrechetWithin(const Vec3d* a, std::size_t p, const Vec3d* b, std::size_t q, double eps);

/// @brief Fréchet coupling: the smallest sum of coupled distances over monotone couplings.
/// @param[out] steps optional: the number of pairs in that coupling (its mean leash is sum / steps)
double frechetCoupling(const Vec3d* a, std::size_t p, const Vec3d* b, std::size_t q, std::size_t* steps = nullptr);

/// @brief The polyline @a pts[a..b] with points inserted so that no gap exceeds @a spacing (world
/// units), into @a out. Discrete Fréchet measures compare vertices: a sparse curve against a dense
/// one reports half a segment even when they coincide, so both are brought to one spacing first.
void densifyPolyline(const std::vector<Vec3d>& pts, std::size_t a, std::size_t b, double spacing, std::vector<Vec3d>& out);

} // namespace vdbhair
