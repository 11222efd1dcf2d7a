#include "RefineReport.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/tools/Morphology.h>
#include <openvdb/tree/ValueAccessor.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace vdbhair {

namespace {

using openvdb::Vec3d;

/// Runs fn(first, last, chunk) over fixed chunks of strands (the same chunks for any thread count).
template<typename Fn>
void forChunks(std::size_t n, std::size_t chunks, bool threaded, Fn&& fn)
{
    auto one = [&](std::size_t c) { fn(n * c / chunks, n * (c + 1) / chunks, c); };
    if (threaded) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t c = r.begin(); c != r.end(); ++c) one(c);
        });
    } else {
        for (std::size_t c = 0; c < chunks; ++c) one(c);
    }
}

double meanCurvature(const Vec3f* p, std::size_t n, std::vector<float>& scratch)
{
    if (n < 3) return 0.0;
    scratch.resize(n);
    curvatureProfile(p, n, scratch.data());
    double sum = 0.0;
    for (std::size_t i = 1; i + 1 < n; ++i) sum += double(scratch[i]);
    return sum / double(n - 2);
}

/// Every 8th vertex and the tip.
void coarsen(const Vec3f* p, std::size_t n, std::vector<Vec3f>& out)
{
    out.clear();
    for (std::size_t i = 0; i < n; i += 8) out.push_back(p[i]);
    if ((n - 1) % 8 != 0) out.push_back(p[n - 1]);
}

} // namespace

double meanCoherence(const TangentField& field)
{
    if (!field.coherence || !field.hairLength) return 0.0;
    double sum = 0.0, weight = 0.0;
    openvdb::FloatGrid::ConstAccessor dens = field.hairLength->getConstAccessor();
    for (auto it = field.coherence->cbeginValueOn(); it; ++it) {
        const double d = double(dens.getValue(it.getCoord()));
        sum += d * double(*it);
        weight += d;
    }
    return weight > 0.0 ? sum / weight : 0.0;
}

RefineMeasures measureRefinement(const StrandSet& input, const StrandSet& output, const TangentField& inputField,
                                 const FieldParams& params, const HeadObstacle& head, bool threaded)
{
    const std::size_t nS = input.numStrands();
    if (output.numStrands() != nS) {
        throw ValueError("measureRefinement: the output has " + std::to_string(output.numStrands()) +
                         " strands, the input " + std::to_string(nS));
    }
    RefineMeasures m;
    m.strands = nS;
    if (nS == 0) return m;
    const FieldMapping map = FieldMapping::fromGrid(*inputField.tangent);
    const double voxel = map.worldVoxelSize();

    const HairVolume volume(*inputField.tangent);
    // The tip voxels, dilated by one voxel (26 neighbours).
    openvdb::BoolTree tips(false);
    {
        openvdb::tree::ValueAccessor<openvdb::BoolTree> acc(tips);
        for (std::size_t i = 0; i < nS; ++i) {
            acc.setValueOn(openvdb::Coord::round(map.worldToIndex(Vec3d(input.tip(i)))));
        }
    }
    openvdb::tools::dilateActiveValues(tips, 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);

    const std::size_t chunks = std::max<std::size_t>(1, std::min<std::size_t>(64, nS / 64));
    struct Part
    {
        std::size_t left = 0, headBefore = 0, headAfter = 0, tipsIn = 0, full = 0, vertices = 0;
        double displacement = 0.0;
        std::vector<double> curvV, curvVIn, curv8, curv8In;
        std::vector<float> disp;  // a float a vertex: the largest array of the report (its 95th percentile only)
        std::vector<std::size_t> leftIds;
    };
    std::vector<Part> parts(chunks);
    forChunks(nS, chunks, threaded, [&](std::size_t first, std::size_t last, std::size_t c) {
        Part& part = parts[c];
        HairVolume::Probe vol(volume);
        openvdb::tree::ValueAccessor<const openvdb::BoolTree> tip(tips);
        HeadObstacle::Probe probe(head);
        std::vector<float> scratch;
        std::vector<Vec3f> coarse;
        for (std::size_t i = first; i < last; ++i) {
            const Vec3f* a = input.data(i);
            const Vec3f* b = output.data(i);
            const std::size_t na = input.size(i), nb = output.size(i);
            const bool left = !vol.containsPolyline(b, nb);
            part.left += left;
            if (left && part.leftIds.size() < 10) part.leftIds.push_back(i);
            if (!head.empty()) {
                for (std::size_t j = 0; j < na; ++j) part.headBefore += probe.distance(Vec3d(a[j])) < 0.0;
                for (std::size_t j = 0; j < nb; ++j) part.headAfter += probe.distance(Vec3d(b[j])) < 0.0;
            }
            part.tipsIn += tip.isValueOn(openvdb::Coord::round(map.worldToIndex(Vec3d(b[nb - 1]))));
            const double la = polylineLength(a, na), lb = polylineLength(b, nb);
            part.full += std::abs(lb - la) <= 1e-3 * la + 1e-6;
            // Curvature at two scales.
            part.curvVIn.push_back(meanCurvature(a, na, scratch));
            part.curvV.push_back(meanCurvature(b, nb, scratch));
            if (na >= 10 && nb >= 10) {
                coarsen(a, na, coarse);
                part.curv8In.push_back(meanCurvature(coarse.data(), coarse.size(), scratch));
                coarsen(b, nb, coarse);
                part.curv8.push_back(meanCurvature(coarse.data(), coarse.size(), scratch));
            }
            // Displacement, vertex by vertex.
            for (std::size_t j = 0; j < std::min(na, nb); ++j) {
                const double d = double((b[j] - a[j]).length()) / voxel;
                part.displacement += d;
                part.disp.push_back(float(d));
            }
            part.vertices += std::min(na, nb);
        }
    });

    std::size_t tipsIn = 0, vertices = 0;
    double displacement = 0.0;
    std::vector<double> curvV, curvVIn, curv8, curv8In;
    std::vector<float> disp;
    std::size_t dispCount = 0;
    for (const Part& p : parts) dispCount += p.disp.size();
    disp.reserve(dispCount);
    for (Part& p : parts) {  // in chunk order
        m.leftVolume += p.left;
        for (std::size_t id : p.leftIds) {
            if (m.leftExamples.size() < 10) m.leftExamples.push_back(id);
        }
        m.insideHeadBefore += p.headBefore;
        m.insideHeadAfter += p.headAfter;
        tipsIn += p.tipsIn;
        m.fullLength += p.full;
        vertices += p.vertices;
        displacement += p.displacement;
        curvV.insert(curvV.end(), p.curvV.begin(), p.curvV.end());
        curvVIn.insert(curvVIn.end(), p.curvVIn.begin(), p.curvVIn.end());
        curv8.insert(curv8.end(), p.curv8.begin(), p.curv8.end());
        curv8In.insert(curv8In.end(), p.curv8In.begin(), p.curv8In.end());
        disp.insert(disp.end(), p.disp.begin(), p.disp.end());
        std::vector<float>().swap(p.disp);  // one copy at a time
    }
    m.tipOccupancy = double(tipsIn) / double(nS);
    m.displacementMean = vertices ? displacement / double(vertices) : 0.0;
    if (!disp.empty()) m.displacementP95 = nearestRankQuantile(std::move(disp), 0.95);
    const double cvIn = median(std::move(curvVIn)), c8In = median(std::move(curv8In));
    m.curvatureKeptVertex = cvIn > 0.0 ? median(std::move(curvV)) / cvIn : 1.0;
    m.curvatureKept8 = c8In > 0.0 ? median(std::move(curv8)) / c8In : 1.0;

    // Coherence of each hairstyle's own field at this voxel size.
    m.coherenceBefore = meanCoherence(inputField);
    FieldParams fp = params;
    fp.maxVoxels = std::max(fp.maxVoxels, FieldParams().maxVoxels);  // a measure: never below the default cap
    m.coherenceAfter = meanCoherence(estimateTangentField(output, fp, threaded));
    return m;
}

} // namespace vdbhair
