#include "TextureOptimization.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Random.h>

#include <Eigen/Dense>
#include <nanoflann.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numeric>
#include <string>

namespace vdbhair {

void TextureParams::validate(const char* where) const
{
    auto fail = [&](const std::string& what) { throw ValueError(std::string(where) + ": " + what); };
    const std::string maxN = std::to_string(kMaxNeighbourhood);
    if (levels < 1 || levels > kMaxLevels) {
        fail("levels " + std::to_string(levels) + " must be between 1 and " + std::to_string(kMaxLevels));
    }
    if (minNeighbourhood < 2 || minNeighbourhood > kMaxNeighbourhood) {
        fail("minNeighbourhood " + std::to_string(minNeighbourhood) + " must be between 2 and " + maxN + " pixels");
    }
    if (neighbourhoodSizes.empty()) fail("neighbourhoodSizes is empty: give at least one width in pixels");
    for (std::size_t i = 0; i < neighbourhoodSizes.size(); ++i) {
        const int w = neighbourhoodSizes[i];
        if (w < minNeighbourhood || w > kMaxNeighbourhood) {
            fail("neighbourhoodSizes[" + std::to_string(i) + "] " + std::to_string(w) + " must be between minNeighbourhood " +
                 std::to_string(minNeighbourhood) + " and " + maxN + " pixels");
        }
    }
    if (!(spacing > 0.0 && spacing <= 1.0)) {
        fail("spacing " + formatNumber(spacing) + " must be in (0, 1] (a fraction of the neighbourhood width)");
    }
    if (maxIterations < 1 || maxIterations > 10000) {
        fail("maxIterations " + std::to_string(maxIterations) + " must be between 1 and 10000");
    }
    if (!(robustExponent > 0.0 && robustExponent <= 2.0)) {
        fail("robustExponent " + formatNumber(robustExponent) + " must be finite and in (0, 2] (Kwatra et al. use 0.8)");
    }
    if (pcaDims < 1 || pcaDims > 1024) fail("pcaDims " + std::to_string(pcaDims) + " must be between 1 and 1024");
    if (!(nearbyRadius >= 0.0 && nearbyRadius <= 1.0)) fail("nearbyRadius " + formatNumber(nearbyRadius) + ": must be between 0 and 1");
    if (keyTaps < 1 || keyTaps > 64) fail("keyTaps " + std::to_string(keyTaps) + " must be between 1 and 64");
    if (candidates < 1 || candidates > 256) fail("candidates " + std::to_string(candidates) + " must be between 1 and 256");
    if (!(searchEpsilon >= 0.0 && searchEpsilon <= 1e6)) fail("searchEpsilon " + formatNumber(searchEpsilon) + " must be finite and at least 0");
}

namespace {

constexpr const char* kWhere = "synthesizeTexture";
constexpr int kMaxOutputSide = 16384;
/// Window distances are clamped below at this fraction of w sigma in the IRLS weights (step 7).
constexpr double kMinDistanceFraction = 1e-3;
/// Rows of keys the PCA is computed from (evenly spread over the sources).
constexpr int kPcaSamples = 1024;
/// Key dimensions up to which the PCA diagonalizes the covariance directly; above, randomized
/// subspace iteration (Halko, Martinsson & Tropp 2011, Alg. 4.4) with this oversampling and
/// power iteration count.
constexpr int kDirectPcaDims = 256;
constexpr int kPcaOversampling = 8;
constexpr int kPcaPowerIterations = 2;

template<typename Fn>
void forRange(std::size_t n, std::size_t grain, bool threaded, const Fn& fn)
{
    if (n == 0) return;
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), fn);
    else fn(tbb::blocked_range<std::size_t>(0, n));
}

/// Half the size of @a fine (rounded up) by 2 x 2 box averages; a coarse pixel is valid only if
/// every fine pixel under it is (its value is then their mean; invalid pixels hold 0).
FeatureImage downsample(const FeatureImage& fine)
{
    const int C = fine.channels;
    FeatureImage coarse((fine.width + 1) / 2, (fine.height + 1) / 2, C);
    for (int y = 0; y < coarse.height; ++y) {
        for (int x = 0; x < coarse.width; ++x) {
            bool valid = true;
            int n = 0;
            float* dst = coarse.pixel(x, y);
            for (int fy = 2 * y; fy < std::min(2 * y + 2, fine.height); ++fy) {
                for (int fx = 2 * x; fx < std::min(2 * x + 2, fine.width); ++fx) {
                    valid = valid && fine.isValid(fx, fy);
                    const float* src = fine.pixel(fx, fy);
                    for (int c = 0; c < C; ++c) dst[c] += src[c];
                    ++n;
                }
            }
            coarse.valid[std::size_t(y) * coarse.width + x] = valid ? 1 : 0;
            for (int c = 0; c < C; ++c) dst[c] = valid ? dst[c] / float(n) : 0.0f;
        }
    }
    return coarse;
}

/// @a coarse resampled bilinearly (pixel centres aligned) to @a width x @a height.
FeatureImage upsample(const FeatureImage& coarse, int width, int height)
{
    const int C = coarse.channels;
    FeatureImage fine(width, height, C);
    auto axis = [](int i, double scale, int n, int& i0, int& i1, float& f) {
        const double t = std::clamp((i + 0.5) * scale - 0.5, 0.0, double(n - 1));
        i0 = std::min(int(t), n - 1);
        i1 = std::min(i0 + 1, n - 1);
        f = float(t - i0);
    };
    const double sx = double(coarse.width) / width, sy = double(coarse.height) / height;
    for (int y = 0; y < height; ++y) {
        int y0, y1;
        float fy;
        axis(y, sy, coarse.height, y0, y1, fy);
        for (int x = 0; x < width; ++x) {
            int x0, x1;
            float fx;
            axis(x, sx, coarse.width, x0, x1, fx);
            const float *a = coarse.pixel(x0, y0), *b = coarse.pixel(x1, y0), *c = coarse.pixel(x0, y1), *d = coarse.pixel(x1, y1);
            float* dst = fine.pixel(x, y);
            for (int k = 0; k < C; ++k) {
                dst[k] = (1.0f - fy) * ((1.0f - fx) * a[k] + fx * b[k]) + fy * ((1.0f - fx) * c[k] + fx * d[k]);
            }
        }
    }
    return fine;
}

/// Per-channel summed-area table: box sums of any rectangle in O(C).
struct Integral
{
    int width = 0, height = 0, channels = 0;
    std::vector<double> sum;  ///< (height+1) x (width+1) x channels

    explicit Integral(const FeatureImage& img) : width(img.width), height(img.height), channels(img.channels)
    {
        const std::size_t stride = std::size_t(width + 1) * channels;
        sum.assign(stride * (height + 1), 0.0);
        std::vector<double> row(stride, 0.0);
        for (int y = 0; y < height; ++y) {
            std::fill(row.begin(), row.end(), 0.0);
            for (int x = 0; x < width; ++x) {
                const float* p = img.pixel(x, y);
                for (int c = 0; c < channels; ++c) row[std::size_t(x + 1) * channels + c] = row[std::size_t(x) * channels + c] + p[c];
            }
            const double* above = &sum[std::size_t(y) * stride];
            double* here = &sum[std::size_t(y + 1) * stride];
            for (std::size_t i = 0; i < stride; ++i) here[i] = above[i] + row[i];
        }
    }
    const double* at(int x, int y) const { return &sum[(std::size_t(y) * (width + 1) + x) * channels]; }
};

/// Side of the largest square of valid pixels (dynamic programming over the mask).
int largestValidSquare(const FeatureImage& img)
{
    std::vector<int> prev(img.width + 1, 0), cur(img.width + 1, 0);
    int best = 0;
    for (int y = 0; y < img.height; ++y) {
        for (int x = 0; x < img.width; ++x) {
            cur[x + 1] = img.isValid(x, y) ? 1 + std::min({prev[x], prev[x + 1], cur[x]}) : 0;
            best = std::max(best, cur[x + 1]);
        }
        std::swap(prev, cur);
    }
    return best;
}

/// Window origins along an axis of @a n pixels: 0, s, 2s, ... and n - w (the last window ends at
/// the edge; the map is not toroidal).
std::vector<int> windowOrigins(int n, int w, int s)
{
    std::vector<int> o;
    for (int v = 0; v + w <= n; v += s) o.push_back(v);
    if (o.empty() || o.back() != n - w) o.push_back(n - w);
    return o;
}

/// For each pixel along an axis, the range [lo, hi) of windows (by origin index) covering it.
void coverage(const std::vector<int>& origins, int w, int n, std::vector<int>& lo, std::vector<int>& hi)
{
    lo.assign(n, 0);
    hi.assign(n, 0);
    int a = 0, b = 0;
    for (int v = 0; v < n; ++v) {
        while (a < int(origins.size()) && origins[a] + w <= v) ++a;
        while (b < int(origins.size()) && origins[b] <= v) ++b;
        lo[v] = a;
        hi[v] = b;
    }
}

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

    void compute(const Integral& I, int ox, int oy, float* out) const
    {
        for (int j = 0; j < taps; ++j) {
            const int y0 = oy + edges[j], y1 = oy + edges[j + 1];
            for (int i = 0; i < taps; ++i) {
                const int x0 = ox + edges[i], x1 = ox + edges[i + 1];
                const double norm = 1.0 / std::sqrt(double((y1 - y0) * (x1 - x0)));
                const double *a = I.at(x0, y0), *b = I.at(x1, y0), *c = I.at(x0, y1), *d = I.at(x1, y1);
                for (int k = 0; k < channels; ++k) *out++ = float((d[k] - b[k] - c[k] + a[k]) * norm);
            }
        }
    }
};

/// Orthonormal basis of the columns of @a m.
Eigen::MatrixXf orthonormalize(const Eigen::MatrixXf& m)
{
    Eigen::HouseholderQR<Eigen::MatrixXf> qr(m);
    return qr.householderQ() * Eigen::MatrixXf::Identity(m.rows(), m.cols());
}

/// Keys minus their mean, projected onto the leading principal axes.
struct Projection
{
    int inDim = 0, outDim = 0;
    std::vector<float> mean;   ///< inDim
    std::vector<float> basis;  ///< inDim x paddedDim, row-major; empty: no reduction (outDim == inDim)

    /// @a out = basis^T (key - mean); @a scratch holds inDim floats.
    void apply(const float* key, float* out, float* scratch) const
    {
        for (int d = 0; d < inDim; ++d) scratch[d] = key[d] - mean[d];
        if (basis.empty()) {
            std::copy_n(scratch, inDim, out);
            return;
        }
        // Blocks of 8 outputs, accumulated in registers over the key (the basis is padded to a
        // multiple of 8 columns).
        for (int j0 = 0; j0 < outDim; j0 += 8) {
            float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
            for (int d = 0; d < inDim; ++d) {
                const float v = scratch[d];
                const float* row = &basis[std::size_t(d) * paddedDim + j0];
                for (int k = 0; k < 8; ++k) acc[k] += v * row[k];
            }
            for (int k = 0; k < 8 && j0 + k < outDim; ++k) out[j0 + k] = acc[k];
        }
    }
    int paddedDim = 0;  ///< columns of basis: outDim rounded up to a multiple of 8
};

/// PCA of the rows of @a samples (keys): the @a dims leading axes.
Projection fitProjection(Eigen::MatrixXf samples, int dims)
{
    Projection p;
    p.inDim = int(samples.cols());
    const Eigen::RowVectorXf mean = samples.colwise().mean();
    p.mean.assign(mean.data(), mean.data() + p.inDim);
    if (dims >= p.inDim) {
        p.outDim = p.inDim;
        return p;
    }
    p.outDim = dims;
    samples.rowwise() -= mean;
    Eigen::MatrixXf axes;  // inDim x dims, leading first
    auto leading = [&](const Eigen::MatrixXf& vectors, const Eigen::VectorXf& /*ascending values*/) {
        axes = vectors.rightCols(dims).rowwise().reverse();
    };
    if (p.inDim <= kDirectPcaDims) {
        const Eigen::MatrixXf cov = samples.transpose() * samples;
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXf> eig(cov);
        leading(eig.eigenvectors(), eig.eigenvalues());
    } else {
        // Randomized subspace iteration, then Rayleigh-Ritz in the subspace found.
        const int l = std::min(dims + kPcaOversampling, p.inDim);
        Eigen::MatrixXf omega(p.inDim, l);
        Rng rng(0x7e47u, std::uint64_t(p.inDim), std::uint64_t(l));
        for (Eigen::Index i = 0; i < omega.size(); i += 2) {
            double a, b;
            rng.normalPair(a, b);
            omega.data()[i] = float(a);
            if (i + 1 < omega.size()) omega.data()[i + 1] = float(b);
        }
        Eigen::MatrixXf z = orthonormalize(omega);
        for (int q = 0; q < kPcaPowerIterations; ++q) z = orthonormalize(samples.transpose() * (samples * z));
        const Eigen::MatrixXf y = samples * z;
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXf> eig(y.transpose() * y);
        axes = z * eig.eigenvectors().rightCols(dims).rowwise().reverse();
    }
    p.paddedDim = (dims + 7) / 8 * 8;
    p.basis.assign(std::size_t(p.inDim) * p.paddedDim, 0.0f);
    for (int d = 0; d < p.inDim; ++d) {
        for (int j = 0; j < dims; ++j) p.basis[std::size_t(d) * p.paddedDim + j] = axes(d, j);
    }
    return p;
}

/// nanoflann's view of the projected keys (row-major, dim floats each).
struct KeyCloud
{
    const float* pts = nullptr;
    std::size_t count = 0;
    int dim = 0;
    std::size_t kdtree_get_point_count() const { return count; }
    float kdtree_get_pt(std::size_t i, std::size_t d) const { return pts[i * std::size_t(dim) + d]; }
    template<class BBoxT> bool kdtree_get_bbox(BBoxT&) const { return false; }
};
/// nanoflann result set: the k nearest points whose squared distance is below a bound (the
/// search prunes every cell beyond the bound from the start).
class BoundedKnn
{
public:
    BoundedKnn(std::size_t capacity, float bound, std::uint32_t* idx, float* dist)
        : mCapacity(capacity), mBound(bound), mIdx(idx), mDist(dist) {}
    std::size_t size() const { return mCount; }
    bool full() const { return mCount == mCapacity; }
    float worstDist() const { return mCount == mCapacity ? mDist[mCapacity - 1] : mBound; }
    bool addPoint(float dist, std::uint32_t index)
    {
        std::size_t i = mCount;
        for (; i > 0 && mDist[i - 1] > dist; --i) {
            if (i < mCapacity) {
                mDist[i] = mDist[i - 1];
                mIdx[i] = mIdx[i - 1];
            }
        }
        if (i < mCapacity) {
            mDist[i] = dist;
            mIdx[i] = index;
        }
        if (mCount < mCapacity) ++mCount;
        return true;
    }

private:
    std::size_t mCapacity, mCount = 0;
    float mBound;
    std::uint32_t* mIdx;
    float* mDist;
};

using KeyTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Adaptor<float, KeyCloud, float>, KeyCloud, -1, std::uint32_t>;

/// Squared distance between the w x w windows of @a a at (ax, ay) and @a b at (bx, by), every
/// channel; stops as soon as the sum exceeds @a bound (then returns a value above it).
double windowDistance2(const FeatureImage& a, int ax, int ay, const FeatureImage& b, int bx, int by, int w, double bound)
{
    const int n = w * a.channels;
    double total = 0.0;
    for (int r = 0; r < w; ++r) {
        const float* p = a.pixel(ax, ay + r);
        const float* q = b.pixel(bx, by + r);
        float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
        int i = 0;
        for (; i + 8 <= n; i += 8) {
            for (int k = 0; k < 8; ++k) {
                const float d = p[i + k] - q[i + k];
                acc[k] += d * d;
            }
        }
        float row = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
        for (; i < n; ++i) {
            const float d = p[i] - q[i];
            row += d * d;
        }
        total += double(row);
        if (total > bound) return total;
    }
    return total;
}

/// The example at one level of the pyramid.
struct ExampleLevel
{
    FeatureImage image;    ///< invalid pixels hold 0
    int largestSquare = 0;  ///< side of the largest square of valid pixels
};

/// Origins (y * width + x) of the windows of width @a w lying wholly in valid pixels, row-major.
std::vector<std::uint32_t> validWindows(const FeatureImage& img, int w)
{
    // Invalid-pixel counts by summed-area table.
    const int W = img.width, H = img.height;
    std::vector<int> s(std::size_t(W + 1) * (H + 1), 0);
    for (int y = 0; y < H; ++y) {
        int row = 0;
        for (int x = 0; x < W; ++x) {
            row += img.isValid(x, y) ? 0 : 1;
            s[std::size_t(y + 1) * (W + 1) + x + 1] = s[std::size_t(y) * (W + 1) + x + 1] + row;
        }
    }
    std::vector<std::uint32_t> out;
    for (int y = 0; y + w <= H; ++y) {
        for (int x = 0; x + w <= W; ++x) {
            const int bad = s[std::size_t(y + w) * (W + 1) + x + w] - s[std::size_t(y) * (W + 1) + x + w] -
                            s[std::size_t(y + w) * (W + 1) + x] + s[std::size_t(y) * (W + 1) + x];
            if (bad == 0) out.push_back(std::uint32_t(y) * std::uint32_t(W) + std::uint32_t(x));
        }
    }
    return out;
}

/// Everything one (level, width) stage needs about the example: sources, keys, the k-d tree.
class SourceIndex
{
public:
    SourceIndex(const FeatureImage& ex, int w, const TextureParams& params, bool threaded)
        : mLayout(w, params.keyTaps, ex.channels)
    {
        mOrigins = validWindows(ex, w);
        const std::size_t n = mOrigins.size();
        mWidth = ex.width;
        mHeight = ex.height;
        mSourceAt.assign(ex.pixelCount(), -1);
        for (std::size_t i = 0; i < n; ++i) mSourceAt[mOrigins[i]] = std::int64_t(i);
        const Integral integral(ex);
        const int D = mLayout.dim();

        // PCA of up to kPcaSamples keys, evenly spread over the sources.
        const std::size_t m = std::min<std::size_t>(n, kPcaSamples);
        Eigen::MatrixXf samples(Eigen::Index(m), D);
        {
            std::vector<float> key(D);
            for (std::size_t i = 0; i < m; ++i) {
                const std::uint32_t o = mOrigins[i * n / m];
                mLayout.compute(integral, int(o % std::uint32_t(ex.width)), int(o / std::uint32_t(ex.width)), key.data());
                for (int d = 0; d < D; ++d) samples(Eigen::Index(i), d) = key[d];
            }
        }
        mProjection = fitProjection(std::move(samples), params.pcaDims);
        const int k = mProjection.outDim;

        // Projected keys of all sources.
        std::vector<float> keys(n * std::size_t(k));
        forRange(n, 64, threaded, [&](const tbb::blocked_range<std::size_t>& r) {
            std::vector<float> key(D), scratch(D);
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const std::uint32_t o = mOrigins[i];
                mLayout.compute(integral, int(o % std::uint32_t(ex.width)), int(o / std::uint32_t(ex.width)), key.data());
                mProjection.apply(key.data(), &keys[i * k], scratch.data());
            }
        });

        // One tree point per distinct key (identical keys, e.g. in constant regions, would make
        // every search visit all of them); the first source of each key represents it.
        std::vector<std::uint32_t> order(n);
        std::iota(order.begin(), order.end(), 0u);
        auto keyOf = [&](std::uint32_t i) { return &keys[std::size_t(i) * k]; };
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            const int c = std::memcmp(keyOf(a), keyOf(b), sizeof(float) * k);
            return c != 0 ? c < 0 : a < b;
        });
        std::vector<std::uint32_t> reps;
        for (std::size_t i = 0; i < n; ++i) {
            if (i == 0 || std::memcmp(keyOf(order[i]), keyOf(order[i - 1]), sizeof(float) * k) != 0) reps.push_back(order[i]);
        }
        std::sort(reps.begin(), reps.end());
        mTreeSources = reps;
        mTreeKeys.resize(reps.size() * std::size_t(k));
        for (std::size_t i = 0; i < reps.size(); ++i) std::copy_n(keyOf(reps[i]), k, &mTreeKeys[i * k]);
        mCloud = KeyCloud{mTreeKeys.data(), reps.size(), k};
        mTree = std::make_unique<KeyTree>(k, mCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    }

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
    std::size_t nearest(const float* query, std::size_t k, float bound, float eps, std::uint32_t* idx, float* dist2) const
    {
        BoundedKnn result(k, bound, idx, dist2);
        mTree->findNeighbors(result, query, nanoflann::SearchParams(32, eps));
        const std::size_t found = result.size();
        for (std::size_t i = 0; i < found; ++i) idx[i] = mTreeSources[idx[i]];
        return found;
    }

private:
    KeyLayout mLayout;
    std::vector<std::uint32_t> mOrigins;
    Projection mProjection;
    std::vector<std::uint32_t> mTreeSources;
    std::vector<float> mTreeKeys;
    KeyCloud mCloud;
    std::unique_ptr<KeyTree> mTree;
    int mWidth = 0, mHeight = 0;
    std::vector<std::int64_t> mSourceAt;
};

void checkExample(const FeatureImage& ex)
{
    const std::string where = std::string(kWhere) + ": example";
    if (ex.width < 1 || ex.height < 1) {
        throw ValueError(where + " is " + std::to_string(ex.width) + " x " + std::to_string(ex.height) + " pixels: it must not be empty");
    }
    if (ex.channels < 1) throw ValueError(where + " has " + std::to_string(ex.channels) + " channels: it needs at least 1");
    const std::size_t pixels = ex.pixelCount();
    if (ex.data.size() != pixels * std::size_t(ex.channels)) {
        throw ValueError(where + " holds " + std::to_string(ex.data.size()) + " values but " + std::to_string(ex.width) + " x " +
                         std::to_string(ex.height) + " x " + std::to_string(ex.channels) + " channels need " +
                         std::to_string(pixels * std::size_t(ex.channels)));
    }
    if (!ex.valid.empty() && ex.valid.size() != pixels) {
        throw ValueError(where + " has a validity mask of " + std::to_string(ex.valid.size()) + " entries for " + std::to_string(pixels) +
                         " pixels");
    }
    for (int y = 0; y < ex.height; ++y) {
        for (int x = 0; x < ex.width; ++x) {
            if (!ex.isValid(x, y)) continue;
            const float* p = ex.pixel(x, y);
            for (int c = 0; c < ex.channels; ++c) {
                if (!std::isfinite(p[c])) {
                    throw ValueError(where + " pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") channel " + std::to_string(c) +
                                     " is " + formatNumber(p[c]) + ": valid pixels must be finite");
                }
            }
        }
    }
}

struct StagePlan
{
    int level = 0, width = 0;
};

} // namespace

FeatureImage synthesizeTexture(const FeatureImage& example, int width, int height, const TextureParams& params,
                               TextureStats* stats, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const auto start = std::chrono::steady_clock::now();
    params.validate(kWhere);
    if (width < 1 || height < 1 || width > kMaxOutputSide || height > kMaxOutputSide) {
        throw ValueError(std::string(kWhere) + ": output size " + std::to_string(width) + " x " + std::to_string(height) +
                         ": width and height must be between 1 and " + std::to_string(kMaxOutputSide) + " pixels");
    }
    checkExample(example);
    const int C = example.channels;
    const double r = params.robustExponent;

    // 1. Pyramids: the example (invalid pixels zeroed) and the output sizes, level 0 the finest.
    std::vector<ExampleLevel> ex(params.levels);
    std::vector<int> outW(params.levels), outH(params.levels);
    ex[0].image = FeatureImage(example.width, example.height, C);
    for (int y = 0; y < example.height; ++y) {
        for (int x = 0; x < example.width; ++x) {
            const bool valid = example.isValid(x, y);
            ex[0].image.valid[std::size_t(y) * example.width + x] = valid ? 1 : 0;
            if (valid) std::copy_n(example.pixel(x, y), C, ex[0].image.pixel(x, y));
        }
    }
    outW[0] = width;
    outH[0] = height;
    for (int l = 1; l < params.levels; ++l) {
        ex[l].image = downsample(ex[l - 1].image);
        outW[l] = (outW[l - 1] + 1) / 2;
        outH[l] = (outH[l - 1] + 1) / 2;
    }
    for (auto& e : ex) e.largestSquare = largestValidSquare(e.image);
    if (ex[0].largestSquare < params.minNeighbourhood) {
        const std::size_t validCount = example.valid.empty()
            ? example.pixelCount()
            : std::size_t(std::count_if(example.valid.begin(), example.valid.end(), [](std::uint8_t v) { return v != 0; }));
        throw ValueError(std::string(kWhere) + ": the example has no wholly valid " + std::to_string(params.minNeighbourhood) + " x " +
                         std::to_string(params.minNeighbourhood) + " neighbourhood (the smallest used): " + std::to_string(validCount) +
                         " of its " + std::to_string(example.width) + " x " + std::to_string(example.height) +
                         " pixels are valid, the largest valid square is " + std::to_string(ex[0].largestSquare) + " x " +
                         std::to_string(ex[0].largestSquare));
    }

    // The example's spread, for the IRLS distance floor: sigma^2 = total variance of valid pixels.
    double sigma = 0.0;
    {
        std::vector<double> mean(C, 0.0), sq(C, 0.0);
        std::size_t n = 0;
        const FeatureImage& e0 = ex[0].image;
        for (int y = 0; y < e0.height; ++y) {
            for (int x = 0; x < e0.width; ++x) {
                if (!e0.isValid(x, y)) continue;
                const float* p = e0.pixel(x, y);
                for (int c = 0; c < C; ++c) mean[c] += p[c];
                ++n;
            }
        }
        for (int c = 0; c < C; ++c) mean[c] /= double(n);
        for (int y = 0; y < e0.height; ++y) {
            for (int x = 0; x < e0.width; ++x) {
                if (!e0.isValid(x, y)) continue;
                const float* p = e0.pixel(x, y);
                for (int c = 0; c < C; ++c) sq[c] += (p[c] - mean[c]) * (p[c] - mean[c]);
            }
        }
        for (int c = 0; c < C; ++c) sigma += sq[c] / double(n);
        sigma = std::sqrt(sigma);
        if (!(sigma > 0.0)) sigma = 1.0;  // a constant example: every distance is 0, any floor works
    }

    // 2. Stages: widths per level, coarse to fine and large to small.
    std::vector<StagePlan> plan;
    for (int l = params.levels - 1; l >= 0; --l) {
        const int limit = std::min({ex[l].largestSquare, outW[l], outH[l]});
        if (l > 0 && limit < params.minNeighbourhood) continue;
        std::vector<int> widths;
        for (int s : params.neighbourhoodSizes) {
            int w = (s + (1 << l) / 2) >> l;
            if (l > 0 && w < params.minNeighbourhood) continue;
            w = std::min(w, limit);
            if (std::find(widths.begin(), widths.end(), w) == widths.end()) widths.push_back(w);
        }
        for (int w : widths) plan.push_back({l, w});
    }

    TextureStats localStats;
    TextureStats& st = stats ? *stats : localStats;
    st = TextureStats();
    ProgressCounter progress(interrupter, "synthesizing texture", std::uint64_t(plan.size()) * std::uint64_t(params.maxIterations),
                             "iterations");

    // 3. Initialization at the coarsest level used: random example patches of the first width.
    FeatureImage x;
    // For each output pixel, the example pixel (y * width + x at the current level) its value came
    // from: in the M-step, the one of the covering window of largest weight (first on a tie).
    std::vector<std::int64_t> from;
    {
        const int l = plan.front().level, w = plan.front().width;
        const FeatureImage& e = ex[l].image;
        const std::vector<std::uint32_t> sources = validWindows(e, w);
        x = FeatureImage(outW[l], outH[l], C);
        from.assign(x.pixelCount(), -1);
        const int bx = (x.width + w - 1) / w, by = (x.height + w - 1) / w;
        for (int j = 0; j < by; ++j) {
            for (int i = 0; i < bx; ++i) {
                Rng rng(params.seed, std::uint64_t(j) * bx + i, 0x7e47u);
                std::uint32_t o = sources[std::min(sources.size() - 1, std::size_t(rng.uniform() * double(sources.size())))];
                if (params.init == TextureInit::Nearby) {
                    // The patch's own place in the example, moved by a random offset; then the
                    // nearest valid window (first on a tie).
                    const double r = params.nearbyRadius * double(std::max(e.width, e.height));
                    const double tx = double(i * w) * double(e.width) / double(x.width) + (2.0 * rng.uniform() - 1.0) * r;
                    const double ty = double(j * w) * double(e.height) / double(x.height) + (2.0 * rng.uniform() - 1.0) * r;
                    double best = std::numeric_limits<double>::max();
                    for (std::uint32_t cand : sources) {
                        const double dx = double(cand % std::uint32_t(e.width)) - tx, dy = double(cand / std::uint32_t(e.width)) - ty;
                        if (dx * dx + dy * dy < best) {
                            best = dx * dx + dy * dy;
                            o = cand;
                        }
                    }
                }
                const int sx = int(o % std::uint32_t(e.width)), sy = int(o / std::uint32_t(e.width));
                for (int y = j * w; y < std::min((j + 1) * w, x.height); ++y) {
                    std::copy_n(e.pixel(sx, sy + y - j * w), std::size_t(std::min(w, x.width - i * w)) * C, x.pixel(i * w, y));
                    for (int px = i * w; px < std::min((i + 1) * w, x.width); ++px) {
                        from[std::size_t(y) * x.width + px] = std::int64_t(sy + y - j * w) * e.width + (sx + px - i * w);
                    }
                }
            }
        }
    }

    int currentLevel = plan.front().level;
    for (const StagePlan& stage : plan) {
        const int l = stage.level, w = stage.width;
        // Each later level starts from the coarser output, upsampled.
        while (currentLevel > l) {
            --currentLevel;
            x = upsample(x, outW[currentLevel], outH[currentLevel]);
            // Sources follow: the fine pixel under coarse source (sx, sy) is (2 sx, 2 sy) plus its
            // own parity.
            const int cw = outW[currentLevel + 1], ecw = ex[currentLevel + 1].image.width;
            const int efw = ex[currentLevel].image.width, efh = ex[currentLevel].image.height;
            std::vector<std::int64_t> fine(x.pixelCount(), -1);
            for (int y = 0; y < x.height; ++y) {
                for (int px = 0; px < x.width; ++px) {
                    const std::int64_t c = from[std::size_t(y / 2) * cw + px / 2];
                    if (c < 0) continue;
                    const int sx = std::min(int(c % ecw) * 2 + (px & 1), efw - 1), sy = std::min(int(c / ecw) * 2 + (y & 1), efh - 1);
                    fine[std::size_t(y) * x.width + px] = std::int64_t(sy) * efw + sx;
                }
            }
            from.swap(fine);
        }
        const FeatureImage& e = ex[l].image;

        // 4. Sources and output windows.
        const auto stageStart = std::chrono::steady_clock::now();
        const SourceIndex sources(e, w, params, threaded);
        const int s = std::max(1, int(std::lround(params.spacing * w)));
        const std::vector<int> ox = windowOrigins(x.width, w, s), oy = windowOrigins(x.height, w, s);
        const std::size_t nx = ox.size(), ny = oy.size(), q = nx * ny;
        std::vector<int> colLo, colHi, rowLo, rowHi;
        coverage(ox, w, x.width, colLo, colHi);
        coverage(oy, w, x.height, rowLo, rowHi);
        const int k = sources.projection().outDim, D = sources.layout().dim();
        const std::size_t cand = std::min<std::size_t>(std::size_t(params.candidates), sources.size());
        const double minDistance = kMinDistanceFraction * w * sigma;

        std::vector<std::int64_t> match(q, -1), next(q, -1);
        std::vector<double> dist2(q, 0.0), weight(q, 0.0);
        TextureStage record;
        record.level = l;
        record.width = w;
        record.spacing = s;
        record.firstIteration = int(st.energy.size());

        for (int it = 0; it < params.maxIterations; ++it) {
            if (progress.add(1)) throw InterruptedError(std::string(kWhere) + ": interrupted");

            // 5. E-step: candidates (previous match, coherent windows, k-d tree), ranked by full distance.
            const Integral integral(x);
            forRange(q, 16, threaded, [&](const tbb::blocked_range<std::size_t>& range) {
                std::vector<float> key(D), scratch(D), projected(k), d2(cand);
                std::vector<std::uint32_t> idx(cand);
                for (std::size_t i = range.begin(); i != range.end(); ++i) {
                    const int wx = ox[i % nx], wy = oy[i / nx];
                    sources.layout().compute(integral, wx, wy, key.data());
                    sources.projection().apply(key.data(), projected.data(), scratch.data());
                    const std::int64_t prev = match[i];
                    std::int64_t best = -1;
                    double bestD2 = std::numeric_limits<double>::infinity();
                    auto consider = [&](std::int64_t src) {
                        const std::uint32_t o = sources.origin(std::size_t(src));
                        const double d = windowDistance2(x, wx, wy, e, int(o % std::uint32_t(e.width)), int(o / std::uint32_t(e.width)), w, bestD2);
                        if (d < bestD2 || (d == bestD2 && best != prev && src < best)) {
                            best = src;
                            bestD2 = d;
                        }
                    };
                    // The previous match, the window the centre pixel's source implies, the grid
                    // neighbours' matches shifted by the neighbours' offsets (coherence, as
                    // Ashikhmin 2001 proposes), then the tree's candidates among keys no farther
                    // than the best so far (key distances never exceed window distances, so no
                    // source beyond is better; the bound has a 1e-5 margin for float rounding).
                    if (prev >= 0) consider(prev);
                    {
                        // The window placed where the source of its centre pixel says.
                        const std::int64_t c = from[std::size_t(wy + w / 2) * x.width + (wx + w / 2)];
                        if (c >= 0) {
                            const std::int64_t src = sources.sourceAt(int(c % e.width) - w / 2, int(c / e.width) - w / 2);
                            if (src >= 0 && src != best) consider(src);
                        }
                    }
                    const std::size_t ix = i % nx, iy = i / nx;
                    const std::size_t nbs[4] = {ix > 0 ? i - 1 : i, ix + 1 < nx ? i + 1 : i, iy > 0 ? i - nx : i, iy + 1 < ny ? i + nx : i};
                    for (std::size_t nb : nbs) {
                        if (nb == i || match[nb] < 0) continue;
                        const std::uint32_t o = sources.origin(std::size_t(match[nb]));
                        const std::int64_t src = sources.sourceAt(int(o % std::uint32_t(e.width)) + wx - ox[nb % nx],
                                                                   int(o / std::uint32_t(e.width)) + wy - oy[nb / nx]);
                        if (src >= 0 && src != best) consider(src);
                    }
                    const float bound = bestD2 < std::numeric_limits<double>::infinity() ? float(bestD2 * (1.0 + 1e-5))
                                                                                        : std::numeric_limits<float>::max();
                    const std::size_t found = sources.nearest(projected.data(), cand, bound, float(params.searchEpsilon), idx.data(), d2.data());
                    for (std::size_t c = 0; c < found; ++c) {
                        if (std::int64_t(idx[c]) != best) consider(idx[c]);
                    }
                    next[i] = best;
                    dist2[i] = bestD2;
                }
            });
            std::size_t changed = 0;
            double energy = 0.0;
            for (std::size_t i = 0; i < q; ++i) {
                changed += next[i] != match[i] ? 1 : 0;
                energy += std::pow(std::sqrt(dist2[i]), r);
            }
            match.swap(next);
            st.energy.push_back(energy);
            ++record.iterations;
            ++st.iterations;

            // 6. Convergence: no window changed its match.
            if (it > 0 && changed == 0) {
                record.converged = true;
                break;
            }

            // 7. M-step: each pixel is the IRLS-weighted mean of the matched windows covering it.
            for (std::size_t i = 0; i < q; ++i) weight[i] = std::pow(std::max(std::sqrt(dist2[i]), minDistance), r - 2.0);
            FeatureImage updated(x.width, x.height, C);
            forRange(std::size_t(x.height), 4, threaded, [&](const tbb::blocked_range<std::size_t>& range) {
                std::vector<double> acc(C);
                for (std::size_t yy = range.begin(); yy != range.end(); ++yy) {
                    const int y = int(yy);
                    for (int px = 0; px < x.width; ++px) {
                        std::fill(acc.begin(), acc.end(), 0.0);
                        double total = 0.0, top = -1.0;
                        std::int64_t topFrom = -1;
                        for (int j = rowLo[y]; j < rowHi[y]; ++j) {
                            for (int i = colLo[px]; i < colHi[px]; ++i) {
                                const std::size_t win = std::size_t(j) * nx + std::size_t(i);
                                const std::uint32_t o = sources.origin(std::size_t(match[win]));
                                const int fx = int(o % std::uint32_t(e.width)) + px - ox[i], fy = int(o / std::uint32_t(e.width)) + y - oy[j];
                                const float* z = e.pixel(fx, fy);
                                const double wt = weight[win];
                                for (int c = 0; c < C; ++c) acc[c] += wt * z[c];
                                total += wt;
                                if (wt > top) {
                                    top = wt;
                                    topFrom = std::int64_t(fy) * e.width + fx;
                                }
                            }
                        }
                        float* dst = updated.pixel(px, y);
                        for (int c = 0; c < C; ++c) dst[c] = float(acc[c] / total);
                        from[std::size_t(y) * x.width + px] = topFrom;
                    }
                }
            });
            x = std::move(updated);
        }
        // Unused iterations of a converged stage count as done for the progress display.
        if (record.iterations < params.maxIterations && progress.add(std::uint64_t(params.maxIterations - record.iterations))) {
            throw InterruptedError(std::string(kWhere) + ": interrupted");
        }
        record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - stageStart).count();
        st.stages.push_back(record);
    }
    progress.finish();
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return x;
}

} // namespace vdbhair
