#include "Refine.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/strands/Measures.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {

double suggestVoxelSize(const StrandSet& strands)
{
    if (strands.empty()) throw ValueError("suggestVoxelSize: the hairstyle has no strands");
    double total = 0.0;
    for (float len : strandLengths(strands)) total += len;
    const std::size_t segments = strands.numVertices() - strands.numStrands();
    const double meanSegment = segments ? total / double(segments) : 0.0;
    const BBox box = computeBBox(strands);
    const Vec3f e = box.extent();
    const double floorSize = double(std::max({e.x(), e.y(), e.z()})) / 2048.0;
    const double h = std::max(2.0 * meanSegment, floorSize);
    return h > 0.0 ? h : 1.0;
}

RefineResult refineStrands(const StrandSet& strands, const RefineParams& params, bool threaded,
                           openvdb::util::NullInterrupter* interrupter)
{
    if (params.levels < 1 || params.levels > 16) {
        throw ValueError("refineStrands: levels " + std::to_string(params.levels) + " must be between 1 and 16");
    }
    FieldParams fp = params.field;
    if (fp.voxelSize == 0.0) fp.voxelSize = suggestVoxelSize(strands);

    RefineResult result;
    result.voxelSize = fp.voxelSize;
    result.fields.resize(std::size_t(params.levels));
    StrandSet current;  // the last level's strands (the input's before the first level)
    for (int level = params.levels - 1; level >= 0; --level) {
        FieldParams lp = fp;
        lp.voxelSize = fp.voxelSize * double(1 << level);
        TangentField f = estimateTangentField(level == params.levels - 1 ? strands : current, lp, threaded, interrupter);
        f.tangent->setName(tangentGridName(level, params.levels));
        f.density->setName(densityGridName(level, params.levels));
        for (openvdb::GridBase* g : {static_cast<openvdb::GridBase*>(f.tangent.get()), static_cast<openvdb::GridBase*>(f.density.get())}) {
            g->insertMeta("vdbhair_level", openvdb::Int32Metadata(level));
            g->insertMeta("vdbhair_levels", openvdb::Int32Metadata(params.levels));
        }
        // Every level retraces the input strands' roots for the input's lengths and vertex
        // arc lengths, so that early stops at one level do not shorten the next. The last
        // level's strands are not needed once its field is estimated: their storage takes the
        // new ones (retraceStrandsInto).
        retraceStrandsInto(strands, *f.tangent, params.trace, current, &result.stats, nullptr, threaded, interrupter);
        result.fields[std::size_t(level)] = std::move(f);
    }
    result.strands = std::move(current);
    const openvdb::GridBase& finest = *result.fields[0].tangent;
    result.angleBefore = meanTangentAngleDeg(strands, finest, nullptr, threaded);
    result.angleAfter = meanTangentAngleDeg(result.strands, finest, nullptr, threaded);
    result.meanDisplacement = meanVertexDisplacement(strands, result.strands, threaded);
    return result;
}

} // namespace vdbhair
