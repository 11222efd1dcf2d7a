// vdbhair scalp MESH|POINTS -o scalp.vdb: a scalp as a VDB level set (grid `surface`), with an
// optional hair region (grid `region`).
#include "../Command.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpRegion.h>
#include <vdbhair/scalp/ScalpSurface.h>

#include <algorithm>
#include <chrono>

namespace vdbhair::app {

namespace {

struct ScalpCmdParams
{
    std::string input, output, region, regionMask, regionGrid;
    double regionThreshold = kDefaultMaskThreshold;
    double voxelSize = 0.0;
    CLI::Option* voxelOpt = nullptr;
    std::vector<double> sphere;  ///< cx, cy, cz, r
    // Defaults from the library's ScalpParams.
    float halfWidth = ScalpParams{}.halfWidth;
    std::uint64_t maxVoxels = ScalpParams{}.maxVoxels;
    std::size_t maxConstraints = ScalpParams::kDefaultMaxConstraints;
    double regionRadius = 0.0;
};

/// Oriented points from a strand file: each root, with its first segment's direction as normal.
OrientedPoints rootsOfStrands(const StrandSet& strands)
{
    OrientedPoints pts;
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        const std::size_t b = strands.begin(i);
        pts.positions.push_back(strands.positions[b]);
        Vec3f d = strands.end(i) > b + 1 ? strands.positions[b + 1] - strands.positions[b] : Vec3f(0.f);
        const float len = d.length();
        pts.normals.push_back(len > 0.f ? d / len : Vec3f(0.f));
    }
    return pts;
}

int runScalp(const ScalpCmdParams& p, const CommonOptions& common)
{
    // Arguments, before any work.
    if (fileExtension(p.output) != ".vdb") throw ValueError(p.output + ": the scalp is written as OpenVDB; the output must end in .vdb");
    const bool voxelGiven = p.voxelOpt && p.voxelOpt->count() > 0;
    if (voxelGiven && (!(p.voxelSize > 0.0) || !std::isfinite(p.voxelSize))) {
        throw ValueError("--voxel-size " + formatValue(p.voxelSize) + ": must be a positive finite length");
    }
    if (!p.sphere.empty() && (p.sphere.size() != 4 || !(p.sphere[3] > 0.0))) throw ValueError("--sphere needs CX,CY,CZ,R with R > 0");
    if (p.sphere.empty() && p.input.empty()) throw ValueError("needs an input (a mesh .ply/.obj, points .ply with normals, or a strand file) or --sphere CX,CY,CZ,R");
    if (!p.sphere.empty() && !p.input.empty()) throw ValueError("both an input (" + p.input + ") and --sphere: give one");
    if (p.regionRadius < 0.0 || !std::isfinite(p.regionRadius)) throw ValueError("--region-radius " + formatValue(p.regionRadius) + ": must be a positive length");
    if (p.regionRadius > 0.0 && p.region.empty()) throw ValueError("--region-radius without --region STRANDS");
    if (!p.region.empty() && !p.regionMask.empty()) throw ValueError("both --region and --region-mask: give one");
    if (!p.regionGrid.empty() && p.regionMask.empty()) throw ValueError("--region-grid without --region-mask MASK.vdb");
    if (!std::isfinite(p.regionThreshold)) throw ValueError("--region-threshold " + formatValue(p.regionThreshold) + ": must be finite");

    ScalpParams sp;
    sp.voxelSize = voxelGiven ? p.voxelSize : 0.0;
    sp.halfWidth = p.halfWidth;
    sp.maxVoxels = p.maxVoxels;
    sp.source = p.input;

    const auto t0 = std::chrono::steady_clock::now();
    openvdb::FloatGrid::Ptr surface;
    std::string kind;
    nlohmann::json detail = nlohmann::json::object();
    if (!p.sphere.empty()) {
        kind = "sphere";
        surface = scalpFromSphere(Vec3d(p.sphere[0], p.sphere[1], p.sphere[2]), p.sphere[3], sp);
    } else {
        const std::string ext = fileExtension(p.input);
        bool asMesh = ext == ".obj";
        if (ext == ".ply") asMesh = plyElementCount(p.input, "face") > 0;
        if (asMesh) {
            kind = "mesh";
            TriangleMesh mesh;
            {
                const Stage stage(common, "reading " + p.input);
                mesh = readTriangleMesh(p.input);
            }
            ScalpMeshReport rep;
            surface = scalpFromMesh(mesh, sp, &rep, common.interrupter);
            detail = {{"triangles", mesh.triangles.size()}, {"welded_vertices", rep.weldedVertices},
                      {"boundary_edges", rep.boundaryEdges}, {"capped_loops", rep.cappedLoops},
                      {"open_edges", rep.openEdges}, {"non_manifold_edges", rep.nonManifoldEdges}};
        } else {
            kind = "points";
            OrientedPoints pts;
            if (ext == ".ply") {
                const Stage stage(common, "reading " + p.input);
                pts = readPlyPoints(p.input);
            } else if (isStrandFile(p.input)) {
                pts = rootsOfStrands(loadStrands("scalp", p.input, common));
            } else {
                throw ValueError(p.input + ": unknown input '" + ext + "'; give a mesh (.ply, .obj), points with normals (.ply) or a strand file");
            }
            if (pts.size() < 5) {
                throw ValueError(p.input + ": " + std::to_string(pts.size()) + " constraint points; the variational implicit needs at least 5 (4 fix its affine part)");
            }
            surface = scalpFromPoints(pts, sp, p.maxConstraints, true, common.interrupter);
            detail = {{"points", pts.size()}, {"constraints", std::min(pts.size(), p.maxConstraints)}};
        }
    }

    openvdb::GridCPtrVec grids{surface};
    openvdb::BoolGrid::Ptr region;
    if (!p.region.empty()) {
        const StrandSet strands = loadStrands("scalp", p.region, common);
        std::vector<Vec3f> roots;
        for (std::size_t i = 0; i < strands.numStrands(); ++i) roots.push_back(strands.root(i));
        double radius = p.regionRadius;
        if (radius == 0.0) {
            // Default: twice the roots' mean nearest-neighbour spacing, so the region has no gaps.
            radius = std::max(2.0 * measureFollicles(roots).nnMean, 2.0 * surface->voxelSize().x());
        }
        // Roots farther from the scalp than a tenth of its size belong to another head.
        const openvdb::CoordBBox ib = surface->evalActiveVoxelBoundingBox();
        const double maxDistance = 0.1 * (surface->indexToWorld(ib.max()) - surface->indexToWorld(ib.min())).length();
        const Stage stage(common, "region from the roots of " + p.region);
        region = regionFromRoots(*surface, roots, radius, p.region, std::uint64_t(1) << 28, maxDistance);
        grids.push_back(region);
        detail["region"] = {{"roots", roots.size()}, {"radius", radius}, {"active_voxels", region->activeVoxelCount()}};
    } else if (!p.regionMask.empty()) {
        // The mask: the grid named, else 'region', else the file's first bool or float grid that is not a level set.
        std::string name = p.regionGrid;
        if (name.empty()) {
            const std::vector<std::string> names = vdbGridNames(p.regionMask, p.regionMask);
            if (std::find(names.begin(), names.end(), "region") != names.end()) name = "region";
            for (std::size_t i = 0; name.empty() && i < names.size(); ++i) {
                const openvdb::GridBase::Ptr g = readVdbGrid(p.regionMask, names[i], p.regionMask);
                if ((g->isType<openvdb::BoolGrid>() || g->isType<openvdb::FloatGrid>()) && g->getGridClass() != openvdb::GRID_LEVEL_SET) name = names[i];
            }
            if (name.empty()) throw LookupError(p.regionMask + ": no bool or float grid to use as a region mask (--region-grid NAME)");
        }
        const openvdb::GridBase::Ptr mask = readVdbGrid(p.regionMask, name, p.regionMask);
        const Stage stage(common, "region from the mask '" + name + "' of " + p.regionMask);
        region = regionFromMask(*surface, *mask, p.regionThreshold, p.regionMask);
        grids.push_back(region);
        detail["region"] = {{"mask", name}, {"threshold", p.regionThreshold}, {"active_voxels", region->activeVoxelCount()}};
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    {
        const Stage stage(common, "writing " + p.output);
        writeVdbGrids(p.output, grids, "scalp(" + p.output + ")");
    }
    const double h = surface->voxelSize().x();
    if (common.json) {
        nlohmann::json j = {{"output", p.output}, {"kind", kind}, {"voxel_size", h}, {"half_width", p.halfWidth},
                            {"active_voxels", surface->activeVoxelCount()}, {"seconds", seconds}};
        j.update(detail);
        printJson(j);
    } else if (!common.quiet) {
        std::cout << "surface: level set from " << (kind == "sphere" ? "a sphere" : kind + " " + p.input) << ", voxel size " << formatValue(h)
                  << ", " << surface->activeVoxelCount() << " active voxels";
        if (kind == "mesh") {
            std::cout << " (" << detail["capped_loops"].get<std::size_t>() << " boundary loop(s) capped, "
                      << detail["welded_vertices"].get<std::size_t>() << " vertices welded)";
        }
        std::cout << "\n";
        if (region && !p.region.empty())
            std::cout << "region: " << region->activeVoxelCount() << " voxels within " << formatValue(detail["region"]["radius"].get<double>())
                      << " of the roots of " << p.region << "\n";
        if (region && !p.regionMask.empty())
            std::cout << "region: " << region->activeVoxelCount() << " voxels covered by the mask '" << detail["region"]["mask"].get<std::string>()
                      << "' of " << p.regionMask << "\n";
        std::cout << "wrote " << p.output << "\n";
    }
    return 0;
}

} // namespace

Command addScalpCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<ScalpCmdParams>();
    CLI::App* sub = app.add_subcommand("scalp", "Make a scalp level set (grid 'surface') from a mesh, a sphere or oriented points, and a hair region (grid 'region')");
    sub->add_option("input", params->input,
                    "Mesh (.ply or .obj with faces: meshToLevelSet, open boundaries capped), points with normals (.ply nx ny nz, or the roots "
                    "of a strand file: Turk & O'Brien's variational implicit)");
    sub->add_option("-o,--output", params->output, "Output .vdb")->required();
    params->voxelOpt = sub->add_option("--voxel-size", params->voxelSize, "Voxel size in world units (default: 1/100 of the largest extent)");
    sub->add_option("--sphere", params->sphere, "A sphere CX,CY,CZ,R (world units) instead of an input")->delimiter(',')->expected(4);
    sub->add_option("--half-width", params->halfWidth, "Narrow-band half width in voxels")->capture_default_str();
    sub->add_option("--max-voxels", params->maxVoxels, "Refuse voxel sizes whose band is estimated at more voxels")->capture_default_str();
    sub->add_option("--max-constraints", params->maxConstraints, "Points input: thin to this many constraint points (the solve is cubic)")->capture_default_str();
    sub->add_option("--region", params->region, "Strand file: the region is where its roots are (grid 'region')");
    sub->add_option("--region-radius", params->regionRadius, "Radius around each root, world units (default: twice the roots' mean spacing)");
    sub->add_option("--region-mask", params->regionMask, "A .vdb whose bool or float grid paints the region: surface voxels it covers (a bool grid's true values, a float grid's values above --region-threshold)");
    sub->add_option("--region-grid", params->regionGrid, "The mask's grid (default: 'region', else the file's first bool or float grid that is not a level set)");
    sub->add_option("--region-threshold", params->regionThreshold, "A float mask covers where its value exceeds this")->capture_default_str();
    addCommonOptions(sub, common);
    sub->footer("Examples:\n  vdbhair scalp head.ply -o scalp.vdb --voxel-size 0.5 --region hair.hair\n"
                "  vdbhair scalp --sphere 0,0,0,10 -o ball.vdb --voxel-size 0.2");
    return {sub, [params, &common] { return runScalp(*params, common); }};
}

} // namespace vdbhair::app
