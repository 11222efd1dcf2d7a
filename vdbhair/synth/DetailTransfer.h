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
///    (exact search; ties to the lower index).
/// 4. **Matching strands**: each output strand takes the member of the matched input cluster whose
///    root offset from its centre, in the centre's aligned frame, is nearest to its own.
/// 5. **Eq. 5-8**: D_α in the centre's aligned root frame, D_β in rotation-minimizing frames along
///    the centre (Frames.h, started from the aligned tangent in both hairstyles), blended with
///    weights (n_s − i)/(n_s − 1) and (i − 1)/(n_s − 1). The paper's γ_β is shifted by a constant
///    so that both estimates, and so the strand, start at the prescribed output root (the paper's
///    text swaps γ_α(1) and γ_β(1) there; this is its stated intent).
/// Transferring a cluster onto its own centre gives the cluster back (tested), with either blend.
///
/// DetailBlend::RootFrame (the default) uses γ_α alone, the detail in the centre's aligned root
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
    Paper       ///< Eq. 7: γ_α at the root blended linearly to γ_β at the tip
};
/// @throw ValueError unless "root-frame" or "paper".
DetailBlend detailBlendFromName(const std::string& name);
const char* detailBlendName(DetailBlend blend);

/// How detail is laid along an output strand whose centre is longer or shorter than the input's.
enum class DetailScale
{
    /// Vertex by vertex (Eq. 5-8 as printed): detail stretches with the length ratio, so curls
    /// onto a wisp k times as long come out k times as long (the paper's stated limitation).
    Index,
    /// The displacement read at the same arc length along the input centre as along the output
    /// centre, and mirrored back and forth beyond the input centre's end: curls keep their size
    /// and spacing whatever the lengths, repeated along a longer strand (its wisp's spread
    /// repeats too: strands gather and part again every two input lengths). Measured against a
    /// split that kept the slowly varying part per index: Curly_100's detail onto straight.hair
    /// arrived with turning per head radius 4.36 against 1.00 (the example's 7.92, index 0.51),
    /// harolongo's 3.40 against 2.85 (its own 3.83, index 2.00).
    ArcLength
};
/// @throw ValueError unless "index" or "arc-length".
DetailScale detailScaleFromName(const std::string& name);
const char* detailScaleName(DetailScale scale);

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
                             int outVertices = 0);

} // namespace vdbhair
