#include "RefineJson.h"

#include <vdbhair/field/FieldTypes.h>

namespace vdbhair {

nlohmann::json toJson(const RefineMeasures& m)
{
    return {{"strands", m.strands},
            {"full_length", m.fullLength},
            {"left_hair_volume", m.leftVolume},
            {"left_hair_volume_examples", m.leftExamples},
            {"inside_head", {{"before", m.insideHeadBefore}, {"after", m.insideHeadAfter}}},
            {"curvature_kept", {{"vertex", m.curvatureKeptVertex}, {"segments8", m.curvatureKept8}}},
            {"tip_occupancy", m.tipOccupancy},
            {"displacement_voxels", {{"mean", m.displacementMean}, {"p95", m.displacementP95}}},
            {"coherence", {{"before", m.coherenceBefore}, {"after", m.coherenceAfter}}}};
}

nlohmann::json refineReport(const RefineResult& r, const RefineParams& rp)
{
    nlohmann::json j = rp.measure ? toJson(r.levels.front().measures) : nlohmann::json::object();
    j["strands"] = r.strands.numStrands();  // also without the measures (the scale benchmark reads it)
    j["mode"] = refineModeName(rp.mode);
    j["voxel_size"] = r.voxelSize;
    j["levels"] = rp.levels;
    j["iterations"] = rp.field.iterations;
    j["space"] = fieldSpaceName(rp.field.space);
    j["head"] = r.head.describe();
    nlohmann::json leaves = nlohmann::json::array();
    for (const FieldFootprint& f : r.memory.footprints) leaves.push_back(f.leaves);
    j["memory"] = {{"estimate_bytes", r.memory.bytes}, {"available_bytes", r.memory.available}, {"leaves", leaves}};
    nlohmann::json per = nlohmann::json::array();
    for (std::size_t l = 0; l < r.levels.size(); ++l) {
        const RefineLevel& lv = r.levels[l];
        nlohmann::json e = rp.measure ? toJson(lv.measures) : nlohmann::json::object();
        e["level"] = l;
        e["voxel_size"] = lv.voxelSize;
        if (rp.mode == RefineMode::Consistent) {
            e["corrected_strands"] = lv.consistency.corrected;
            e["field_steps"] = lv.consistency.fieldSteps;
            e["no_field_steps"] = lv.consistency.noFieldSteps;
            e["steps"] = lv.consistency.steps;
            e["pushed_out_of_head"] = lv.consistency.pushedOut;
            e["held_in_hair_steps"] = lv.consistency.heldIn;
            e["reverted_strands"] = lv.consistency.reverted;
        } else {
            e["stopped"] = {{"vanished", lv.trace.vanished}, {"left_field", lv.trace.leftField}, {"max_steps", lv.trace.maxSteps}};
        }
        per.push_back(e);
    }
    j["per_level"] = per;
    if (rp.mode == RefineMode::Consistent) j["corrected_strands"] = r.levels.front().consistency.corrected;
    return j;
}

} // namespace vdbhair
