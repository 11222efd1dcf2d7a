/// @file DetailTransfer.h
/// @brief Cluster-oriented detail transfer (Wang et al. 2009, §5.2, Eq. 4-8): the strands of a
/// finer output level get the detail of an input cluster, superposed on their output centre.
///
/// 1. **Output clusters** (top-down, Kim & Neumann 2002): every output root of the finer level joins
///    the coarser output strand whose root is nearest.
/// 2. **Per-strand-aligned frames** (Eq. 4): a centre's root frame turned about its normal so its
///    tangent follows the strand's average direction v_g = Σ_{i≥2} (γ(i) − γ(1)) projected onto
///    the tangent plane (unchanged where that projection vanishes).
/// 3. **Matching clusters**: PCA (n_f components, Pca.h) of the input and output centres together,
///    in their aligned frames; each output centre takes the input centre nearest in feature space
///    (exact search; ties to the lower index), or by default the nearest with share left
///    (DetailMatchParams: balanced, each set at one scale); with DetailMatchParams::place the
///    distance between their roots in (u, v) counts too.
/// 4. **Matching strands**: each output strand takes a member of the matched input cluster by root
///    offset from its centre, in the centre's aligned frame: the nearest, or by default
///    (DetailMatchParams) pairs by increasing offset distance with each member serving at most
///    balance × its even share of the output wisp's strands.
/// 5. **Eq. 5-8**: D_α in the centre's aligned root frame, D_β in rotation-minimizing frames along
///    the centre (Frames.h, started from the aligned tangent in both hairstyles), blended with
///    weights (n_s − i)/(n_s − 1) and (i − 1)/(n_s − 1). The paper's γ_β is shifted by a constant
///    so that both estimates, and so the strand, start at the prescribed output root (the paper's
///    text swaps γ_α(1) and γ_β(1) there; this is its stated intent).
/// Transferring a cluster onto its own centre gives the cluster back (tested), with the root-frame
/// and paper blends.
///
/// **Edges** (DetailBlend::Edges, the default). Displacements from a centre ("strand minus centre
/// at the same vertex") do not survive a centre of another length or bend: laid onto longer
/// centres their tangential drift, mirrored, compresses and stretches a curl's pitch (Curly_100's
/// curls onto straight.hair came out with about 65 % too much turning under balanced matching),
/// and held in a bending frame they loop (below). Instead a strand is split into a carrier, its
/// low-pass (smoothPolyline(), σ = 3/16 of its vertices), and its own
/// edges, each expressed in the carrier's rotation-minimizing frame at the edge's middle (started
/// from the aligned tangent, as D_β's; a run of collinear edges, a straight piece of a coarse
/// polyline, in the frame at the run's middle, so that it stays straight). The output strand starts at its root and lays the edges
/// one after another in the frames of the output carrier (the output centre smoothed at σ = half
/// the input centre's vertices, in world units, plus the strand's smooth offset from its input
/// centre's carrier, smoothed alike, held in the aligned root frames, as D_α; with wisps matched by
/// place, a strand that would then rise above its root more than its input strand and its output
/// centre do, by a twentieth of the head radius, has its offset turned only as the root normal
/// turns) at the arc each edge
/// reached along its own carrier (DetailTransfer.cc, "Carrier smoothing", says why the two σ);
/// so edges keep their lengths and the
/// angles between them, and a curl keeps its turning per length (tested on a helix laid onto a
/// straight centre three times as long and onto a quarter circle). DetailScale decides how far
/// the strand runs: its own length (Strand), its own scaled by the centres' carrier lengths with
/// the edges (Index), or its own plus what the output centre's carrier has over the input centre's
/// (ArcLength; at least its own times their ratio), where past the strand's end a loop of it repeats: the edges from
/// the place most like the strand's end on, at least a quarter of the strand (a period of a
/// curl), turned as a whole so that its net step points along the carrier and its start joins the
/// strand's end. A strand shorter than one and a half turns of its wisp's curl (a C, whose curl
/// its carrier holds, so that a loop of its edges repeats only their crimp) continues instead as
/// the helix of its wisp: the wisp's turning per length and mean cosine to its centre (radius,
/// pitch and handedness; DetailEdges.h, wispCurl()), eased in from the strand's last direction
/// and steered onto the carrier (tested: three quarters of a helix turn onto a centre eight times
/// as long keeps the helix's radius within 2 % and its turning within 3 %; Curly_100 onto
/// straight.hair keeps its curl amplitude within 7 %, docs/editing.md). A wisp transferred onto its own centre comes back (tested to 1e-4 of the strand's
/// length, with every DetailScale): the same carriers, frames and arcs, and its own length.
///
/// **Matching** (DetailMatchParams): balanced by share, at one scale, by default.
///
/// DetailBlend::RootFrame uses γ_α alone, the detail in the centre's aligned root
/// frame. Eq. 7's blend toward γ_β, as implemented here, adds a wiggle wherever the input and
/// output centres bend differently (the displacement turns with the two curves' rotation-minimizing
/// frames): measured end to end, the bundled ponytail's turning per length came out 6.0 times
/// the example's with Eq. 7 against 0.18 with γ_α alone, Curly_100's length 3.5 times against 0.12.
/// That is what offset curves do: a displacement held in a curve's moving frame traces a curve
/// that loops wherever the displacement is longer than the curve's radius of curvature (|D| κ > 1),
/// and cluster offsets (tenths of a head radius) exceed the radius of curvature of curly or tied
/// centres; not proven here to be the whole cause.
#pragma once

#include <vdbhair/synth/Pca.h>
#include <vdbhair/synth/StrandSamples.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief The aligned frame of Eq. 4 for sample row @a row (root-relative, in @a rootFrame).
ScalpFrame alignedFrame(const float* row, int vertices, const ScalpFrame& rootFrame);

/// @brief What detail transfer needs of one level of the input hierarchy.
struct TransferSource
{
    const StrandSamples* strands = nullptr;        ///< the input's finer level
    const StrandSamples* centers = nullptr;        ///< the input's coarser level (centres of @c strands)
    const std::vector<std::uint32_t>* label = nullptr;  ///< #strands: the centre of each strand
};

enum class DetailBlend
{
    RootFrame,  ///< γ_α only: displacements in the centre's aligned root frame
    Paper,      ///< Eq. 7: γ_α at the root blended linearly to γ_β at the tip
    /// The strand's own edges (the default; DetailTransfer.h, "Edges"): each edge in the
    /// rotation-minimizing frame of the strand's low-passed self (its carrier), re-laid in the
    /// frame of the output centre's low-passed self at the same place along it. Edges keep their
    /// lengths and the angles between them, so curls keep their turning per length.
    Edges
};
/// @throw ValueError unless "root-frame", "paper" or "edges".
DetailBlend detailBlendFromName(const std::string& name);
const char* detailBlendName(DetailBlend blend);

/// How detail is laid along an output strand whose centre is longer or shorter than the input's.
enum class DetailScale
{
    /// Vertex by vertex (Eq. 5-8 as printed): detail stretches with the length ratio, so curls
    /// onto a wisp k times as long come out k times as long (the paper's stated limitation). With
    /// DetailBlend::Edges every edge is scaled by the ratio of the centres' carrier lengths.
    Index,
    /// The displacement read at the same arc length along the input centre as along the output
    /// centre: curls keep their size and spacing whatever the lengths, and the output strand
    /// runs the output centre's length (with DetailBlend::Edges: its input strand's carrier length
    /// plus what the output centre's carrier has over the input centre's). Beyond the input's end, the root-frame and paper blends mirror
    /// the displacement back and forth (a wisp's spread repeats too: strands gather and part
    /// again every two input lengths); DetailBlend::Edges repeats a loop of the strand (a period
    /// of its detail) instead, turned as a whole (DetailTransfer.h, "Edges").
    ArcLength,
    /// DetailBlend::Edges: the strand keeps its own length and pitch, laid along the output
    /// centre at its own arc length (past the centre's end, straight on along its last tangent);
    /// synthesis's default, where output centres come from the example and so are of its
    /// lengths. The other blends read it as ArcLength.
    Strand
};
/// @throw ValueError unless "index", "arc-length" or "strand".
DetailScale detailScaleFromName(const std::string& name);
const char* detailScaleName(DetailScale scale);

/// How output centres choose input centres (step 3).
struct DetailMatchParams
{
    /// Balanced matching: pairs (output centre, input centre) are taken by increasing feature
    /// distance, and an input centre serves output wisps of at most @c balance times its own
    /// share of the output's strands (its members' part of the input's strands: an even share
    /// kept wisps larger than the mean from their own detail, so a hairstyle onto itself did not
    /// come back); an output wisp that fits no candidate's share takes its nearest. Within a
    /// matched wisp, a member serves at most @c balance times its even share of the output wisp's
    /// strands (step 4: by nearest offset alone 100 strands of Curly_100 took a few members many
    /// times, and their lengths). Without it a few input wisps, those that
    /// match long straight centres best, lay their detail everywhere: Curly_100 onto
    /// straight.hair arrived at 4.5 to 9.9 turning per head radius with the seed (7.90 its own).
    /// Balanced matching compares centres at one scale (each set's rows divided by its median
    /// centre length), so that long output wisps match input wisps by shape rather than by size;
    /// at one scale alone, straight wisps chose the straightest input centres, whose strands
    /// are the tightest curls (Curly_100 onto straight.hair 8.8-17.5), which the balance evens out.
    /// 0 turns all three off (every output centre takes its nearest input centre at absolute
    /// size and every output strand its nearest member, the paper's rule).
    double balance = 1.1;
    /// Input centres considered per output centre, nearest first (balanced matching only;
    /// transfer between hairstyles, whose wisps differ more, considers more).
    int candidates = 16;
    /// Where the centres' roots are counts too: the squared (u, v) distance between an output
    /// centre's root and an input centre's is added to their feature distance, scaled so that
    /// two median spacings of the input centres cost @c place² times the input centres' mean
    /// squared feature norm. Synthesis sets 1: output wisps then take their detail from the
    /// example's wisps near their place, so a short layered crown stays short and a nape stays
    /// long. By shape alone, Ruby's short hair used 96 of its 200 finer wisps, and not those of
    /// its short strands (a third of its strands are under a head radius long, a quarter of the
    /// output's). Much more weight brings in wisps of other shapes: at 2 and 3, strands stood
    /// out of Ruby's crown. 0 (the default, and transfer between hairstyles): by shape alone.
    double place = 0.0;

    /// @throw ValueError naming the parameter, its value and the rule.
    void validate(const char* where) const;
};

struct TransferStats
{
    std::size_t clusters = 0;             ///< output clusters (coarser output strands with members)
    std::size_t distinctSources = 0;      ///< distinct input clusters used
};

/// @brief The finer output level: strands rooted at @a roots (world, on the scalp), detail from
/// @a source, superposed on the coarser output strands @a outCenters.
/// @param outLabel if given, receives each new strand's output centre
/// @param givenLabel if given (#roots, values below outCenters.count()), each new strand's output
/// centre, in place of step 1's nearest root (transfer onto a hairstyle keeps its own wisps)
/// @param outVertices vertices per new strand (0: as @a outCenters'); the input's displacement is
/// read between its vertices (linearly), so a longer output strand can carry the input's detail
/// at the input's own spacing (DetailScale::ArcLength)
/// @throw ValueError if @a source is incomplete or empty, or @a givenLabel does not fit; InterruptedError.
StrandSamples transferDetail(const TransferSource& source, const StrandSamples& outCenters,
                             const std::vector<Vec3d>& roots, const ScalpMap& map, int components = Pca::kDefaultComponents,
                             std::vector<std::uint32_t>* outLabel = nullptr, TransferStats* stats = nullptr,
                             DetailBlend blend = DetailBlend::RootFrame, bool threaded = true, openvdb::util::NullInterrupter* interrupter = nullptr,
                             const std::vector<std::uint32_t>* givenLabel = nullptr, DetailScale scale = DetailScale::Index,
                             int outVertices = 0, const DetailMatchParams& match = DetailMatchParams{});

} // namespace vdbhair
