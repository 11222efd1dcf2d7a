#include <vdbhair/Quantile.h>

#include <catch2/catch.hpp>

#include <vector>

using namespace vdbhair;

// Oracles: the sorted samples written out by hand, and NumPy's methods ("lower", "higher",
// "inverted_cdf") on the same numbers.

TEST_CASE("orderStatistic: the k-th smallest, ties counted, k past the end the largest", "[core]")
{
    const std::vector<double> v{3.0, 1.0, 2.0, 2.0, 5.0, 2.0};  // sorted: 1 2 2 2 3 5
    const double expected[6] = {1.0, 2.0, 2.0, 2.0, 3.0, 5.0};
    for (std::size_t k = 0; k < 6; ++k) CHECK(orderStatistic(v, k) == expected[k]);
    CHECK(orderStatistic(v, 99) == 5.0);
    CHECK(orderStatistic(std::vector<float>{}, 0) == 0.f);
    CHECK(v == std::vector<double>{3.0, 1.0, 2.0, 2.0, 5.0, 2.0});  // the caller's sample is left as it was
}

TEST_CASE("upperMedian: v[n / 2], a member of the sample (NumPy's \"higher\" at 0.5)", "[core]")
{
    CHECK(upperMedian(std::vector<double>{5.0, 1.0, 3.0}) == 3.0);
    CHECK(upperMedian(std::vector<double>{4.0, 1.0, 3.0, 2.0}) == 3.0);  // numpy.quantile([1,2,3,4], .5, method="higher")
    CHECK(upperMedian(std::vector<double>{3.0, 1.0, 2.0, 2.0, 5.0, 2.0}) == 2.0);
    CHECK(upperMedian(std::vector<float>{2.5f, -1.f}) == 2.5f);
    CHECK(upperMedian(std::vector<double>{}) == 0.0);
}

TEST_CASE("median: the middle value, or the mean of the two middle values", "[core]")
{
    CHECK(median(std::vector<double>{5.0, 1.0, 3.0}) == 3.0);
    CHECK(median(std::vector<double>{4.0, 1.0, 3.0, 2.0}) == 2.5);
    CHECK(median(std::vector<double>{2.0, 7.0, 1.0, 2.0}) == 2.0);  // sorted 1 2 2 7: a tie in the middle
    CHECK(median(std::vector<double>{0.1, 0.2}) == 0.5 * (0.2 + 0.1));
    CHECK(median(std::vector<double>{}) == 0.0);
}

TEST_CASE("lowerQuantile: the order statistic floor(q (n - 1)) (NumPy's \"lower\")", "[core]")
{
    const std::vector<double> v{10, 9, 8, 7, 6, 5, 4, 3, 2, 1};
    CHECK(lowerQuantile(v, 0.95) == 9.0);  // numpy.quantile(range(1, 11), .95, method="lower")
    CHECK(lowerQuantile(v, 0.05) == 1.0);
    CHECK(lowerQuantile(v, 0.0) == 1.0);
    CHECK(lowerQuantile(v, 1.0) == 10.0);
    CHECK(lowerQuantile(std::vector<float>{2.f, 2.f, 1.f}, 0.5) == 2.f);  // sorted 1 2 2: index 1
    CHECK(lowerQuantile(std::vector<double>{}, 0.5) == 0.0);
}

TEST_CASE("nearestRankQuantile: the order statistic ceil(q n) - 1 (NumPy's \"inverted_cdf\")", "[core]")
{
    std::vector<double> twenty;
    for (int i = 20; i >= 1; --i) twenty.push_back(double(i));
    CHECK(nearestRankQuantile(twenty, 0.95) == 19.0);  // numpy.quantile(range(1, 21), .95, method="inverted_cdf")
    CHECK(nearestRankQuantile(std::vector<double>{10, 9, 8, 7, 6, 5, 4, 3, 2, 1}, 0.95) == 10.0);
    CHECK(nearestRankQuantile(std::vector<double>{4, 3, 2, 1}, 0.5) == 2.0);
    const std::vector<double> ties{3.0, 1.0, 2.0, 2.0, 5.0, 2.0};  // sorted: 1 2 2 2 3 5
    CHECK(nearestRankQuantile(ties, 0.5) == 2.0);
    CHECK(nearestRankQuantile(ties, 0.7) == 3.0);
    CHECK(nearestRankQuantile(ties, 0.0) == 1.0);
    CHECK(nearestRankQuantile(ties, 1.0) == 5.0);
    CHECK(nearestRankQuantile(std::vector<float>{}, 0.9) == 0.f);
}
