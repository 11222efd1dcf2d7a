#include "TextureSourceIndex.h"

#include <vdbhair/Parallel.h>
#include <vdbhair/Random.h>

#include <Eigen/Dense>
#include <tbb/blocked_range.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

namespace vdbhair {
namespace detail {

namespace {

/// Rows of keys the PCA is computed from (evenly spread over the sources).
constexpr int kPcaSamples = 1024;
/// Key dimensions up to which the PCA diagonalizes the covariance directly; above, randomized
/// subspace iteration (Halko, Martinsson & Tropp 2011, Alg. 4.4) with this oversampling and
/// power iteration count.
constexpr int kDirectPcaDims = 256;
constexpr int kPcaOversampling = 8;
constexpr int kPcaPowerIterations = 2;

/// Orthonormal basis of the columns of @a m.
Eigen::MatrixXf orthonormalize(const Eigen::MatrixXf& m)
{
    Eigen::HouseholderQR<Eigen::MatrixXf> qr(m);
    return qr.householderQ() * Eigen::MatrixXf::Identity(m.rows(), m.cols());
}

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

} // namespace

Integral::Integral(const FeatureImage& img) : width(img.width), height(img.height), channels(img.channels)
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

void KeyLayout::compute(const Integral& I, int ox, int oy, float* out) const
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

void Projection::apply(const float* key, float* out, float* scratch) const
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

SourceIndex::SourceIndex(const FeatureImage& ex, int w, const TextureParams& params, bool threaded)
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
    forEachRange(n, threaded, 64, [&](const tbb::blocked_range<std::size_t>& r) {
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
    mCloud = RowCloud{mTreeKeys.data(), reps.size(), k};
    mTree = std::make_unique<RowKdTree>(k, mCloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
}

std::size_t SourceIndex::nearest(const float* query, std::size_t k, float bound, float eps, std::uint32_t* idx, float* dist2) const
{
    BoundedKnn result(k, bound, idx, dist2);
    mTree->findNeighbors(result, query, nanoflann::SearchParams(32, eps));
    const std::size_t found = result.size();
    for (std::size_t i = 0; i < found; ++i) idx[i] = mTreeSources[idx[i]];
    return found;
}

} // namespace detail
} // namespace vdbhair
