#include "ScalpInput.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/Follicles.h>

#include <algorithm>

namespace vdbhair {

const ParamTable<ScalpBuildParams>& scalpParameters()
{
    using P = ScalpBuildParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto voxel = makeParam<P>("voxel-size", "Voxel size", "world units", member<P>([](P& p) -> double& { return p.surface.voxelSize; }));
        voxel.min = 0.0;
        voxel.zeroMeans = "1/100 of the input's largest extent";
        t.push_back(voxel);
        // ScalpParams::halfWidth is a float (OpenVDB's level-set tools take one): read and set as a number.
        auto half = makeParam<P>("half-width", "Narrow-band half width", "voxels",
                                 ParamAccess<P, double>{[](const P& p) { return double(p.surface.halfWidth); },
                                                        [](P& p, double v) { p.surface.halfWidth = float(v); }});
        half.min = ScalpParams::kMinHalfWidth;
        half.max = ScalpParams::kMaxHalfWidth;
        t.push_back(half);
        auto maxVoxels = makeParam<P>("max-voxels", "Refuse voxel sizes whose band is estimated at more voxels", "",
                                      member<P>([](P& p) -> std::uint64_t& { return p.surface.maxVoxels; }));
        maxVoxels.min = 1;
        t.push_back(maxVoxels);
        auto constraints = makeParam<P>("max-constraints", "Points input: thin to this many constraint points (the solve is cubic)", "",
                                        member<P>([](P& p) -> std::size_t& { return p.surface.maxConstraints; }));
        constraints.min = double(ScalpParams::kMinConstraints);
        t.push_back(constraints);
        auto radius = makeParam<P>("region-radius", "Region from roots: the radius around each root", "world units",
                                   member<P>([](P& p) -> double& { return p.regionRadius; }));
        radius.min = 0.0;
        radius.zeroMeans = "twice the roots' mean spacing, at least 2 voxels";
        t.push_back(radius);
        t.push_back(makeParam<P>("region-threshold", "A float mask or vertex value covers where it exceeds this", "",
                                 member<P>([](P& p) -> double& { return p.regionThreshold; })));
        auto vertex = makeParam<P>("region-vertex",
                                   "A PLY mesh input's vertex property that paints the region: a colour channel (red, green, blue, alpha; "
                                   "uchar scaled to 0-1) or any named scalar, above the region threshold (each band voxel takes the "
                                   "inverse-distance average of its 4 nearest vertices' values)", "",
                                   member<P>([](P& p) -> std::string& { return p.regionVertex; }));
        vertex.pythonNone = true;  // None: no painted region
        t.push_back(vertex);
        return t;
    }();
    return table;
}

OrientedPoints orientedRoots(const StrandSet& strands)
{
    OrientedPoints pts;
    pts.positions.reserve(strands.numStrands());
    pts.normals.reserve(strands.numStrands());
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        const std::size_t b = strands.begin(i);
        const Vec3f d = strands.end(i) > b + 1 ? strands.positions[b + 1] - strands.positions[b] : Vec3f(0.f);
        const float len = d.length();
        pts.positions.push_back(strands.positions[b]);
        pts.normals.push_back(len > 0.f ? d / len : Vec3f(0.f));
    }
    return pts;
}

openvdb::FloatGrid::Ptr scalpFromFile(const std::string& path, const ScalpParams& params, ScalpFileReport* report, bool threaded,
                                      openvdb::util::NullInterrupter* interrupter)
{
    ScalpParams sp = params;
    if (sp.source.empty()) sp.source = path;
    ScalpFileReport local;
    ScalpFileReport& rep = report ? *report : local;
    const std::string ext = fileExtension(path);
    const bool asMesh = ext == ".obj" || (ext == ".ply" && plyElementCount(path, "face") > 0);
    if (asMesh) {
        rep.kind = "mesh";
        if (interrupter) interrupter->start(("reading " + path).c_str());
        const TriangleMesh mesh = readTriangleMesh(path);
        if (interrupter) interrupter->end();
        rep.triangles = mesh.triangles.size();
        return scalpFromMesh(mesh, sp, &rep.mesh, interrupter);
    }
    rep.kind = "points";
    OrientedPoints pts;
    if (ext == ".ply") {
        pts = readPlyPoints(path);
    } else if (isStrandFile(path)) {
        ReadOptions opts;
        opts.interrupter = interrupter;
        pts = orientedRoots(readStrands(path, opts, &rep.read));
    } else {
        throw ValueError(path + ": unknown scalp input '" + ext + "'; give a mesh (.ply, .obj), points with normals (.ply) or a strand file");
    }
    if (pts.size() < 5) {
        throw ValueError(path + ": " + std::to_string(pts.size()) +
                         " constraint points; the variational implicit needs at least 5 (4 fix its affine part)");
    }
    rep.points = pts.size();
    rep.constraints = std::min(pts.size(), sp.maxConstraints);
    return scalpFromPoints(pts, sp, threaded, interrupter);
}

openvdb::BoolGrid::Ptr readScalpRegion(const std::string& path)
{
    if (fileExtension(path) != ".vdb") return nullptr;
    const std::string where = "readScalpRegion(" + path + ")";
    const std::vector<std::string> names = vdbGridNames(path, where);
    if (std::find(names.begin(), names.end(), "region") == names.end()) return nullptr;
    const openvdb::GridBase::Ptr g = readVdbGrid(path, "region", where);
    openvdb::BoolGrid::Ptr region = openvdb::GridBase::grid<openvdb::BoolGrid>(g);
    if (!region) throw TypeError(path + ": grid 'region' holds " + g->valueType() + " values; a region is a bool grid");
    return region;
}

double defaultRegionRadius(const openvdb::FloatGrid& surface, const std::vector<Vec3f>& roots)
{
    return std::max(2.0 * measureFollicles(roots).nnMean, 2.0 * surface.voxelSize().x());
}

double defaultRootDistance(const openvdb::FloatGrid& surface)
{
    const openvdb::CoordBBox ib = surface.evalActiveVoxelBoundingBox();
    return 0.1 * (surface.indexToWorld(ib.max()) - surface.indexToWorld(ib.min())).length();
}

} // namespace vdbhair
