#include "../TestUtil.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>

using namespace vdbhair;

TEST_CASE("resampleStrands: equal arc-length spacing, root and tip kept", "[strands]")
{
    const StrandSet s = test::sampleStrands();
    const StrandSet r = resampleStrands(s, 9);
    REQUIRE(r.numStrands() == 3);
    REQUIRE(r.numVertices() == 27);
    REQUIRE_NOTHROW(r.validate("resample"));
    for (std::size_t i = 0; i < r.numStrands(); ++i) {
        REQUIRE(r.root(i) == s.root(i));
        REQUIRE((r.tip(i) - s.tip(i)).length() < 1e-5f);
        // Vertices lie on the input polyline at equal arc lengths: on the straight strand exactly.
    }
    for (std::size_t k = 0; k < 9; ++k) {
        const Vec3f expected = s.root(1) + Vec3f(float(k) / 8.f, 0.f, 0.f);
        REQUIRE((r.positions[r.begin(1) + k] - expected).length() < 1e-6f);
    }
    // Attributes are interpolated at the same arc lengths.
    REQUIRE(r.thickness.size() == 27);
    REQUIRE(r.thickness[r.begin(1)] == s.thickness[s.begin(1)]);
    REQUIRE(r.thickness[r.begin(1) + 4] == Approx(0.5f * (s.thickness[s.begin(1)] + s.thickness[s.begin(1) + 1])));
    REQUIRE_THROWS_AS(resampleStrands(s, 1), ValueError);
}

TEST_CASE("resampleStrands: a finely resampled circle keeps its length", "[strands]")
{
    StrandSet s;
    s.addStrand(test::circleArc(1.0, 2.0, 2000));
    const StrandSet r = resampleStrands(s, 101);
    std::vector<double> len(101);
    arcLengths(r.data(0), 101, len.data());
    for (std::size_t k = 1; k < 101; ++k) REQUIRE(len[k] - len[k - 1] == Approx(0.02).epsilon(1e-3));
}

TEST_CASE("resampleStrandsBySpacing: vertex count from the length", "[strands]")
{
    StrandSet s;
    s.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(10.f, 0.f, 0.f)});
    s.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(0.01f, 0.f, 0.f)});
    s.addStrand(std::vector<Vec3f>{Vec3f(0.f), Vec3f(0.f)});  // zero length
    const StrandSet r = resampleStrandsBySpacing(s, 0.5f);
    REQUIRE(r.size(0) == 21);
    REQUIRE(r.size(1) == 2);
    REQUIRE(r.size(2) == 2);
    REQUIRE(r.positions[r.begin(2) + 1] == Vec3f(0.f));
    REQUIRE_THROWS_AS(resampleStrandsBySpacing(s, 0.f), ValueError);
    REQUIRE_THROWS_AS(resampleStrandsBySpacing(s, 1e-9f, 1000), LimitError);
}
