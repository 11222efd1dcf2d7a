#include "ScalpJson.h"

namespace vdbhair {

nlohmann::json scalpReport(const openvdb::FloatGrid& surface, double halfWidth, const ScalpArea& areas, const ScalpFileReport* file,
                           const openvdb::BoolGrid* region, const ScalpRegionSource& source)
{
    nlohmann::json j = {{"kind", file ? file->kind : std::string("sphere")},
                        {"voxel_size", surface.voxelSize().x()},
                        {"half_width", halfWidth},
                        {"active_voxels", surface.activeVoxelCount()},
                        {"area", areas.area},
                        {"area_without_zero", areas.areaWithoutZero}};
    if (file && file->kind == "mesh") {
        j.update({{"triangles", file->triangles}, {"welded_vertices", file->mesh.weldedVertices},
                  {"boundary_edges", file->mesh.boundaryEdges}, {"capped_loops", file->mesh.cappedLoops},
                  {"open_edges", file->mesh.openEdges}, {"non_manifold_edges", file->mesh.nonManifoldEdges}});
    } else if (file) {
        j.update({{"points", file->points}, {"constraints", file->constraints}});
    }
    if (region) {
        using Kind = ScalpRegionSource::Kind;
        nlohmann::json r = {{"active_voxels", region->activeVoxelCount()}};
        if (source.kind == Kind::Roots) r.update({{"roots", source.roots}, {"radius", source.radius}});
        else r.update({{source.kind == Kind::Vertex ? "vertex" : "mask", source.name}, {"threshold", source.threshold}});
        j["region"] = r;
    }
    return j;
}

nlohmann::json rootsReport(const Follicles& f, const FollicleStats& stats, bool region)
{
    return {{"count", f.positions.size()},
            {"region", region},
            {"area", f.area},
            {"area_without_zero", f.areaWithoutZero},
            {"target_spacing", f.targetSpacing},
            {"iterations", f.iterations},
            {"last_move", f.lastMove},
            {"removed", f.removed},
            {"contour", f.contour},
            {"initial", f.initial},
            {"fissions", f.fissions},
            {"deaths", f.deaths},
            {"last_population_change", f.lastPopulationChange},
            {"radius_spread", f.radiusSpread},
            {"spacing", {{"mean", stats.nnMean}, {"cv", stats.nnCV}, {"min", stats.nnMin}, {"max", stats.nnMax}}},
            {"max_surface_distance_voxels", stats.maxSurfaceDistanceVoxels}};
}

} // namespace vdbhair
