#include "TextureOptimization.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Random.h>
#include <vdbhair/synth/impl/TextureSourceIndex.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
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

/// One synthesizeTexture() call: the pyramids, the stages, and the output being synthesized.
struct TextureRun
{
    TextureRun(const TextureParams& p, bool runThreaded, int channels) : params(p), threaded(runThreaded), C(channels), r(p.robustExponent) {}

    const TextureParams& params;
    const bool threaded;
    const int C;     ///< channels
    const double r;  ///< the robust exponent
    std::vector<ExampleLevel> ex;   ///< the example's pyramid, level 0 the finest
    std::vector<int> outW, outH;    ///< the output's size at each level
    double sigma = 0.0;             ///< the example's spread (exampleSpread())
    std::vector<StagePlan> plan;
    FeatureImage x;                 ///< the output at the current level
    /// For each output pixel, the example pixel (y * width + x at the current level) its value came
    /// from: in the M-step, the one of the covering window of largest weight (first on a tie).
    std::vector<std::int64_t> from;
    int currentLevel = 0;
};

/// Step 1, pyramids: the example (invalid pixels zeroed) and the output sizes, level 0 the finest.
void buildPyramids(TextureRun& t, const FeatureImage& example, int width, int height)
{
    const TextureParams& params = t.params;
    const int C = t.C;
    std::vector<ExampleLevel>& ex = t.ex;
    std::vector<int>&outW = t.outW, &outH = t.outH;
    ex.resize(params.levels);
    outW.resize(params.levels);
    outH.resize(params.levels);
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
}

/// The example's spread, for the IRLS distance floor: sigma^2 = total variance of the valid pixels
/// of @a e0 (1 for a constant example: every distance is 0, any floor works).
double exampleSpread(const FeatureImage& e0, int C)
{
    double sigma = 0.0;
    std::vector<double> mean(C, 0.0), sq(C, 0.0);
    std::size_t n = 0;
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
    if (!(sigma > 0.0)) sigma = 1.0;
    return sigma;
}

/// Step 2, stages: widths per level, coarse to fine and large to small.
std::vector<StagePlan> planStages(const TextureRun& t)
{
    const TextureParams& params = t.params;
    std::vector<StagePlan> plan;
    for (int l = params.levels - 1; l >= 0; --l) {
        const int limit = std::min({t.ex[l].largestSquare, t.outW[l], t.outH[l]});
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
    return plan;
}

/// Step 3, initialization at the coarsest level used: random example patches of the first width.
void initializeOutput(TextureRun& t)
{
    const TextureParams& params = t.params;
    FeatureImage& x = t.x;
    std::vector<std::int64_t>& from = t.from;
    const int C = t.C;
    const int l = t.plan.front().level, w = t.plan.front().width;
    const FeatureImage& e = t.ex[l].image;
    const std::vector<std::uint32_t> sources = detail::validWindows(e, w);
    x = FeatureImage(t.outW[l], t.outH[l], C);
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
    t.currentLevel = l;
}

/// The output, and the sources of its pixels, upsampled to level @a l (each later level starts
/// from the coarser output).
void upsampleTo(TextureRun& t, int l)
{
    FeatureImage& x = t.x;
    std::vector<std::int64_t>& from = t.from;
    int& currentLevel = t.currentLevel;
    while (currentLevel > l) {
        --currentLevel;
        x = upsample(x, t.outW[currentLevel], t.outH[currentLevel]);
        // Sources follow: the fine pixel under coarse source (sx, sy) is (2 sx, 2 sy) plus its
        // own parity.
        const int cw = t.outW[currentLevel + 1], ecw = t.ex[currentLevel + 1].image.width;
        const int efw = t.ex[currentLevel].image.width, efh = t.ex[currentLevel].image.height;
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
}

/// Step 4, one stage's sources and output windows, and the windows' matches.
struct Stage
{
    Stage(const TextureRun& t, int level, int width)
        : l(level), w(width), e(t.ex[level].image), sources(e, w, t.params, t.threaded), s(std::max(1, int(std::lround(t.params.spacing * w)))),
          ox(windowOrigins(t.x.width, w, s)), oy(windowOrigins(t.x.height, w, s)), nx(ox.size()), ny(oy.size()), q(nx * ny),
          k(sources.projection().outDim), D(sources.layout().dim()), cand(std::min<std::size_t>(std::size_t(t.params.candidates), sources.size())),
          minDistance(kMinDistanceFraction * w * t.sigma), match(q, -1), next(q, -1), dist2(q, 0.0), weight(q, 0.0)
    {
        coverage(ox, w, t.x.width, colLo, colHi);
        coverage(oy, w, t.x.height, rowLo, rowHi);
    }

    const int l, w;          ///< level; window width
    const FeatureImage& e;   ///< the example at this level
    const detail::SourceIndex sources;
    const int s;             ///< spacing of the output windows
    const std::vector<int> ox, oy;  ///< the output windows' origins along x and y
    const std::size_t nx, ny, q;    ///< windows along x, along y, in all
    std::vector<int> colLo, colHi, rowLo, rowHi;  ///< the windows covering each column and row (coverage())
    const int k, D;          ///< projected and full key dimensions
    const std::size_t cand;  ///< tree candidates per window
    const double minDistance;
    std::vector<std::int64_t> match, next;  ///< each window's source, and this iteration's
    std::vector<double> dist2, weight;
};

/// Step 5, the E-step: each window's best source among candidates (the previous match, coherent
/// windows, the k-d tree), ranked by full distance, into Stage::next and Stage::dist2.
void matchWindows(const TextureRun& t, Stage& g)
{
    const FeatureImage& x = t.x;
    const FeatureImage& e = g.e;
    const detail::SourceIndex& sources = g.sources;
    const std::vector<int>&ox = g.ox, &oy = g.oy;
    const std::size_t nx = g.nx, ny = g.ny, cand = g.cand;
    const int w = g.w, k = g.k, D = g.D;
    const detail::Integral integral(x);
    forRange(g.q, 16, t.threaded, [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<float> key(D), scratch(D), projected(k), d2(cand);
        std::vector<std::uint32_t> idx(cand);
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const int wx = ox[i % nx], wy = oy[i / nx];
            sources.layout().compute(integral, wx, wy, key.data());
            sources.projection().apply(key.data(), projected.data(), scratch.data());
            const std::int64_t prev = g.match[i];
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
                const std::int64_t c = t.from[std::size_t(wy + w / 2) * x.width + (wx + w / 2)];
                if (c >= 0) {
                    const std::int64_t src = sources.sourceAt(int(c % e.width) - w / 2, int(c / e.width) - w / 2);
                    if (src >= 0 && src != best) consider(src);
                }
            }
            const std::size_t ix = i % nx, iy = i / nx;
            const std::size_t nbs[4] = {ix > 0 ? i - 1 : i, ix + 1 < nx ? i + 1 : i, iy > 0 ? i - nx : i, iy + 1 < ny ? i + nx : i};
            for (std::size_t nb : nbs) {
                if (nb == i || g.match[nb] < 0) continue;
                const std::uint32_t o = sources.origin(std::size_t(g.match[nb]));
                const std::int64_t src = sources.sourceAt(int(o % std::uint32_t(e.width)) + wx - ox[nb % nx],
                                                           int(o / std::uint32_t(e.width)) + wy - oy[nb / nx]);
                if (src >= 0 && src != best) consider(src);
            }
            const float bound = bestD2 < std::numeric_limits<double>::infinity() ? float(bestD2 * (1.0 + 1e-5))
                                                                                : std::numeric_limits<float>::max();
            const std::size_t found = sources.nearest(projected.data(), cand, bound, float(t.params.searchEpsilon), idx.data(), d2.data());
            for (std::size_t c = 0; c < found; ++c) {
                if (std::int64_t(idx[c]) != best) consider(idx[c]);
            }
            g.next[i] = best;
            g.dist2[i] = bestD2;
        }
    });
}

/// Step 7, the M-step: each pixel is the IRLS-weighted mean of the matched windows covering it;
/// the output's pixel sources become those of the covering window of largest weight.
FeatureImage blendWindows(TextureRun& t, Stage& g)
{
    const FeatureImage& x = t.x;
    const FeatureImage& e = g.e;
    const int C = t.C;
    const std::size_t nx = g.nx;
    for (std::size_t i = 0; i < g.q; ++i) g.weight[i] = std::pow(std::max(std::sqrt(g.dist2[i]), g.minDistance), t.r - 2.0);
    FeatureImage updated(x.width, x.height, C);
    forRange(std::size_t(x.height), 4, t.threaded, [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<double> acc(C);
        for (std::size_t yy = range.begin(); yy != range.end(); ++yy) {
            const int y = int(yy);
            for (int px = 0; px < x.width; ++px) {
                std::fill(acc.begin(), acc.end(), 0.0);
                double total = 0.0, top = -1.0;
                std::int64_t topFrom = -1;
                for (int j = g.rowLo[y]; j < g.rowHi[y]; ++j) {
                    for (int i = g.colLo[px]; i < g.colHi[px]; ++i) {
                        const std::size_t win = std::size_t(j) * nx + std::size_t(i);
                        const std::uint32_t o = g.sources.origin(std::size_t(g.match[win]));
                        const int fx = int(o % std::uint32_t(e.width)) + px - g.ox[i], fy = int(o / std::uint32_t(e.width)) + y - g.oy[j];
                        const float* z = e.pixel(fx, fy);
                        const double wt = g.weight[win];
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
                t.from[std::size_t(y) * x.width + px] = topFrom;
            }
        }
    });
    return updated;
}

/// Steps 4-7 for one stage: E- and M-steps until no window changes its match or maxIterations.
TextureStage runStage(TextureRun& t, const StagePlan& stage, TextureStats& st, ProgressCounter& progress)
{
    const TextureParams& params = t.params;
    const auto stageStart = std::chrono::steady_clock::now();
    Stage g(t, stage.level, stage.width);
    TextureStage record;
    record.level = g.l;
    record.width = g.w;
    record.spacing = g.s;
    record.firstIteration = int(st.energy.size());

    for (int it = 0; it < params.maxIterations; ++it) {
        if (progress.add(1)) throw InterruptedError(std::string(kWhere) + ": interrupted");

        matchWindows(t, g);
        std::size_t changed = 0;
        double energy = 0.0;
        for (std::size_t i = 0; i < g.q; ++i) {
            changed += g.next[i] != g.match[i] ? 1 : 0;
            energy += std::pow(std::sqrt(g.dist2[i]), t.r);
        }
        g.match.swap(g.next);
        st.energy.push_back(energy);
        ++record.iterations;
        ++st.iterations;

        // 6. Convergence: no window changed its match.
        if (it > 0 && changed == 0) {
            record.converged = true;
            break;
        }

        t.x = blendWindows(t, g);
    }
    // Unused iterations of a converged stage count as done for the progress display.
    if (record.iterations < params.maxIterations && progress.add(std::uint64_t(params.maxIterations - record.iterations))) {
        throw InterruptedError(std::string(kWhere) + ": interrupted");
    }
    record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - stageStart).count();
    return record;
}
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
    TextureRun t(params, threaded, example.channels);
    buildPyramids(t, example, width, height);
    t.sigma = exampleSpread(t.ex[0].image, t.C);
    t.plan = planStages(t);

    TextureStats localStats;
    TextureStats& st = stats ? *stats : localStats;
    st = TextureStats();
    ProgressCounter progress(interrupter, "synthesizing texture", std::uint64_t(t.plan.size()) * std::uint64_t(params.maxIterations),
                             "iterations");
    initializeOutput(t);
    for (const StagePlan& stage : t.plan) {
        upsampleTo(t, stage.level);
        st.stages.push_back(runStage(t, stage, st, progress));
    }
    progress.finish();
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return std::move(t.x);
}

} // namespace vdbhair
