// vdbhair scalp MESH|POINTS -o scalp.vdb: a scalp as a VDB level set (grid `surface`), with an
// optional hair region (grid `region`).
#include "../Command.h"
#include "../ParamOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpInput.h>
#include <vdbhair/scalp/ScalpJson.h>
#include <vdbhair/scalp/ScalpRegion.h>
#include <vdbhair/scalp/ScalpSurface.h>

#include <algorithm>
#include <chrono>

namespace vdbhair::app {

namespace {

struct ScalpCmdParams
{
    std::string input, output, region, regionMask, regionGrid;
    ScalpBuildParams params;  ///< its declared parameters (scalpParameters()) are options
    std::vector<double> sphere;  ///< cx, cy, cz, r
};

int runScalp(const ScalpCmdParams& p, const CommonOptions& common)
{
    // Arguments, before any work.
    if (fileExtension(p.output) != ".vdb") throw ValueError(p.output + ": the scalp is written as OpenVDB; the output must end in .vdb");
    checkParamOptions(scalpParameters(), p.params);
    if (!p.sphere.empty() && (p.sphere.size() != 4 || !(p.sphere[3] > 0.0))) throw ValueError("--sphere needs CX,CY,CZ,R with R > 0");
    if (p.sphere.empty() && p.input.empty()) throw ValueError("needs an input (a mesh .ply/.obj, points .ply with normals, or a strand file) or --sphere CX,CY,CZ,R");
    if (!p.sphere.empty() && !p.input.empty()) throw ValueError("both an input (" + p.input + ") and --sphere: give one");
    const double regionRadius = p.params.regionRadius, regionThreshold = p.params.regionThreshold;
    if (regionRadius > 0.0 && p.region.empty()) throw ValueError("--region-radius without --region STRANDS");
    if (int(!p.region.empty()) + int(!p.regionMask.empty()) + int(!p.params.regionVertex.empty()) > 1)
        throw ValueError("more than one of --region, --region-mask and --region-vertex: give one");
    if (!p.params.regionVertex.empty() && fileExtension(p.input) != ".ply")
        throw ValueError("--region-vertex " + p.params.regionVertex + ": reads a vertex property of a PLY mesh, and the input " +
                         (p.input.empty() ? std::string("is a sphere") : "'" + p.input + "' is not one"));
    if (!p.regionGrid.empty() && p.regionMask.empty()) throw ValueError("--region-grid without --region-mask MASK.vdb");

    ScalpParams sp = p.params.surface;
    sp.source = p.input;

    const auto t0 = std::chrono::steady_clock::now();
    openvdb::FloatGrid::Ptr surface;
    ScalpFileReport file;  // without an input (a sphere): not read
    if (!p.sphere.empty()) {
        surface = scalpFromSphere(Vec3d(p.sphere[0], p.sphere[1], p.sphere[2]), p.sphere[3], sp);
    } else {
        surface = scalpFromFile(p.input, sp, &file, true, common.interrupter);
        printWarnings("scalp", file.read, common);
    }
    const std::string kind = p.sphere.empty() ? file.kind : "sphere";

    openvdb::GridCPtrVec grids{surface};
    openvdb::BoolGrid::Ptr region;
    ScalpRegionSource source;
    if (!p.region.empty()) {
        const StrandSet strands = loadStrands("scalp", p.region, common);
        std::vector<Vec3f> roots;
        for (std::size_t i = 0; i < strands.numStrands(); ++i) roots.push_back(strands.root(i));
        const double radius = regionRadius > 0.0 ? regionRadius : defaultRegionRadius(*surface, roots);
        const Stage stage(common, "region from the roots of " + p.region);
        region = regionFromRoots(*surface, roots, radius, p.region, std::uint64_t(1) << 28, defaultRootDistance(*surface));
        grids.push_back(region);
        source.roots = roots.size();
        source.radius = radius;
    } else if (!p.params.regionVertex.empty()) {
        const Stage stage(common, "region from the vertex values '" + p.params.regionVertex + "' of " + p.input);
        region = regionFromVertexValues(*surface, readTriangleMesh(p.input), readPlyVertexValues(p.input, p.params.regionVertex), regionThreshold, p.input);
        grids.push_back(region);
        source = {ScalpRegionSource::Kind::Vertex, 0, 0.0, p.params.regionVertex, regionThreshold};
    } else if (!p.regionMask.empty()) {
        // The mask: the grid named, else 'region', else the file's first bool or float grid that is not a level set.
        const openvdb::GridBase::Ptr mask = readMaskGrid(p.regionMask, p.regionGrid, "region", "a region mask (--region-grid NAME)");
        const std::string name = mask->getName();
        const Stage stage(common, "region from the mask '" + name + "' of " + p.regionMask);
        region = regionFromMask(*surface, *mask, regionThreshold, p.regionMask);
        grids.push_back(region);
        source = {ScalpRegionSource::Kind::Mask, 0, 0.0, name, regionThreshold};
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    {
        const Stage stage(common, "writing " + p.output);
        writeVdbGrids(p.output, grids, "scalp(" + p.output + ")");
    }
    const double h = surface->voxelSize().x();
    // The area roots can grow on, as `roots` counts it, and the band that has no surface in it.
    const ScalpArea areas = measureScalpArea(surface, region);
    warnBandWithoutZero("scalp", kind == "sphere" ? std::string("the sphere") : p.input, areas.area, areas.areaWithoutZero, common);
    if (common.json) {
        nlohmann::json j = scalpReport(*surface, sp.halfWidth, areas, p.sphere.empty() ? &file : nullptr, region.get(), source);
        j["output"] = p.output;
        j["seconds"] = seconds;
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "surface: level set from " << (kind == "sphere" ? "a sphere" : kind + " " + p.input) << ", voxel size " << formatValue(h)
                  << ", " << surface->activeVoxelCount() << " active voxels";
        if (kind == "mesh") {
            std::cout << " (" << file.mesh.cappedLoops << " boundary loop(s) capped, " << file.mesh.weldedVertices << " vertices welded)";
        }
        std::cout << "; surface area " << formatValue(std::round(areas.area * 10.0) / 10.0) << (region ? " in the region" : "") << "\n";
        if (region && !p.region.empty())
            std::cout << "region: " << region->activeVoxelCount() << " voxels within " << formatValue(source.radius)
                      << " of the roots of " << p.region << "\n";
        if (region && !p.params.regionVertex.empty())
            std::cout << "region: " << region->activeVoxelCount() << " voxels where the vertex value '" << p.params.regionVertex << "' exceeds "
                      << formatValue(regionThreshold) << "\n";
        if (region && !p.regionMask.empty())
            std::cout << "region: " << region->activeVoxelCount() << " voxels covered by the mask '" << source.name
                      << "' of " << p.regionMask << "\n";
        std::cout << "wrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addScalpCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<ScalpCmdParams>();
    CLI::App* sub = addVerb(app, "scalp");
    sub->add_option("input", params->input,
                    "Mesh (.ply or .obj with faces: meshToLevelSet, open boundaries capped), points with normals (.ply nx ny nz, or the roots "
                    "of a strand file: Turk & O'Brien's variational implicit)");
    sub->add_option("-o,--output", params->output, "Output .vdb")->required();
    sub->add_option("--sphere", params->sphere, "A sphere CX,CY,CZ,R (world units) instead of an input")->delimiter(',')->expected(4);
    addParamOptions(sub, params->params, scalpParameters());
    sub->add_option("--region", params->region, "Strand file: the region is where its roots are (grid 'region')");
    sub->add_option("--region-mask", params->regionMask, "A .vdb whose bool or float grid paints the region: surface voxels it covers (a bool grid's true values, a float grid's values above --region-threshold)");
    sub->add_option("--region-grid", params->regionGrid, "The mask's grid (default: 'region', else the file's first bool or float grid that is not a level set)");
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Examples:\n  vdbhair scalp head.ply -o scalp.vdb --voxel-size 0.5 --region hair.hair\n"
                "  vdbhair scalp --sphere 0,0,0,10 -o ball.vdb --voxel-size 0.2");
    return {sub, [params, &common] { return runScalp(*params, common); }};
}

} // namespace vdbhair::app
