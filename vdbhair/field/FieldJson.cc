#include "FieldJson.h"

#include <vdbhair/field/FieldTypes.h>
#include <vdbhair/field/ScalpMap.h>

#include <algorithm>

namespace vdbhair {

nlohmann::json fieldReport(std::size_t strands, const FieldParams& fp, int levels, const openvdb::GridCPtrVec& grids)
{
    nlohmann::json gridsJson = nlohmann::json::array();
    for (const openvdb::GridBase::ConstPtr& g : grids)
        gridsJson.push_back({{"name", g->getName()}, {"voxel_size", g->voxelSize().x()}, {"active_voxels", g->activeVoxelCount()}});
    nlohmann::json j = {{"strands", strands}, {"voxel_size", fp.voxelSize}, {"iterations", fp.iterations}, {"levels", levels},
                        {"space", fieldSpaceName(fp.space)}, {"grids", gridsJson}};
    if (fp.space == FieldSpace::Scalp) {
        const ScalpSphere& sphere = fp.scalpSphere();
        j["scalp"] = {{"center", {sphere.center.x(), sphere.center.y(), sphere.center.z()}}, {"radius", sphere.radius},
                      {"up", {sphere.up.x(), sphere.up.y(), sphere.up.z()}}};
        if (fp.scalpSurface) {
            // The measured scalp: d(u, v) in radii over the table, and the rays that missed it.
            const std::vector<float>& d = fp.scalpSurface->distances();
            j["scalp"]["resolution"] = fp.scalpSurface->resolution();
            j["scalp"]["distance_range"] = {*std::min_element(d.begin(), d.end()), *std::max_element(d.begin(), d.end())};
            j["scalp"]["misses"] = fp.scalpSurface->misses();
        }
    }
    return j;
}

nlohmann::json denseReport(const DenseBox& box, const std::vector<float>& volume)
{
    std::size_t occupied = 0;
    for (std::size_t i = 3; i < volume.size(); i += 4) occupied += volume[i] > 0.0f;
    return {{"shape", {box.size.z(), box.size.y(), box.size.x(), 4}},
            {"occupied", occupied},
            {"box", {box.worldMin.x(), box.worldMin.y(), box.worldMin.z(), box.worldMax.x(), box.worldMax.y(), box.worldMax.z()}}};
}

nlohmann::json retraceReport(const TraceStats& s, const TraceParams& tp, double step, double displacement,
                             const std::optional<TangentAngles>& angles)
{
    nlohmann::json j = {{"strands", s.strands},
                        {"full_length", s.fullLength},
                        {"stopped", {{"vanished", s.vanished}, {"left_field", s.leftField}, {"max_steps", s.maxSteps}}},
                        {"steps", s.steps},
                        {"mean_displacement", displacement},
                        {"step", step},
                        {"integrator", integratorName(tp.integrator)}};
    if (angles) {
        // null: no vertex lay inside the field (every strand left it), so there is no angle.
        auto angle = [](double deg, std::size_t counted) { return counted ? nlohmann::json(deg) : nlohmann::json(nullptr); };
        j["tangent_angle_deg"] = {{"before", angle(angles->beforeDeg, angles->countedBefore)},
                                  {"after", angle(angles->afterDeg, angles->countedAfter)}};
    }
    return j;
}

} // namespace vdbhair
