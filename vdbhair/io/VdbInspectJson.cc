#include "VdbInspectJson.h"

#include <variant>

namespace vdbhair {

namespace {

nlohmann::json vec3Json(const Vec3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json statsJson(const ValueStats& s)
{
    return {{"count", s.count}, {"min", s.min}, {"max", s.max}, {"mean", s.mean}, {"stddev", s.stddev},
            {"p01", s.p01}, {"median", s.p50}, {"p99", s.p99}};
}

} // namespace

nlohmann::json gridInfoJson(const GridInfo& g)
{
    nlohmann::json meta = nlohmann::json::object();
    for (const MetaValue& m : g.metadata) meta[m.name] = std::visit([](const auto& v) { return nlohmann::json(v); }, m.value);
    nlohmann::json j = {
        {"name", g.name},
        {"type", g.type},
        {"value_type", g.valueType},
        {"class", g.gridClass},
        {"vector_type", g.vectorType.empty() ? nlohmann::json(nullptr) : nlohmann::json(g.vectorType)},
        {"voxel_size", (g.voxelSize.x() == g.voxelSize.y() && g.voxelSize.x() == g.voxelSize.z())
                           ? nlohmann::json(g.voxelSize.x()) : vec3Json(g.voxelSize)},
        {"active_voxels", g.activeVoxels},
        {"active_tiles", g.activeTiles},
        {"leaf_nodes", g.leafNodes},
        {"memory_bytes", g.memoryBytes},
        {"bbox", g.emptyBBox ? nlohmann::json(nullptr) : nlohmann::json({vec3Json(g.bboxMin), vec3Json(g.bboxMax)})},
        {"metadata", meta}};
    if (g.isPoints) {
        nlohmann::json attrs = nlohmann::json::array();
        for (const PointAttributeInfo& a : g.attributes) attrs.push_back({{"name", a.name}, {"type", a.valueType}, {"codec", a.codec}});
        j["points"] = {{"count", g.pointCount}, {"attributes", attrs}, {"groups", g.groups}};
    }
    return j;
}

nlohmann::json gridReportJson(const GridReport& r)
{
    nlohmann::json j = gridInfoJson(r.info);
    j["index_bbox"] = r.emptyIndexBBox ? nlohmann::json(nullptr) : nlohmann::json({r.indexMin, r.indexMax});
    j["tiles_by_level"] = {{"root", r.tilesByLevel[0]}, {"upper", r.tilesByLevel[1]}, {"lower", r.tilesByLevel[2]}};
    j["internal_nodes"] = r.internalNodes;
    j["leaf_fill"] = {{"mean", r.leafFillMean}, {"min", r.leafFillMin}, {"max", r.leafFillMax}, {"full_share", r.leafFullShare}};
    if (r.isVector) {
        j["length"] = statsJson(r.values);
        j["unit_share"] = r.unitShare;
        j["zero_share"] = r.zeroShare;
        j["mean_vector"] = {r.meanVector.x(), r.meanVector.y(), r.meanVector.z()};
        j["coherence"] = r.coherence;
    } else if (r.isScalar) {
        j["values"] = statsJson(r.values);
        j["zero_share"] = r.zeroShare;
    } else if (r.info.isPoints) {
        j["points_per_voxel"] = statsJson(r.values);
    }
    j["explanation"] = r.explanation;
    return j;
}

} // namespace vdbhair
