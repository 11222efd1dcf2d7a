/// @file PrefitTrace.h
/// @brief The pre-fit's trace (HelicoidFit.h): a helicoid traced over a target fragment and
/// sampled at the fragment's own arc lengths, so the pre-fit's residuals are smooth in the
/// parameters. Internal to the fitter.
#pragma once

#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/impl/FitTarget.h>

#include <cstddef>
#include <vector>

namespace vdbhair {
namespace fit {

/// Radians the strand may turn over the segments one pre-fit step spans (0: one step per
/// segment). 23 % less CPU on straight hair than a step per segment (docs/fitting.md).
constexpr double kPrefitMaxTurn = 0.3;

/// @brief Trace @a h from its root h.p0 over the arc lengths of @a target's fragment [a, b]:
/// out[i] is where target vertex a + i should be. Steps of Kutta's third-order rule (three
/// tangents, the last shared with the next step), one per target segment subdivided to at most
/// @a maxStep, or one over up to four segments where the strand turns at most kPrefitMaxTurn over
/// them, with the vertices inside it cubic Hermite interpolants of the step's ends (O(h⁴)). The
/// steps depend on the fragment only, so out is smooth in h's parameters. Tangents use the
/// branchless forms of fastmath's functions (the same polynomials as Helicoid::tangent()).
/// @param[out] out b - a + 1 world positions
/// @param[out] endTangent optional: the unit tangent at the last point
void traceAtVertices(const Helicoid& h, const FitTarget& target, std::size_t a, std::size_t b, double maxStep,
                     std::vector<Vec3d>& out, Vec3d* endTangent = nullptr);

} // namespace fit
} // namespace vdbhair
