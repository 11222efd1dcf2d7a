/// @file RootEnd.h
/// @brief Which end of each strand read from a file is its root: `--roots first|last|auto`.
///
/// vdbhair's strands run root to tip (docs/formats.md), and so do the files of every tool
/// we know, but files exported tip first exist (a reversed curve in Maya or Blender, a script that
/// walks from the free end). ReadOptions::roots says what to do; readStrands() applies it after
/// whichever reader ran (orientStrandRoots()).
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstddef>
#include <functional>
#include <string>

namespace vdbhair {

/// @brief Where a file's strands have their roots.
/// - First: the first vertex (the default, every format's convention).
/// - Last: the last vertex; every strand is reversed.
/// - Auto: measured on the whole file, see orientStrandRoots().
enum class RootEnd { First, Last, Auto };

/// @brief "first", "last", "auto".
const char* rootEndName(RootEnd end);
/// @throw ValueError naming the value and the choices.
RootEnd rootEndFromName(const std::string& name);

/// @brief Unsigned distance (world units) from a point to a head's surface, for RootEnd::Auto.
using SurfaceDistanceFn = std::function<double(const Vec3f& worldPos)>;

/// @brief What orientStrandRoots() decided, and the evidence (for the warning and for tests).
struct RootEndDecision
{
    bool decided = true;          ///< false: Auto could not tell (too few strands), nothing changed
    bool reversed = false;        ///< every strand was reversed
    std::size_t strands = 0;
    /// Auto without a head: the share of all vertices outside the sphere fitted to the first ends
    /// and to the last ends. With a head: the share of strands whose first end is nearer the head
    /// than their last end, and the share the other way round.
    double scoreFirst = 0.0, scoreLast = 0.0;
    bool usedHead = false;
};

/// @brief Strands below this count are too few for RootEnd::Auto without a head: left as stored,
/// with a warning. Measured on random subsets of the 21 shared hairstyles of 93 to 10,000
/// strands (40 draws each): the sphere rule picks the wrong end for 23 % of 5-strand subsets,
/// 4.9 % at 20, 2.7 % at 32, 1.7 % at 50, and never on a whole file.
constexpr std::size_t kAutoRootsMinStrands = 32;

/// @brief Reverse strand @a i in place: its positions and per-vertex attributes.
void reverseStrand(StrandSet& strands, std::size_t i);

/// @brief Put every strand's root first, as @a end says.
///
/// RootEnd::Auto decides once for the whole file (flip every strand or none), because a
/// per-strand test is wrong too often on real hair (long hair lies on the shoulders nearer the
/// head than its roots, bangs hang in front of the face nearer the head's centre than the
/// scalp), while a vote over the file is right on every shared hairstyle:
/// - with @a headDistance (a head mesh or level set): the end nearer the head's surface in the
///   majority of strands is the root end (ties keep the stored order);
/// - without: roots lie on the scalp and the hair lies outside it. A sphere is fitted (least
///   squares, Coope 1993) to the first ends and one to the last ends; the end whose sphere has
///   more of the hair's vertices outside it (beyond 0.98 of its radius) is the root end. The
///   strands' "common centre" of the issue is that sphere's centre. Below
///   kAutoRootsMinStrands strands nothing is changed (decided = false).
///
/// @param headDistance unsigned distance to the head's surface; empty: no head
/// @return what was decided; the caller words the warning (describeRootEndDecision()).
RootEndDecision orientStrandRoots(StrandSet& strands, RootEnd end, const SurfaceDistanceFn& headDistance = {});

/// @brief The warning line for an Auto decision, e.g. "--roots auto reversed 100 % of the
/// strands (7905 of 7905): ...". Empty when Auto kept every strand as stored and was sure.
/// @param setting the option that chose Auto, as the caller spells it ("--roots auto", "roots=auto")
std::string describeRootEndDecision(const RootEndDecision& d, const std::string& setting = "roots=auto");

} // namespace vdbhair
