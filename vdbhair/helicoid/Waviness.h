/// @file Waviness.h
/// @brief The waviness offset of Piuze et al. 2011, Eq. 4: a helical displacement about a traced
/// strand, in the plane of its normal and binormal.
#pragma once

#include <vdbhair/Random.h>
#include <vdbhair/helicoid/Helicoid.h>

namespace vdbhair {

/// @brief p̃(s) = p(s) + a cos(b s + phase) E_B(s) + a sin(b s + phase) E_N(s), s the arc length
/// from the root, the frame that of Eq. 2 at p(s); plus, when noise > 0, a seeded Gaussian offset
/// of standard deviation `noise` (world units) in the same plane at every vertex (the paper's
/// "stochastic perturbations", bounded so the strand stays near its wave).
struct WavinessParams
{
    double amplitude = 0.0;  ///< a, world units
    double frequency = 0.0;  ///< b, radians per unit length (the paper's "frequency 2πb" with b here already in radians)
    double phase = 0.0;      ///< radians
    double noise = 0.0;      ///< world units
    /// Arc length over which the offset rises from 0 at the root to its full size (a smoothstep
    /// of s / ramp), so that a root stays where it is; 0: the paper's constant offset, which moves
    /// the root by a too. New hair on a scalp (GroomControls.h) uses one wavelength, 2π / b.
    double ramp = 0.0;
};

/// @brief Write the displaced points of @a trace to @a out (trace.points.size() entries).
/// @param rng the strand's own stream (used only when noise > 0)
void applyWaviness(const HelicoidTrace& trace, const WavinessParams& params, Rng& rng, Vec3f* out);

} // namespace vdbhair
