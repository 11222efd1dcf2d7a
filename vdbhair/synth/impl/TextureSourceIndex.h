/// @file TextureSourceIndex.h
/// @brief The search structure of texture optimization (TextureOptimization.cc): the example's
/// windows of one width as keys (box means over a summed-area table), the keys' leading principal
/// axes, and a k-d tree over the distinct projected keys. Used by TextureOptimization.cc.
#pragma once

#include <vdbhair/strands/PointCloud.h>
#include <vdbhair/synth/FeatureImage.h>
#include <vdbhair/synth/TextureOptimization.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace vdbhair {
namespace detail {

/// Per-channel summed-area table: box sums of any rectangle in O(C).
struct Integral
{
    int width = 0, height = 0, channels = 0;
    std::vector<double> sum;  ///< (height+1) x (width+1) x channels

    explicit Integral(const FeatureImage& img);
    const double* at(int x, int y) const { return &sum[(std::size_t(y) * (width + 1) + x) * channels]; }
};

/// Origins (y * width + x) of the windows of width @a w lying wholly in valid pixels, row-major.
std::vector<std::uint32_t> validWindows(const FeatureImage& img, int w);

/// The search key of a window: its w x w x C values averaged over taps x taps cells, each cell's
/// mean times sqrt(its pixel count), so that key distances never exceed window distances.
struct KeyLayout
{
    int width = 0, taps = 0, channels = 0;
    std::vector<int> edges;  ///< taps + 1 cell boundaries along an axis, 0 to width

    KeyLayout(int w, int maxTaps, int c) : width(w), taps(std::min(w, maxTaps)), channels(c), edges(taps + 1)
    {
        for (int i = 0; i <= taps; ++i) edges[i] = int((std::int64_t(i) * w) / taps);
    }
    int dim() const { return taps * taps * channels; }

    /// The key of the window with its origin at (@a ox, @a oy): dim() floats into @a out.
    void compute(const Integral& I, int ox, int oy, float* out) const;
};

/// Keys minus their mean, projected onto the leading principal axes.
struct Projection
{
    int inDim = 0, outDim = 0;
    std::vector<float> mean;   ///< inDim
    std::vector<float> basis;  ///< inDim x paddedDim, row-major; empty: no reduction (outDim == inDim)

    /// @a out = basis^T (key - mean); @a scratch holds inDim floats.
    void apply(const float* key, float* out, float* scratch) const;
    int paddedDim = 0;  ///< columns of basis: outDim rounded up to a multiple of 8
};

/// Everything one (level, width) stage needs about the example: sources, keys, the k-d tree.
class SourceIndex
{
public:
    SourceIndex(const FeatureImage& ex, int w, const TextureParams& params, bool threaded);

    SourceIndex(const SourceIndex&) = delete;  // the tree refers to mCloud
    SourceIndex& operator=(const SourceIndex&) = delete;

    const KeyLayout& layout() const { return mLayout; }
    const Projection& projection() const { return mProjection; }
    std::size_t size() const { return mOrigins.size(); }
    std::uint32_t origin(std::size_t i) const { return mOrigins[i]; }
    /// The source whose window has its origin at example pixel (x, y), or -1 (none there).
    std::int64_t sourceAt(int x, int y) const
    {
        if (x < 0 || y < 0 || x >= mWidth || y >= mHeight) return -1;
        return mSourceAt[std::size_t(y) * mWidth + x];
    }
    /// Up to @a k sources whose projected keys are nearest @a query with squared key distance
    /// below @a bound (source indices, nearest first).
    std::size_t nearest(const float* query, std::size_t k, float bound, float eps, std::uint32_t* idx, float* dist2) const;

private:
    KeyLayout mLayout;
    std::vector<std::uint32_t> mOrigins;
    Projection mProjection;
    std::vector<std::uint32_t> mTreeSources;
    std::vector<float> mTreeKeys;
    RowCloud mCloud;  ///< the projected keys, row-major
    std::unique_ptr<RowKdTree> mTree;
    int mWidth = 0, mHeight = 0;
    std::vector<std::int64_t> mSourceAt;
};

} // namespace detail
} // namespace vdbhair
