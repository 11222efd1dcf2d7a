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
    /// The scalp's unit normal at the guide's root, or zero: with it, roots are sampled in the
    /// disk perpendicular to it (the scalp's tangent plane), so that a wisp of hair lying close to
    /// the scalp has its roots on the scalp rather than in and out of it; without, in the plane
    /// of the guide's E_N and E_B at its root (perpendicular to the guide's tangent).
    Vec3d normal{0.0};
    /// Fraction in [0, 1] of the wisp strands that are strays: each strand is one with this
    /// probability (drawn from its own stream) and gets an extra rigid rotation (see traceWisp())
    /// by an angle uniform in [strayAngle / 2, strayAngle] — hairs that cross their neighbours,
    /// the inconsistencies refinement is meant to remove.
    double strays = 0.0;
    /// Radians: the largest stray rotation. 0.6 rad turns a stray by 17-34 degrees, well beyond
    /// any fanning a scene uses (0.05-0.1 rad), so strays are visibly out of the flow.
    double strayAngle = 0.6;
};

/// @brief Trace one wisp strand of a guide whose trace is @a guide.
///
/// Its root is sampled uniformly in the disk of radius `radius` around the guide's root, in the
/// plane of the guide's E_N and E_B there. It is traced through the guide's helicoid field — the
/// guide's pieces with their own p0 and Q — piece by piece over the guide's piece lengths, not as
/// a translated copy of the guide. With fanning > 0 the traced strand is then rotated rigidly
/// about its root by an angle uniform in [0, fanning] about a uniformly random axis (a rigid
/// rotation of the field it follows, which fans the wisp out). With a normal, roots are sampled in
/// the disk perpendicular to it instead (WispParams::normal). A stray (WispParams::strays) is then
/// rotated rigidly once more: when the wisp has a normal, about the line along the normal through
/// the guide's root (sideways, within the scalp's tangent plane; the stray's root turns within the
/// disk; for a sphere head and its radial normal that line passes through the centre, so strays
/// never enter the head), otherwise about the stray's root and a uniformly random axis
/// perpendicular to the guide's tangent at its root; the sense of the rotation is random.
/// Draws from @a rng, in order: the root (2 numbers), the fanning (3), and, only when strays > 0,
/// the stray choice and rotation (3) — so scenes without strays grow exactly as before.
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
