/// @file GroomControls.h
/// @brief The controls a groom artist sets on new hair (`interpolate`): where it grows and how long
/// (density and length per root, from a scalp mask or per-root values: scalp/RootValues.h), curl
/// (the waviness of Piuze et al. 2011, Eq. 4), clumping into wisps around clump centres (§3.3's
/// wisps, around interpolated centres), and frizz.
///
/// The order, each step on the result of the one before: density thins the roots (before any
/// hair is made); length cuts each new hair; the head sweeps it out (HeadCollision.h); curl winds
/// it; clumps pull each hair towards its clump centre's hair; frizz roughens it; and what these
/// last three moved into the head is pushed out vertex by vertex (interpolateGuides()). Every random choice
/// draws from a stream seeded by (seed, root index, the control), so the result does not depend on
/// the thread count, and turning one control on does not change what the others draw.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

struct ClumpParams
{
    /// World units; 0: no clumps. Clump centres are roots at least this far apart, picked greedily
    /// in a seeded random order (a Poisson-disk set), so every root is within this distance of a
    /// centre; each root joins the nearest centre of its own group. A centre's hair is the hair
    /// interpolated at that root: Piuze et al.'s wisps around interpolated clump centres.
    double radius = 0.0;
    /// In [0, 1]: at its tip a hair moves this share of the way to its centre's hair at the same
    /// arc length (1: the tips meet).
    double tightness = 0.8;
    /// > 0: the pull at a fraction t of a hair's length is tightness · t^profile; 1 tightens evenly
    /// from the root, 2 and more keep the clump open until nearer the tip.
    double profile = 1.0;
    /// Hairs only join a centre shaped like them: a likeness distance (PointInterpolation.h) over
    /// this leaves a hair out of the clump, so clumps never pull across a parting or between
    /// layers. 0: any shape.
    double likeness = 0.25;
};

struct CurlParams
{
    /// a of Eq. 4, world units (0: no curl). Each hair curls about its rotation-minimizing frame,
    /// started alike on every hair (world x across the root tangent, else y), its phase shared by
    /// its clump (ringlets) or, without clumps, by all hairs (waves in step: frizz is the random part).
    double amplitude = 0.0;
    double frequency = 0.0;  ///< b of Eq. 4, radians per world unit: one turn every 2π / b
    /// World units: the standard deviation of a random offset across the hair at its tip, growing
    /// linearly from 0 at the root (0: no frizz).
    double frizz = 0.0;
};

/// The hair's own vertices are kept; with curl, a hair is first resampled to at least this many
/// vertices per turn (2π / b of arc length), so that curls are curls and not zigzags.
constexpr double kCurlVerticesPerTurn = 8.0;

struct GroomParams
{
    ClumpParams clump;
    CurlParams curl;
    std::uint64_t seed = 0;
    std::size_t maxVertices = std::size_t(1) << 28;  ///< the cap on the vertices curl may add (12 bytes each)
};

/// @brief Check every value; @throw ValueError naming the value and the rule (names as the CLI's
/// options: "--clump-radius", ...).
void validateGroomParams(const GroomParams& params);

/// @brief The declared clump, curl and frizz parameters (vdbhair/Parameters.h); the seed and the
/// vertex cap are the grooming verb's (InterpolateParams sets them).
const ParamTable<GroomParams>& groomParameters();

/// @brief Which of @a R roots a density keeps: root i when a draw uniform in [0, 1) from its own
/// stream is below density[i] (0 never, 1 always), and its length fraction (if any) is above 0.
/// @param density empty (all kept) or #R values; @param length empty or #R values
/// @throw ValueError (a value that is not finite, a density outside [0, 1], a length over 1,
/// sizes other than #R).
std::vector<char> rootsKept(std::size_t R, const std::vector<float>& density, const std::vector<float>& length, std::uint64_t seed);

/// @brief Cut hair i at fraction[i] of its length (1: as it is): its vertices before the cut and
/// the point at the cut. Per-vertex attributes are cut with it.
/// @throw ValueError (sizes, a fraction outside (0, 1]).
/// @return the hairs cut
std::size_t cutStrands(StrandSet& strands, const std::vector<float>& fraction, bool threaded = true);

/// @brief The clump centre each root joins (ClumpParams::radius): greedy Poisson-disk centres in a
/// seeded random order, no two of one group closer than @a radius, and each root joins the nearest
/// centre of its group (a centre joins itself), which is within @a radius.
/// @param groups empty or #R group indices
/// @throw ValueError (a radius that is not positive and finite, or so small that there would be
/// more than 2^20 cells across the roots' extent).
std::vector<std::uint32_t> clumpCentres(const std::vector<Vec3d>& roots, double radius, const std::vector<std::uint32_t>& groups,
                                        std::uint64_t seed, bool threaded = true);

struct GroomStats
{
    std::size_t clumps = 0;         ///< clump centres
    std::size_t clumped = 0;        ///< hairs pulled into a clump (not counting the centres)
    std::size_t curled = 0;         ///< hairs curled
    std::size_t addedVertices = 0;  ///< vertices curl added (resampling)
};

/// @brief Curl, clumps and frizz on @a strands (see above), in place.
/// @param groups empty or one group index per hair: clumps never join hairs of two groups
/// @throw ValueError (bad params, @a groups of the wrong size), LimitError (curl would exceed
/// maxVertices), InterruptedError.
GroomStats applyGroomControls(StrandSet& strands, const GroomParams& params, const std::vector<std::uint32_t>& groups = {},
                              bool threaded = true, openvdb::util::NullInterrupter* interrupter = nullptr);

} // namespace vdbhair
