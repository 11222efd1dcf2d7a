#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Random.h>
#include <vdbhair/synth/TextureOptimization.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

using namespace vdbhair;
using Catch::Matchers::Contains;

namespace {

/// Period P in x and y: channels sin and cos of 2 pi x / P and of 2 pi y / P, so every phase
/// (x mod P, y mod P) has its own value.
FeatureImage periodicMap(int w, int h, int period)
{
    FeatureImage img(w, h, 4);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const double ax = 2.0 * M_PI * x / period, ay = 2.0 * M_PI * y / period;
            float* p = img.pixel(x, y);
            p[0] = float(std::sin(ax));
            p[1] = float(std::cos(ax));
            p[2] = float(std::sin(ay));
            p[3] = float(std::cos(ay));
        }
    }
    return img;
}

/// Smooth random channels whose spread falls off as 0.8^c, like PCA features.
FeatureImage noiseMap(int w, int h, int channels, std::uint64_t seed)
{
    FeatureImage img(w, h, channels);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            Rng rng(seed, std::uint64_t(y) * w + x);
            for (int c = 0; c < channels; ++c) img.pixel(x, y)[c] = float(rng.uniform() - 0.5);
        }
    }
    // Two passes of a 5 x 5 box blur (clamped at the edges).
    for (int pass = 0; pass < 2; ++pass) {
        FeatureImage out(w, h, channels);
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                for (int dy = -2; dy <= 2; ++dy) {
                    for (int dx = -2; dx <= 2; ++dx) {
                        const float* s = img.pixel(std::clamp(x + dx, 0, w - 1), std::clamp(y + dy, 0, h - 1));
                        for (int c = 0; c < channels; ++c) out.pixel(x, y)[c] += s[c] / 25.0f;
                    }
                }
            }
        }
        img = std::move(out);
    }
    for (std::size_t i = 0; i < img.pixelCount(); ++i) {
        for (int c = 0; c < channels; ++c) img.data[i * channels + c] *= float(10.0 * std::pow(0.8, c));
    }
    return img;
}

/// Mean over pixels of the squared difference between @a img and itself shifted by (dx, dy).
double shiftedMsd(const FeatureImage& img, int dx, int dy)
{
    double sum = 0.0;
    std::size_t n = 0;
    for (int y = 0; y + dy < img.height; ++y) {
        for (int x = 0; x + dx < img.width; ++x) {
            const float *a = img.pixel(x, y), *b = img.pixel(x + dx, y + dy);
            for (int c = 0; c < img.channels; ++c) sum += double(a[c] - b[c]) * double(a[c] - b[c]);
            ++n;
        }
    }
    return sum / double(n);
}

/// Distance from pixel vector @a p to the nearest valid pixel vector of @a ex.
double distanceToExample(const float* p, const FeatureImage& ex)
{
    double best = std::numeric_limits<double>::infinity();
    for (int y = 0; y < ex.height; ++y) {
        for (int x = 0; x < ex.width; ++x) {
            if (!ex.isValid(x, y)) continue;
            double d = 0.0;
            for (int c = 0; c < ex.channels; ++c) d += double(p[c] - ex.pixel(x, y)[c]) * double(p[c] - ex.pixel(x, y)[c]);
            best = std::min(best, d);
        }
    }
    return std::sqrt(best);
}

bool allFinite(const FeatureImage& img)
{
    return std::all_of(img.data.begin(), img.data.end(), [](float v) { return std::isfinite(v); });
}

/// Says stop at its @a after-th poll.
class StopAfter : public openvdb::util::NullInterrupter
{
public:
    explicit StopAfter(int after) : mAfter(after) {}
    bool wasInterrupted(int = -1) override { return ++mPolls >= mAfter; }
    int polls() const { return mPolls; }

private:
    int mAfter, mPolls = 0;
};

} // namespace

TEST_CASE("synthesizeTexture: a periodic map keeps its period and only its own values", "[synth]")
{
    const int P = 8;
    const FeatureImage ex = periodicMap(48, 48, P);
    TextureParams tp;
    tp.seed = 5;
    TextureStats st;
    const FeatureImage out = synthesizeTexture(ex, 96, 80, tp, &st);
    REQUIRE(out.width == 96);
    REQUIRE(out.height == 80);
    REQUIRE(out.channels == 4);
    CHECK(std::all_of(out.valid.begin(), out.valid.end(), [](std::uint8_t v) { return v == 1; }));
    REQUIRE(allFinite(out));

    // Shifting by the period changes little, by half the period a lot (for a sinusoid of
    // amplitude 1 the half-period shift gives 4 x 0.5 = 2 per sinusoid and channel pair).
    const double fullX = shiftedMsd(out, P, 0), halfX = shiftedMsd(out, P / 2, 0);
    const double fullY = shiftedMsd(out, 0, P), halfY = shiftedMsd(out, 0, P / 2);
    double worst = 0.0, sumDist = 0.0;
    for (std::size_t i = 0; i < out.pixelCount(); ++i) {
        const double d = distanceToExample(&out.data[i * 4], ex);
        worst = std::max(worst, d);
        sumDist += d;
    }
    std::cout << "periodic: shift P msd (" << fullX << ", " << fullY << "), shift P/2 (" << halfX << ", " << halfY
              << "); distance to the nearest example value mean " << sumDist / double(out.pixelCount()) << ", max " << worst << "; "
              << st.iterations << " iterations in " << st.stages.size() << " stages, " << st.seconds << " s\n";
    CAPTURE(fullX, halfX, fullY, halfY, worst);
    CHECK(halfX > 1.0);
    CHECK(halfY > 1.0);
    CHECK(fullX < 0.05 * halfX);
    CHECK(fullY < 0.05 * halfY);
    CHECK(worst < 0.25);
}

TEST_CASE("synthesizeTexture: two constant regions give pixels of one or the other, not blends", "[synth]")
{
    const float a[3] = {1.0f, 0.0f, 0.5f}, b[3] = {0.0f, 1.0f, -0.5f};
    FeatureImage ex(64, 64, 3);
    for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) std::copy_n(x < 32 ? a : b, 3, ex.pixel(x, y));
    }
    auto classify = [&](const FeatureImage& out, std::size_t& nearA, std::size_t& nearB) {
        nearA = nearB = 0;
        for (std::size_t i = 0; i < out.pixelCount(); ++i) {
            double da = 0.0, db = 0.0;
            for (int c = 0; c < 3; ++c) {
                da += std::pow(out.data[i * 3 + c] - a[c], 2.0);
                db += std::pow(out.data[i * 3 + c] - b[c], 2.0);
            }
            // |a - b| = sqrt(3): within 5 % of it counts as that vector.
            nearA += std::sqrt(da) < 0.05 * std::sqrt(3.0) ? 1 : 0;
            nearB += std::sqrt(db) < 0.05 * std::sqrt(3.0) ? 1 : 0;
        }
    };
    TextureParams tp;
    tp.seed = 11;
    const FeatureImage out = synthesizeTexture(ex, 96, 96, tp);
    std::size_t nearA, nearB;
    classify(out, nearA, nearB);
    const double pure = double(nearA + nearB) / double(out.pixelCount());

    // Least squares (r = 2) for comparison: the robust exponent is what keeps edges sharp.
    TextureParams ls = tp;
    ls.robustExponent = 2.0;
    const FeatureImage outLs = synthesizeTexture(ex, 96, 96, ls);
    std::size_t lsA, lsB;
    classify(outLs, lsA, lsB);
    const double purels = double(lsA + lsB) / double(outLs.pixelCount());
    std::cout << "two regions: " << nearA << " pixels near a, " << nearB << " near b, " << out.pixelCount() - nearA - nearB
              << " blends (r = 2: " << outLs.pixelCount() - lsA - lsB << " blends)\n";
    CAPTURE(nearA, nearB, pure, purels);
    CHECK(pure > 0.95);
    CHECK(nearA > 0);
    CHECK(nearB > 0);
    CHECK(pure >= purels);
}

TEST_CASE("synthesizeTexture: values of invalid example pixels never appear", "[synth]")
{
    FeatureImage ex = noiseMap(64, 64, 3, 7);
    float maxValid = -std::numeric_limits<float>::infinity(), minValid = std::numeric_limits<float>::infinity();
    for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) {
            // A 20 x 20 hole in the middle and the last 6 columns are invalid, holding 100.
            const bool invalid = (x >= 22 && x < 42 && y >= 22 && y < 42) || x >= 58;
            if (invalid) {
                ex.valid[std::size_t(y) * 64 + x] = 0;
                std::fill_n(ex.pixel(x, y), 3, 100.0f);
            } else {
                for (int c = 0; c < 3; ++c) {
                    maxValid = std::max(maxValid, ex.pixel(x, y)[c]);
                    minValid = std::min(minValid, ex.pixel(x, y)[c]);
                }
            }
        }
    }
    // A NaN in an invalid pixel is ignored too.
    ex.pixel(30, 30)[1] = std::numeric_limits<float>::quiet_NaN();
    TextureParams tp;
    tp.seed = 2;
    const FeatureImage out = synthesizeTexture(ex, 80, 80, tp);
    REQUIRE(allFinite(out));
    const auto [lo, hi] = std::minmax_element(out.data.begin(), out.data.end());
    std::cout << "mask: valid example values in [" << minValid << ", " << maxValid << "], output in [" << *lo << ", " << *hi << "]\n";
    CHECK(*hi <= maxValid + 1e-4f);
    CHECK(*lo >= minValid - 1e-4f);
}

TEST_CASE("synthesizeTexture: an example without a valid neighbourhood is refused", "[synth]")
{
    // Valid pixels on a checkerboard: no two neighbours are both valid.
    FeatureImage ex = noiseMap(20, 20, 2, 1);
    for (int y = 0; y < 20; ++y) {
        for (int x = 0; x < 20; ++x) ex.valid[std::size_t(y) * 20 + x] = (x + y) % 2;
    }
    TextureParams tp;
    CHECK_THROWS_AS(synthesizeTexture(ex, 30, 30, tp), ValueError);
    CHECK_THROWS_WITH(synthesizeTexture(ex, 30, 30, tp),
                      Contains("no wholly valid 4 x 4 neighbourhood") && Contains("200 of its 20 x 20 pixels are valid"));
    // A 6 x 6 valid block is enough: the widths shrink to it.
    for (int y = 3; y < 9; ++y) {
        for (int x = 5; x < 11; ++x) ex.valid[std::size_t(y) * 20 + x] = 1;
    }
    TextureStats st;
    const FeatureImage out = synthesizeTexture(ex, 30, 30, tp, &st);
    CHECK(allFinite(out));
    for (const TextureStage& s : st.stages) {
        CAPTURE(s.level, s.width);
        CHECK(s.width <= 6 >> s.level);
    }
    CHECK(st.stages.back().level == 0);
}

TEST_CASE("synthesizeTexture: deterministic for a seed, serial and threaded alike", "[synth]")
{
    // 16 PCA channels of falling spread, 72 x 72 into 72 x 72 (the pipeline's maps are about 100 x 100;
    // this is enough for every stage to split its rows between threads).
    const FeatureImage ex = noiseMap(72, 72, 16, 3);
    TextureParams tp;
    tp.seed = 42;
    TextureStats serialStats, threadedStats;
    const FeatureImage serial = synthesizeTexture(ex, 72, 72, tp, &serialStats, false);
    const FeatureImage threaded = synthesizeTexture(ex, 72, 72, tp, &threadedStats, true);
    std::cout << "72 x 72 x 16 -> 72 x 72: " << serialStats.seconds << " s on one thread, " << threadedStats.seconds
              << " s threaded; " << serialStats.iterations << " iterations:";
    for (const TextureStage& s : serialStats.stages) {
        std::cout << " (level " << s.level << ", w " << s.width << ": " << s.iterations << " in " << s.seconds << " s)";
    }
    std::cout << "\n";
    REQUIRE(allFinite(serial));
    REQUIRE(serial.data.size() == threaded.data.size());
    CHECK(std::memcmp(serial.data.data(), threaded.data.data(), serial.data.size() * sizeof(float)) == 0);
    CHECK(serialStats.energy == threadedStats.energy);

    // Same seed, same map; another seed, another map (smaller, to keep the test short).
    const FeatureImage small = noiseMap(64, 64, 16, 4);
    const FeatureImage first = synthesizeTexture(small, 64, 64, tp);
    const FeatureImage again = synthesizeTexture(small, 64, 64, tp);
    tp.seed = 43;
    const FeatureImage other = synthesizeTexture(small, 64, 64, tp);
    CHECK(std::memcmp(first.data.data(), again.data.data(), first.data.size() * sizeof(float)) == 0);
    std::size_t differing = 0;
    for (std::size_t i = 0; i < other.data.size(); ++i) differing += other.data[i] != first.data[i] ? 1 : 0;
    CAPTURE(differing);
    CHECK(differing > other.data.size() / 2);
}

TEST_CASE("synthesizeTexture: the energy never rises within a stage", "[synth]")
{
    const FeatureImage ex = noiseMap(64, 64, 8, 9);
    TextureParams tp;
    tp.seed = 1;
    TextureStats st;
    synthesizeTexture(ex, 72, 72, tp, &st);
    REQUIRE(!st.stages.empty());
    REQUIRE(st.energy.size() == std::size_t(st.iterations));
    int total = 0;
    double worstRise = 0.0;
    for (const TextureStage& s : st.stages) {
        CAPTURE(s.level, s.width, s.iterations);
        REQUIRE(s.iterations >= 1);
        CHECK(s.firstIteration == total);
        total += s.iterations;
        std::cout << "energy, level " << s.level << ", w " << s.width << (s.converged ? " (converged)" : "") << ":";
        for (int i = 0; i < s.iterations; ++i) std::cout << " " << st.energy[std::size_t(s.firstIteration + i)];
        std::cout << "\n";
        for (int i = 1; i < s.iterations; ++i) {
            const double before = st.energy[std::size_t(s.firstIteration + i - 1)], after = st.energy[std::size_t(s.firstIteration + i)];
            worstRise = std::max(worstRise, (after - before) / before);
        }
        // Most of the decrease comes in the stage's first iterations.
        if (s.iterations >= 2) CHECK(st.energy[std::size_t(s.firstIteration + s.iterations - 1)] < st.energy[std::size_t(s.firstIteration)]);
    }
    CHECK(total == st.iterations);
    // Float rounding of the output and the IRLS distance floor allow a relative rise of ~1e-6.
    CHECK(worstRise <= 1e-5);
}

TEST_CASE("synthesizeTexture: thin outputs and the interrupter", "[synth]")
{
    const FeatureImage ex = noiseMap(40, 40, 4, 5);
    TextureParams tp;
    const FeatureImage thin = synthesizeTexture(ex, 3, 50, tp);
    CHECK(thin.width == 3);
    CHECK(thin.height == 50);
    CHECK(allFinite(thin));

    StopAfter stop(3);
    CHECK_THROWS_AS(synthesizeTexture(ex, 40, 40, tp, nullptr, true, &stop), InterruptedError);
    CHECK(stop.polls() == 3);
}

TEST_CASE("synthesizeTexture: bad parameters and inputs name what is wrong", "[synth]")
{
    const FeatureImage ex = noiseMap(24, 24, 2, 1);
    auto fails = [&](const TextureParams& tp, const std::string& text) {
        CAPTURE(text);
        CHECK_THROWS_AS(synthesizeTexture(ex, 30, 30, tp), ValueError);
        CHECK_THROWS_WITH(synthesizeTexture(ex, 30, 30, tp), Contains(text));
    };
    TextureParams tp;
    tp.robustExponent = std::numeric_limits<double>::quiet_NaN();
    fails(tp, "robustExponent nan must be finite and in (0, 2]");
    tp = TextureParams();
    tp.robustExponent = std::numeric_limits<double>::infinity();
    fails(tp, "robustExponent inf");
    tp = TextureParams();
    tp.neighbourhoodSizes = {16, 0};
    fails(tp, "neighbourhoodSizes[1] 0 must be between minNeighbourhood 4 and 256");
    tp.neighbourhoodSizes.clear();
    fails(tp, "neighbourhoodSizes is empty");
    tp = TextureParams();
    tp.levels = 0;
    fails(tp, "levels 0 must be between 1 and 8");
    tp = TextureParams();
    tp.spacing = 0.0;
    fails(tp, "spacing 0 must be in (0, 1]");
    tp = TextureParams();
    tp.maxIterations = 0;
    fails(tp, "maxIterations 0");
    tp = TextureParams();
    tp.pcaDims = 0;
    fails(tp, "pcaDims 0");

    tp = TextureParams();
    CHECK_THROWS_WITH(synthesizeTexture(ex, 0, 0, tp), Contains("synthesizeTexture: output size 0 x 0") && Contains("between 1 and"));
    CHECK_THROWS_AS(synthesizeTexture(ex, 10, -1, tp), ValueError);
    CHECK_THROWS_WITH(synthesizeTexture(FeatureImage(), 10, 10, tp), Contains("example is 0 x 0 pixels"));
    FeatureImage bad = ex;
    bad.data.pop_back();
    CHECK_THROWS_WITH(synthesizeTexture(bad, 10, 10, tp), Contains("example holds 1151 values"));
    bad = ex;
    bad.pixel(3, 4)[1] = std::numeric_limits<float>::infinity();
    CHECK_THROWS_WITH(synthesizeTexture(bad, 10, 10, tp), Contains("example pixel (3, 4) channel 1 is inf"));
}

