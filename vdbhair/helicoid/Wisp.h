/// @file Wisp.h
/// @brief Wisps (Piuze et al. 2011, §3.3): extra strands traced as streamlines of a guide's own
/// helicoid field from roots offset around the guide's root.
#pragma once

#include <vdbhair/Random.h>
#include <vdbhair/helicoid/Helicoid.h>

namespace vdbhair {

struct WispParams
{
    std::size_t count = 0;  ///< strands in addition to the guide
    double radius = 0.0;    ///< world units: roots are sampled in a disk of this radius
    double fanning = 0.0;   ///< radians: the largest random rotation of a wisp strand about its root
};

/// @brief Trace one wisp strand of a guide whose trace is @a guide.
///
/// Its root is sampled uniformly in the disk of radius `radius` around the guide's root, in the
/// plane of the guide's E_N and E_B there. It is traced through the guide's helicoid field — the
/// guide's pieces with their own p0 and Q — piece by piece over the guide's piece lengths, not as
/// a translated copy of the guide. With fanning > 0 the traced strand is then rotated rigidly
/// about its root by an angle uniform in [0, fanning] about a uniformly random axis (a rigid
/// rotation of the field it follows, which fans the wisp out).
/// @param rng the wisp strand's own stream
void traceWisp(const HelicoidTrace& guide, const std::vector<HelicoidPiece>& pieces, const WispParams& params,
               double step, HelicoidIntegrator integrator, Rng& rng, HelicoidTrace& out);

/// @brief traceWisp() for @a count wisp strands at once, strand i drawing from @a rngs[i]
/// (the same strands as one call each, traced in lockstep for speed).
/// @param frames whether @a outs' frames must follow the fanning rotation too (waviness needs them);
/// without, only points and arc lengths are meaningful after fanning.
void traceWisps(const HelicoidTrace& guide, const std::vector<HelicoidPiece>& pieces, const WispParams& params,
                double step, HelicoidIntegrator integrator, Rng* rngs, std::size_t count, HelicoidTrace* outs, bool frames = true);

} // namespace vdbhair
