/// @file Comb.h
/// @brief Detail-preserving combing (Wang et al. 2009, §6: "first applying detail-preserving
/// deformations to the strands in the coarsest level and then transferring original finer-level
/// details onto the edited coarsest level"; the deformation is Xu et al. 2007's §3.1).
///
/// **A stroke** is a polyline in world space with a radius r and a strength s in [0, 1]; its reach
/// is the tube of radius r around it, where its influence is w(d) = s (1 − (d/r)⁴)² at distance d
/// (flat near the axis, 0.88 s at r/2, smoothly zero at the wall; a comb's teeth hold what they
/// pass through), and its direction at a point is that of the nearest segment.
///
/// **The coarsest level** is the coarsest level of the hairstyle's own hierarchy (Clustering.h,
/// built as synthesis builds it). Each coarsest strand (n_s vertices) is deformed in the gradient
/// domain: walking from the root, every edge e_i keeps its length and is turned by a rotation R_i,
/// and the vertices are the root plus the running sum of the turned edges R_i e_i — the
/// least-squares (Poisson) reconstruction of Xu et al. §3.1 from transformed edge vectors with the
/// root as the only fixed vertex, whose normal equations (a tridiagonal Laplacian) the running sum
/// solves exactly. The rotations are propagated along the strand: R_i is R_{i−1} turned further,
/// by the fraction f = 1 − (1 − w)^(|e_i| / r) of the angle between the strand's *smoothed*
/// direction at i (already turned by R_{i−1}) and the stroke's direction, w being the mean
/// influence over the wisp's strands at vertex i, each where it has moved to (a comb that catches
/// part of a wisp pulls the whole wisp part of the way; the centre alone would leave a wisp whose
/// centre the stroke misses untouched while the stroke passes through its strands). So inside the reach the strand's overall direction
/// turns toward the stroke's (fully for s = 1; for s < 1, the share s of the way over one r of its
/// length at the tube's axis), beyond it the rest of the strand follows rigidly, and the strand's own
/// waves and curls (which the smoothed direction, σ = StrandSamples::kDetailSmoothing, leaves out)
/// turn with it instead of being straightened. Several strokes apply in order, each to the strands
/// as the previous left them; their rotations compose.
///
/// **Detail re-transfer.** Every strand of the hairstyle (at its own vertices) gets the rotation
/// field of its coarsest centre, read at its own arc length (rotations interpolated between the
/// centre's edge midpoints, held beyond its ends), and is rebuilt from its root by the same running
/// sum of turned edges. Composed through the levels, the paper's re-transfer of each finer level's
/// detail onto the edited level above is this same rotation of every strand's edges, because each
/// strand keeps its own detail relative to its own centre; in this form it keeps every segment's
/// length and every root exactly, and a strand whose centre no stroke reaches is copied unchanged.
///
/// **The head, and no new kinks.** The combed strands are then swept out of the head along their
/// length (CombParams::head). Where the comb's turn and the head's push together still bend a
/// strand by over kKinkDegrees between two edges at a vertex where its input did not (a strand
/// deep inside a body mesh pressed against its surface: 4 of 288 random strokes on six grooms,
/// scripts/comb_strokes.py), that strand alone is combed again with a share of its wisp's turn,
/// every rotation slerped from none, the largest share found by halving [0, 1] six times with
/// which no new kink is left after the head's sweep. A share of 0 is the input, which the head
/// leaves as it is, so no strand ends with a new kink; CombStats::backedOff counts them.
#pragma once

#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/synth/Synthesis.h>

#include <array>
#include <string>
#include <vector>

namespace vdbhair {

struct CombStroke
{
    std::vector<Vec3d> points;  ///< world positions, at least 2
    double radius = 0.0;        ///< world units, positive
    double strength = 1.0;      ///< 0 (no effect) to 1 (align fully)
};

/// @brief Strokes from a JSON file: `{"vdbhair": "strokes/1", "strokes": [{"points": [[x, y, z],
/// ...], "radius": R, "strength": S}, ...]}` (strength optional, default 1), or one stroke object.
/// @throw IoError, FormatError naming the file, the key path and the rule (fewer than two points,
/// a radius that is not positive, a strength outside [0, 1], non-finite values, unknown keys).
std::vector<CombStroke> readStrokes(const std::string& path);

/// @throw ValueError naming @a where, the stroke's index and the rule.
void validateStroke(const CombStroke& stroke, std::size_t index, const std::string& where);

struct CombParams
{
    /// vertices (n_s), cluster (ε, up, seed): the hierarchy, built as synthesis builds it, of two
    /// levels by default (the strands and their wisps, 16 strands or more each): a comb moves
    /// wisps, and synthesis's third level (a quarter of the wisps) is a region of the head a
    /// stroke would move as one.
    SynthParams synth = [] {
        SynthParams p;
        p.cluster.levels = 2;
        return p;
    }();
    double smoothing = StrandSamples::kDetailSmoothing;  ///< σ of the strand directions, a fraction of the vertices
    /// The head the combed strands may not enter, with its policy (HeadObstacle.h): under NoDeeper
    /// (readHeadObstacle()'s default) no vertex goes deeper into it than the input's vertex of the
    /// same index was, so a vertex outside stays outside. The combed strands are swept out of it
    /// along their length (resolveHeadCollisions(), HeadCollision.h, as new hair is): a strand that
    /// meets it follows it, its lengths kept, the bend spread over a stretch rather than made at
    /// one vertex (which kinked combed hair at the shoulders). Unset: the scalp's level set when
    /// combHair() is given one, else the sphere fitted to the roots (headFromRoots(), NoDeeper);
    /// HeadObstacle::none(): no head.
    HeadObstacle head;
    /// The policy of a head the front end gives (a file, a sphere): what it makes @c head with
    /// (`--head-policy`); the scalp's and the one fitted to the roots keep their own.
    HeadPolicy headPolicy = kDefaultHeadPolicy;

    /// @throw ValueError naming the parameter, its value and the rule.
    void validate(const char* where) const;
};

/// @brief comb's parameters declared once (Parameters.h): synth's hierarchy (synthParameters(),
/// nested: their defaults are CombParams::synth's) and up, then the smoothing and the head policy.
/// The head, the scalp and the strokes are each front end's own.
const ParamTable<CombParams>& combParameters();

struct CombStats
{
    std::size_t clusters = 0;        ///< coarsest clusters
    std::size_t combedClusters = 0;  ///< coarsest strands some stroke reached
    std::size_t movedStrands = 0;    ///< strands of those clusters
    /// Over every (stroke, input vertex within its reach): mean angle in degrees between the
    /// strand's tangent and the stroke's direction (at the nearest point), before and after
    double angleBefore = 0.0, angleAfter = 0.0;
    std::size_t reachVertices = 0;
    /// Mean total turning per unit length of the moved strands, before and after (radians per unit)
    double turningBefore = 0.0, turningAfter = 0.0;
    std::string head;               ///< the head used (HeadObstacle::describe()), "none" without one
    std::size_t headDeflected = 0;  ///< moved strands the head pushed out
    /// Vertices of the moved strands inside the head (signed distance below 0), before and after
    std::size_t insideHeadBefore = 0, insideHeadAfter = 0;
    /// Moved strands that turn by more than kKinkDegrees between two consecutive edges and did
    /// not before: kinks the comb (or the head pushing hair out of it) made
    std::size_t newKinks = 0;
    /// Moved strands combed less than their wisp so as to make no new kink (combHair(): the
    /// largest share of the wisp's turn that bends neither the strand nor the head's push of it
    /// over kKinkDegrees at a vertex the input did not)
    std::size_t backedOff = 0;
};

struct CombResult
{
    StrandSet strands;                 ///< the input combed: same strands, vertices and attributes
    std::vector<std::int32_t> cluster; ///< #strands: coarsest cluster of each
    CombStats stats;
    std::vector<SynthStage> stages;
};

/// @brief Deform one coarsest strand by one stroke (the deformation above).
/// @param members the wisp's strands at as many vertices as @a points (world): the influence w at
/// vertex i is the mean of the stroke's influence on them at vertex i (where each has moved to),
/// its direction the influence-weighted mean; empty: the influence on @a points itself
/// @param rotations receives one rotation per edge as quaternions (w, x, y, z)
/// @param maxTurnPerLength if positive, the most the stroke turns the strand per unit of its
/// length (radians): strands whose own edges are long cannot bend more sharply than their edges
/// show (combHair(): kMaxCombTurnPerEdge over the longest edge of the wisp's strands)
/// @return whether the stroke reached it (false: @a out equals @a points, rotations are identity)
bool combPolyline(const std::vector<Vec3d>& points, const std::vector<std::vector<Vec3d>>& members, const CombStroke& stroke,
                  double sigmaVertices, std::vector<Vec3d>& out, std::vector<std::array<double, 4>>& rotations,
                  double maxTurnPerLength = 0.0);

/// @brief Comb @a strands with @a strokes in order.
/// @param scalp the scalp level set, or null for the sphere fitted to the roots (the hierarchy's
/// frames; the head too when CombParams::head is unset)
/// @throw ValueError (bad strokes or parameters, no strands, too few for the levels), InterruptedError.
CombResult combHair(const StrandSet& strands, const std::vector<CombStroke>& strokes, const CombParams& params,
                    openvdb::FloatGrid::ConstPtr scalp = nullptr, bool threaded = true,
                    openvdb::util::NullInterrupter* interrupter = nullptr);

} // namespace vdbhair
