#include "TangentAngles.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/FieldSampler.h>
#include <vdbhair/field/Simd.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/openvdb.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {

using openvdb::Vec3d;

namespace {

template<typename Fn>
void applyVec3(const openvdb::GridBase& field, const char* where, Fn&& fn)
{
    if (const auto* g = dynamic_cast<const openvdb::Vec3SGrid*>(&field)) return fn(*g);
    if (const auto* g = dynamic_cast<const openvdb::Vec3DGrid*>(&field)) return fn(*g);
    throw TypeError(std::string(where) + ": grid '" + field.getName() + "' holds " + field.valueType() +
                    " values; measuring angles needs a vector grid (vec3s or vec3d)");
}

} // namespace

namespace {

/// @brief Sums of the angles (radians) between strands' unit tangents and a field's direction, per
/// strand, over the vertices where the field is defined and does not vanish (the tracer's rule:
/// FieldDirectionSampler with threshold 1e-3). In float, through the bricks with scattered samples
/// (a strand's vertices lie about a voxel apart, so a cached cell rarely helps).
template<typename TreeT>
class AngleMeter
{
public:
    AngleMeter(const BrickedField<TreeT>& bricks, const FieldMapping& map) : mSampler(bricks), mMap(map) {}

    /// Angle sum and count over strand @a i of @a strands.
    void measure(const StrandSet& strands, std::size_t i, double& sum, std::size_t& count)
    {
        const std::size_t n = strands.size(i);
        mTangents.resize(n);
        computeTangents(strands.data(i), n, mTangents.data());
        const Vec3f* p = strands.data(i);
        mIndex.resize(n);
        mSamples.resize(n);
        for (std::size_t k = 0; k < n; ++k) mIndex[k] = mMap.worldToIndex(Vec3d(p[k]));
        mSampler.sampleScattered(mIndex.data(), n, mSamples.data());
        float strandSum = 0.f;  // at most a few thousand angles of at most pi: float holds them
        std::size_t strandCount = 0;
        for (std::size_t k = 0; k < n; ++k) {
            const Vec3f& t = mTangents[k];
            const Float4& r = mSamples[k];
            const float len2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            const float limit = kThreshold * r[3];
            // Outside the field (no active corner), vanishing there, or a point without tangent.
            if (!(r[3] > 0.f) || !(len2 > limit * limit) || t.lengthSqr() == 0.f) continue;
            const float c = (r[0] * t[0] + r[1] * t[1] + r[2] * t[2]) / std::sqrt(len2);
            strandSum += std::acos(std::max(-1.f, std::min(1.f, c)));
            ++strandCount;
        }
        sum = double(strandSum);
        count = strandCount;
    }

private:
    static constexpr float kThreshold = float(kDefaultVanishThreshold);  // the tracer's rule
    FieldSampler<TreeT> mSampler;
    const FieldMapping& mMap;
    std::vector<Vec3f> mTangents;
    std::vector<Vec3d> mIndex;
    std::vector<Float4> mSamples;
};

/// @brief The mean angle in degrees of each set in @a sets against @a field, through one set of
/// bricks; strand i of every set is measured in the same task (a retrace's output strand lies
/// where its input did, in bricks the input's strand just brought into the cache).
std::vector<double> meanAnglesDeg(const std::vector<const StrandSet*>& sets, const openvdb::GridBase& field,
                                  std::vector<std::size_t>& counted, bool threaded)
{
    const std::size_t nSets = sets.size();
    std::size_t nS = 0;
    for (const StrandSet* s : sets) nS = std::max(nS, s->numStrands());
    std::vector<double> sum(nS * nSets, 0.0);
    std::vector<std::size_t> count(nS * nSets, 0);
    applyVec3(field, "meanTangentAngleDeg", [&](const auto& grid) {
        using TreeT = typename std::decay_t<decltype(grid)>::TreeType;
        const FieldMapping map = FieldMapping::fromGrid(grid);
        const BrickedField<TreeT> bricks(grid.tree());
        // Strands in spatial order (by the first set's roots): neighbours share bricks, which
        // then come from the cache, where index order jumps across a field larger than the cache.
        // Each strand's sums land in its own slot, so the order changes no result.
        const std::vector<std::uint32_t> order = spatialOrder(*sets[0]);
        auto body = [&](const tbb::blocked_range<std::size_t>& r) {
            AngleMeter<TreeT> meter(bricks, map);
            for (std::size_t j = r.begin(); j != r.end(); ++j) {
                const std::size_t i = j < order.size() ? order[j] : j;  // strands only the other sets have: last
                // The spatial order scatters strands over memory: fetch a later one meanwhile.
                if (j + 2 < order.size()) {
                    const std::size_t later = order[j + 2];
                    for (const StrandSet* set : sets) {
                        if (later < set->numStrands()) prefetchBytes(set->data(later), set->size(later) * sizeof(Vec3f));
                    }
                }
                for (std::size_t s = 0; s < nSets; ++s) {
                    if (i < sets[s]->numStrands()) meter.measure(*sets[s], i, sum[i * nSets + s], count[i * nSets + s]);
                }
            }
        };
        if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nS, 64), body);
        else body(tbb::blocked_range<std::size_t>(0, nS));
    });
    std::vector<double> mean(nSets, 0.0);
    counted.assign(nSets, 0);
    for (std::size_t s = 0; s < nSets; ++s) {
        double total = 0.0;
        for (std::size_t i = 0; i < nS; ++i) { total += sum[i * nSets + s]; counted[s] += count[i * nSets + s]; }  // fixed order
        mean[s] = counted[s] ? total / double(counted[s]) * 180.0 / M_PI : 0.0;
    }
    return mean;
}

} // namespace

double meanTangentAngleDeg(const StrandSet& strands, const openvdb::GridBase& field, std::size_t* counted, bool threaded)
{
    std::vector<std::size_t> n;
    const double mean = meanAnglesDeg({&strands}, field, n, threaded)[0];
    if (counted) *counted = n[0];
    return mean;
}

TangentAngles meanTangentAnglesDeg(const StrandSet& before, const StrandSet& after, const openvdb::GridBase& field, bool threaded)
{
    std::vector<std::size_t> n;
    const std::vector<double> mean = meanAnglesDeg({&before, &after}, field, n, threaded);
    return {mean[0], mean[1], n[0], n[1]};
}

} // namespace vdbhair
