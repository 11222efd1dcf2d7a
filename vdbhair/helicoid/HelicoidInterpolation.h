/// @file HelicoidInterpolation.h
/// @brief New hairs from guide p-helicoids by interpolating their parameters (Piuze et al. 2011,
/// §4.1-4.3), not their points: curvature then varies smoothly between guides (Fig. 6).
///
/// **Weights** (§4.1): Shepard's, ShepardWeights.h (power 3, every guide or the K nearest).
///
/// **kT sign rule** (§4.1): before blending, a piece with kT < 0 is described by -kT and a frame
/// turned by π, the same curve; two geometrically identical guides that differ only in the sign of
/// kT then no longer blend into a straight helicoid. The half turn is about E_T, not E_N as the
/// paper writes: with Eq. 1 as printed (theta = atan2(kT y1 + kN y2, 1 + kN y1 - kT y2) + kB y3),
/// negating kT and turning the frame about E_T maps (y1, y2, y3) to (y1, -y2, -y3), theta to
/// -theta and leaves E_T unchanged everywhere (HelicoidFit.h flips its fits the same way); a turn
/// about E_N does not preserve the field. Frames after a flipped piece are themselves turned by π,
/// so a piece's half turn is added to its roll only where the flip state changes.
///
/// **Frames**: the first piece's frame Q (its roll folded in) is averaged by FrameAverage.h
/// (quaternions sign-aligned to the heaviest guide, weighted, normalized).
///
/// **p-helicoids** (§4.2), the rule: a guide of P_i pieces is a step function k_i(s) over normalized
/// arc length s ∈ [0, 1] with breakpoints c_i[0..P_i] (c_i[j] = length of its first j pieces / L_i).
/// The new hair has P pieces: the heaviest guide's count, blending only the guides of that count
/// (PieceCountRule::Heaviest, the default, where every C_i below is the identity on breakpoints), or
/// the largest count among the guides with non-zero weight (Most: for Shepard over every guide the
/// same P everywhere, so nothing jumps); with
/// C_i(u) = c_i linearly interpolated at the fractional index u·P_i, its breakpoints are
/// b_j = Σ w_i C_i(j / P) and piece j takes k_j = Σ w_i k_i(C_i((j + ½) / P)), i.e. each guide's k
/// resampled along its own normalized arc length. Breakpoints and k are continuous in the weights,
/// so for a fixed P guides of different piece counts blend without a jump; a guide with P_i = P
/// is reproduced piece for piece at weight 1, and a guide with fewer pieces is split into
/// sub-pieces of its own k — not the same curve, since each piece restarts the helicoid at its
/// joint. Measured on fitted real hair (straight.hair, 1,000 strands at 30 vertices, 10 % guides,
/// two neighbours), resampling the k of fits with other piece counts gave tips 50-70 % of the
/// length away from the blend of the two guides' tips midway between them: a fit's piece k are
/// only meaningful in their own frame chain. Hence the default Heaviest, which never resamples. The new hair's length is
/// L = Σ w_i L_i, piece j is (b_{j+1} - b_j) L long, and as in the paper, pieces after the first take
/// their frame from the end of the previous one (Eq. 2), so every joint is C¹ (frames continuous).
/// Their roll about E_T (fits have one) is the weighted circular mean of each guide's roll at the
/// piece where that guide's own piece begins (0 where the new piece continues a guide piece).
/// The tracing step is Σ w_i step_i; waviness (Eq. 4) blends amplitude and noise over all guides
/// (0 where a guide has none), frequency and phase over the guides that have it. Wisps are not
/// carried over: each new hair is one strand.
///
/// **Arbitrary surfaces** (§4.3): when the new roots and the guides have surface normals, a surface
/// frame W is built at each root from its normal n (W = [n, u, n × u], u the reference axis `up`
/// projected onto the tangent plane; x, then z where up is nearly normal — the rule of
/// `vdbhair roots`). Each guide's first frame is expressed in its own root's W_i, R_i = W_iᵀ Q_i;
/// the R_i are averaged as above, and the new hair's frame is Q = W R̄: the hair leaves the scalp
/// at the same angle to the surface as its guides, wherever the surface turns.
///
/// **Arcs** (HelicoidBlend::Arcs; `--blend arcs`, the default of reconstruction): fits of neighbouring real strands
/// are not parameterized alike (their first frames differ by a 90th percentile of 70° of roll that
/// their k compensate, and their pieces break at different places), so averaging their (Q, k)
/// makes a curve like neither (docs/interpolation.md: 26 % error against point blending's 2.4 %
/// on straight hair). Under this rule each guide is first re-described, from its own trace, as A
/// equal pieces with k = (kT, 0, 0, 0), which Eq. 1 makes circular arcs, joined with rolls: a
/// p-helicoid (§3.4) in which the frame carried from piece to piece (Eq. 2 along an arc) is the
/// rotation-minimizing frame of the curve. Its first frame is canonical: the root's surface frame W
/// (or, without normals, one frame shared by every guide: the mean root tangent and `up`) turned by
/// the least rotation that takes W's first axis onto the strand's root tangent. Each arc j is then
/// a curvature vector c_j = kT (cos Ψ_j, sin Ψ_j) in the carried frame, Ψ_j the sum of the rolls up
/// to it, and arc j turns the tangent at s_j = jL/A into the tangent at s_{j+1}. Guides described
/// alike blend alike: the new hair's first frame is the weighted mean root tangent with the
/// heaviest guide's canonical frame carried onto it by the least rotation (relative to W as
/// above), its length Σ w_i L_i and its arcs c_j = Σ w_i c_ij, each guide's turned by the roll
/// between its own frame carried onto that tangent and the new one, written back as kT = |c_j|
/// and rolls Ψ_j − Ψ_{j−1}. Only guides shaped like the heaviest take part (a parting between
/// guides would otherwise cancel their bends into a hair that sticks out): each weight is
/// multiplied by (1 − (u/0.25)²)², u the mean distance between the guide's root-relative points
/// and the heaviest's at 16 equal fractions of the length, over the longer length (in the
/// surface frame's axes with surface frames), and renormalized. A is the same for every guide: `arcs`, or one arc per 0.2 radian of the
/// most-turning guide's turning, between 16 and 512. The output is again a scene of p-helicoids.
/// HelicoidBlend::Fitted (the default of interpolation) blends the fits' own pieces by the rules
/// above, as the paper prints them. The two differ where guides differ: arcs blend curvature
/// vectors, so opposite bends cancel as blended points do (Fig. 6's π-rotated guides meet in a
/// straight hair), where fitted pieces keep the guides' curvature between them (Fig. 6, tested);
/// arcs follow captured hair far more closely (docs/interpolation.md).
///
/// **Exactness**: a root with a single weight (a coincident root, or a single guide) returns that
/// guide unchanged, translated to the root (and rotated by W W_iᵀ with surface frames).
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/helicoid/ShepardWeights.h>

#include <openvdb/util/NullInterrupter.h>

#include <memory>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief How many pieces a new hair has when its guides' piece counts differ (§4.2, see above).
enum class PieceCountRule
{
    Heaviest,  ///< the heaviest guide's count, blended only with the guides of that count (their
               ///< weights renormalized): no piece is resampled; the shape jumps where the heaviest
               ///< guide changes between guides of different counts
    Most,      ///< the most pieces among the guides with weight: constant under Shepard over every
               ///< guide (no jump anywhere), but a guide with fewer pieces is split and its shape changes
};

/// @brief What a new hair blends of its guides (see "Arcs" above).
enum class HelicoidBlend
{
    Fitted,  ///< the guides' fitted pieces as they are (§4.1-4.2 as printed, with PieceCountRule)
    Arcs,    ///< each guide re-described as equal circular arcs in its rotation-minimizing frame from a canonical root frame
};

/// @brief "arcs" or "fitted".
const char* helicoidBlendName(HelicoidBlend blend);
/// @throw ValueError naming @a name and the choices.
HelicoidBlend helicoidBlendFromName(const std::string& name);

struct HelicoidInterpolationParams
{
    ShepardParams shepard;
    HelicoidBlend blend = HelicoidBlend::Fitted;  ///< the paper's; ReconstructParams chooses Arcs
    std::size_t arcs = 0;  ///< HelicoidBlend::Arcs: arcs per hair; 0: one per 0.2 radian of the most-turning guide (16..512)
    PieceCountRule pieceCount = PieceCountRule::Heaviest;  ///< HelicoidBlend::Fitted; measured: Most is far worse on fitted real hair (docs/interpolation.md)
    bool kTSignRule = true;                    ///< §4.1; off only to show what it prevents
    Vec3d up{0.0, 1.0, 0.0};                   ///< reference axis of surface frames (as `vdbhair roots --up`)
    std::size_t maxVertices = std::size_t(1) << 28;  ///< refuse requests that would grow more (12 bytes each: 3 GB)
};

/// @brief The declared blend, arcs and Shepard power (vdbhair/Parameters.h); the neighbours are
/// guideNeighborsParam()'s (PointInterpolation.h), the up axis and vertex cap the verb's.
const ParamTable<HelicoidInterpolationParams>& helicoidInterpolationParameters();

/// @brief Roots at which to interpolate: #R world positions and, for surface frames, #R unit
/// outward normals (or none).
struct InterpolationRoots
{
    std::vector<Vec3d> positions;
    std::vector<Vec3d> normals;
    /// #R group ids or empty: a root blends only guides of its group (interpolatePoints(); empty:
    /// each root takes the group of the guide nearest it)
    std::vector<std::int32_t> groups;
    /// #R values in [0, 1] or empty (interpolateGuides(), GroomControls.h): the share of roots kept
    /// (density) and the share of each new hair's length kept (length; 0 grows none)
    std::vector<float> density, length;
};

/// @brief The surface frame W at a root with normal @a normal (see above).
/// @throw ValueError for a zero or non-finite normal.
FrameD surfaceFrame(const Vec3d& normal, const Vec3d& up);

/// @brief Check a guide scene before interpolating from it.
/// @throw ValueError naming the guide, the piece and the value: no guides, no pieces, a non-finite
/// root, frame, k, length, roll or step, a negative piece length or a zero total length.
void validateGuideScene(const Scene& guides);

class HelicoidInterpolator
{
public:
    /// @param guideNormals empty, or #G unit normals at the guide roots (surface frames)
    /// @throw ValueError (validateGuideScene, validateShepardParams, normals of the wrong size).
    HelicoidInterpolator(const Scene& guides, const HelicoidInterpolationParams& params,
                         const std::vector<Vec3d>& guideNormals = {});
    ~HelicoidInterpolator();

    /// @brief The new hair at @a root; @a normal non-null (and guide normals given) for surface frames.
    SceneGuide interpolate(const Vec3d& root, const Vec3d* normal = nullptr) const;

    /// @brief The Shepard weights at @a root (they sum to 1).
    void weights(const Vec3d& root, std::vector<GuideWeight>& out) const;

    const GuideLocator& locator() const { return *mLocator; }
    /// @brief An upper bound of the vertices one new hair grows (checked against overflow).
    std::size_t maxVerticesPerHair() const { return mMaxVertices; }

private:
    struct Prepared;
    struct ArcGuide;
    void prepareArcs(const std::vector<Vec3d>& guideNormals);
    SceneGuide interpolateArcs(const std::vector<GuideWeight>& ws, const Vec3d& root, const Vec3d* normal) const;
    /// @a avg (relative to the surface frames with them) in world axes at a root with @a normal.
    FrameD placeFirstFrame(const FrameD& avg, const std::vector<GuideWeight>& ws, const Vec3d* normal) const;
    void blendWaviness(const std::vector<GuideWeight>& ws, SceneGuide& out) const;

    const Scene& mScene;
    HelicoidInterpolationParams mParams;
    std::vector<Prepared> mGuides;
    std::vector<FrameD> mFirstFrames;  ///< Q of each guide's first piece (relative to W_i with surface frames)
    std::vector<ArcGuide> mArcs;       ///< HelicoidBlend::Arcs: each guide's arcs
    std::vector<FrameD> mArcFrames;    ///< HelicoidBlend::Arcs: each guide's canonical first frame (relative to W_i with surface frames)
    std::size_t mArcCount = 0;
    std::vector<Vec3d> mNormals;       ///< guide normals (surface frames) or empty
    std::unique_ptr<GuideLocator> mLocator;
    bool mSurface = false;
    std::size_t mMaxVertices = 0;
};

/// @brief New hairs at every root: a scene of one guide per root (no wisps), with the guides'
/// seed, step and integrator; grow it with growScene(). In parallel, identical for any thread count.
/// With root normals and no @a guideNormals, each guide takes the normal of the root nearest it.
/// @throw ValueError (see HelicoidInterpolator; no roots; normals of the wrong size), LimitError
/// (more than params.maxVertices vertices would grow: estimated before any work), InterruptedError.
Scene interpolateHelicoids(const Scene& guides, const InterpolationRoots& roots, const HelicoidInterpolationParams& params,
                           const std::vector<Vec3d>& guideNormals = {}, bool threaded = true,
                           openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Guides from plain strands (`interpolate` given a strand file, not a scene): every strand
/// fitted (fitStrands() with @a fit), one guide each in order, traced with RK4 at the first fit's
/// step (fits are streamlines, regrown exactly).
/// @param where names the strands in messages (a path, "interpolate(guides)")
/// @throw ValueError naming the strand that cannot be fitted (a zero length), InterruptedError.
Scene guideSceneFromStrands(const StrandSet& strands, const FitParams& fit, const std::string& where, bool threaded = true,
                            openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Normals at the guide roots for surface frames: radial from the scene's head sphere if it
/// has one, else none (interpolateHelicoids() and interpolatePoints() then give each guide the
/// normal of the root nearest it).
std::vector<Vec3d> sceneGuideNormals(const Scene& guides);

} // namespace vdbhair
