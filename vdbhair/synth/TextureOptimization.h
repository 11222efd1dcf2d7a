/// @file TextureOptimization.h
/// @brief Texture optimization (Kwatra, Essa, Bobick, Kwatra 2005, "Texture Optimization for
/// Example-based Synthesis"): the 2D synthesis of Wang et al. (2009, §5.1), which synthesizes an
/// output feature map with the look of the example's.
///
/// Kwatra's energy over the output x is E(x) = sum_p |x_p - z_p|^r (their Eq. 1 with the robust
/// exponent of their §3.1), where p runs over a grid X+ of output neighbourhoods (w x w windows,
/// all channels) spaced w/4 apart, x_p is the output window and z_p its nearest example window.
/// It is minimized by an EM-like alternation, coarse to fine. Algorithm (steps labelled in
/// TextureOptimization.cc):
/// 1. Pyramids: the example and the output are halved `levels - 1` times (2 x 2 box filter,
///    sizes rounded up). A coarse example pixel is valid only if every fine pixel under it is,
///    so a coarse window that is wholly valid covers only valid fine pixels.
/// 2. Stages: at level l each width w of @c neighbourhoodSizes (given at the finest level) becomes
///    w / 2^l pixels (rounded), largest first; at coarse levels widths below @c minNeighbourhood
///    are dropped. Every width is clamped to the output's shorter side and to the largest square
///    of valid example pixels, so a small valid region shrinks the windows; if that square is
///    smaller than @c minNeighbourhood, the finest level throws ValueError and a coarser level
///    is skipped. Repeated widths run once.
/// 3. Initialization, at the coarsest level used: the output is tiled with w x w patches (w the
///    first stage's width) copied from example windows drawn uniformly among the wholly valid
///    ones (TextureInit::Anywhere), or from the valid window nearest to the patch's own place (in
///    example pixels, scaled by the size ratio) moved by a random offset (TextureInit::Nearby),
///    patch i from the random stream (seed, i). Each later level starts from the previous
///    level's output, upsampled bilinearly. Every output pixel remembers the example pixel it
///    came from (here; then, after each M-step, the one the heaviest window covering it gave).
/// 4. Sources: every example window lying wholly in valid pixels (all positions, spacing 1). Its
///    search key is its w x w x C values box-filtered to at most @c keyTaps x @c keyTaps cells
///    (each cell's mean times the square root of its pixel count, so key distances never exceed
///    window distances), projected by PCA (fitted to up to 1024 of the keys) onto @c pcaDims
///    axes, and put in a nanoflann k-d tree. Output windows lie on a grid of spacing
///    max(1, round(w/4)) whose last row and column are moved in to end at the map's edge (the
///    output is not toroidal).
/// 5. E-step, for each output window: candidates are its previous match, the window its centre
///    pixel's remembered source implies, its four grid neighbours' matches shifted by their
///    offsets (coherence, Ashikhmin 2001), and the k-d tree's @c candidates nearest keys among
///    those no farther than the best candidate so far (none beyond can be better, by step 4).
///    The smallest full w x w x C squared distance wins (every channel, equal weight; the
///    previous match on a tie, then the lower index). Since the previous match is always a
///    candidate, the E-step never increases E although the search is approximate. E is
///    recorded here, for the current x and the new matches.
/// 6. Convergence: a stage stops when no window changed its match (after its first E-step) or
///    after @c maxIterations E-steps.
/// 7. M-step (IRLS, Kwatra §3.1): each output pixel becomes the weighted mean of the values the
///    matched windows covering it put there, weight |x_p - z_p|^(r-2) per window with the
///    distance clamped below at 1e-3 w sigma (sigma^2: the valid example pixels' total variance
///    over channels), so that an exact match does not take an infinite weight. With unclamped
///    weights this step cannot increase E (the quadratic it minimizes majorizes |.|^r for r <= 2).
///    Measured: E never rose within a stage by more than float rounding.
///
/// Values: every output value is a convex combination of valid example values (step 7, and
/// bilinear upsampling), so a value found only in invalid example pixels never appears.
///
/// Defaults and their sources: levels 3, widths {32, 16, 8} at the finest level, spacing w/4 and
/// r = 0.8 are Kwatra et al. 2005's (Wang et al. 2009, §6, use Kwatra's settings). Scaling the
/// widths down per level, the iteration cap and the search settings are ours; each field says
/// what was measured (100 x 100 x 16 smooth-noise maps into 100 x 100, 6 seeds, one thread, on a
/// shared 2-core machine; final energies within about 5 % of each other are within the spread
/// between seeds). With the defaults that case took 0.5 to 0.7 s of CPU on one thread there
/// (tests/synth/TestTextureOptimization.cc prints the time).
///
/// Results depend only on the inputs and the seed: every window and pixel is computed on its own
/// and sums run in a fixed order, so threaded and serial runs agree bit for bit.
#pragma once

#include <vdbhair/synth/FeatureImage.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <vector>

namespace vdbhair {

/// Where the initial patches of step 3 come from.
enum class TextureInit
{
    Anywhere,  ///< any wholly valid example window (Kwatra et al.): the output's layout is new
    Nearby     ///< the valid window nearest to the patch's own place moved by a random offset of at
               ///< most @c nearbyRadius: the example's large-scale layout is kept, its detail rearranged
};

struct TextureParams
{
    static constexpr int kMaxLevels = 8;
    static constexpr int kMaxNeighbourhood = 256;

    /// Resolution levels of the pyramid, 1 to kMaxLevels (Kwatra et al. 2005: 3).
    int levels = 3;
    /// Neighbourhood widths in pixels of the finest level, largest first (Kwatra et al. 2005:
    /// 32, 16, 8); level l uses w / 2^l (step 2 of the file comment).
    std::vector<int> neighbourhoodSizes = {32, 16, 8};
    /// Smallest width at a coarse level, and the smallest the example's valid region may force;
    /// 2 to 256 and at most every width above. Ours: 4 keeps width 8 at level 1 and 16 at level 2
    /// (4 pixels there; measured: 8 drops those two stages, saves no measurable time and ended
    /// 3 % higher in E).
    int minNeighbourhood = 4;
    /// Spacing of the output windows as a fraction of their width, in (0, 1] (Kwatra: w/4).
    double spacing = 0.25;
    /// E-steps per (level, width) at most. Ours: Kwatra gives no count; stages at the finest
    /// level still gain about 0.2 % of E per iteration at 10, and a cap of 6 ended 14 % higher.
    int maxIterations = 10;
    /// Robust exponent r of E = sum |x_p - z_p|^r, in (0, 2] (Kwatra: 0.8; 2 is least squares,
    /// which blends: 672 blended pixels against 24 at 0.8 in the two-region test).
    double robustExponent = 0.8;
    /// Dimensions of the PCA search key, 1 to 1024. Ours: 32 (16, 24 and 48 were no faster
    /// measurably and ended 2 to 5 % higher in E).
    int pcaDims = 32;
    /// A window's key has at most keyTaps x keyTaps cells, 1 to 64. Ours: 4, so a key has at
    /// most 16 C values (256 for 16 channels); 8 took about twice the time for no lower E.
    int keyTaps = 4;
    /// k-d tree neighbours compared by full window distance in each E-step, 1 to 256. Ours: 8
    /// (4 ended 2 % higher in E and was no faster measurably).
    int candidates = 8;
    /// nanoflann's approximation, at least 0: a k-d tree cell is skipped unless its squared key
    /// distance times (1 + searchEpsilon) is below the current k-th best. Ours: 4 (0, exact in
    /// key space, took about twice the time; 0, 1, 4 and 8 ended within 2 % of each other in E).
    double searchEpsilon = 4.0;
    TextureInit init = TextureInit::Anywhere;
    /// TextureInit::Nearby: the largest offset of a patch's source, as a fraction of the example's
    /// larger side (0.15: about a fifth of a head's width of hair on a whole-scalp map).
    double nearbyRadius = 0.15;
    /// Seed of the initial patches (step 3).
    std::uint64_t seed = 0;

    /// @throw ValueError naming the parameter, the value received and the rule, after @a where.
    void validate(const char* where) const;
};

/// @brief One (level, width) stage of a synthesis.
struct TextureStage
{
    int level = 0;       ///< 0 the finest
    int width = 0;       ///< window width in pixels of the level
    int spacing = 0;     ///< output window spacing in pixels of the level
    int firstIteration = 0;  ///< index of the stage's first entry in TextureStats::energy
    int iterations = 0;      ///< E-steps run
    bool converged = false;  ///< stopped because no match changed (else at maxIterations)
    double seconds = 0.0;    ///< wall time of the stage
};

struct TextureStats
{
    /// Kwatra's energy sum_p |x_p - z_p|^r after each E-step, all stages in order (values of
    /// different stages are not comparable: their windows differ).
    std::vector<double> energy;
    std::vector<TextureStage> stages;
    int iterations = 0;    ///< E-steps over all stages
    double seconds = 0.0;  ///< wall time of synthesizeTexture
};

/// @brief Synthesize a @a width x @a height map with the look of @a example (Kwatra et al. 2005;
/// see the file comment). Only example windows lying wholly in its valid pixels are sources.
/// @param example  any channel count (e.g. 16 PCA feature channels); every channel counts equally
///                 in distances. Values in invalid pixels are ignored (they may be non-finite).
/// @param width, height  output size in pixels, 1 to 16384 each
/// @return a map of example.channels channels, every pixel valid
/// @throw ValueError for bad parameters, an empty or malformed example, a non-finite valid
/// value, or an example with no wholly valid window of minNeighbourhood pixels; InterruptedError
/// when @a interrupter asks to stop (polled once per iteration).
FeatureImage synthesizeTexture(const FeatureImage& example, int width, int height, const TextureParams& params,
                               TextureStats* stats = nullptr, bool threaded = true,
                               openvdb::util::NullInterrupter* interrupter = nullptr);

} // namespace vdbhair
