// scalp and roots: scalp level sets and follicles on them (`vdbhair scalp`, `vdbhair roots`).
#include "Common.h"
#include "Params.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpInput.h>
#include <vdbhair/scalp/ScalpJson.h>
#include <vdbhair/scalp/ScalpRegion.h>
#include <vdbhair/strands/StrandSet.h>

#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>

namespace vdbhair::py {

namespace {


std::vector<Vec3f> toFloat(const std::vector<Vec3d>& points)
{
    return std::vector<Vec3f>(points.begin(), points.end());
}

/// An (N, 3) float32 array copied from @a v.
pyb::array_t<float> pointsArray(const std::vector<Vec3f>& v)
{
    pyb::array_t<float> a({v.size(), std::size_t(3)});
    float* d = a.mutable_data();
    for (std::size_t i = 0; i < v.size(); ++i)
        for (int c = 0; c < 3; ++c) d[3 * i + c] = v[i][c];
    return a;
}

/// Roots for a region: a Strands' roots or an (N, 3) array.
std::vector<Vec3f> rootsArgument(const pyb::handle& obj, const std::string& what)
{
    if (pyb::isinstance<StrandSet>(obj)) {
        const StrandSet& s = obj.cast<const StrandSet&>();
        std::vector<Vec3f> roots;
        for (std::size_t i = 0; i < s.numStrands(); ++i) roots.push_back(s.root(i));
        return roots;
    }
    return toFloat(pointsArgument(obj, what));
}

/// A scalp= argument: a vdbhair.Grid holding a float level set, or a path (readScalp()).
openvdb::FloatGrid::Ptr scalpGridArgument(const pyb::handle& obj, const std::string& where)
{
    if (pyb::isinstance<PyGrid>(obj)) {
        const openvdb::GridBase::Ptr& g = obj.cast<const PyGrid&>().grid;
        openvdb::FloatGrid::Ptr grid = std::dynamic_pointer_cast<openvdb::FloatGrid>(g);
        if (!grid || grid->getGridClass() != openvdb::GRID_LEVEL_SET)
            throw TypeError(where + ": grid '" + g->getName() + "' is not a float level set; vdbhair.scalp() makes one");
        return grid;
    }
    throw TypeError(where + ": scalp must be a vdbhair.Grid (a level set) or a path to a scalp .vdb or a head mesh");
}

/// roots()'s result: `roots --json`'s report (rootsReport()), plus the follicles as arrays.
pyb::dict folliclesDict(const Follicles& f, const FollicleStats& stats, bool region)
{
    pyb::dict d = toPython(rootsReport(f, stats, region));
    d["positions"] = pointsArray(f.positions);
    d["normals"] = pointsArray(f.normals);
    d["tangents"] = pointsArray(f.tangents);
    return d;
}

/// roots: follicles spread over a scalp (follicleParameters()).
void defineRoots(pyb::module_& m)
{
    auto rootsImpl = [](const pyb::object& scalp, const pyb::dict& kw) {
        FollicleParams fp;
        applyKeywords(follicleParameters(), kw, fp, "roots");
        if ((fp.count == 0) == (fp.spacing == 0.0)) throw ValueError("roots: give one of count= and spacing=");
        fp.up = fp.up / fp.up.length();  // any non-zero (x, y, z) (checked as declared)
        const bool fromPath = isPathLike(scalp);
        const std::string path = fromPath ? pathString(scalp, "roots: scalp") : std::string();
        openvdb::FloatGrid::Ptr surface = fromPath ? nullptr : scalpGridArgument(scalp, "roots");
        const pyb::object regionArg = kw["region"];
        openvdb::BoolGrid::Ptr region;
        const bool noRegion = pyb::isinstance<pyb::bool_>(regionArg) && !regionArg.cast<bool>();
        const bool regionFromFile = regionArg.is_none();
        if (!regionArg.is_none() && !noRegion) {
            if (!pyb::isinstance<PyGrid>(regionArg)) throw TypeError("roots: region must be a vdbhair.Grid (bool), False or None");
            region = std::dynamic_pointer_cast<openvdb::BoolGrid>(regionArg.cast<const PyGrid&>().grid);
            if (!region) throw TypeError("roots: region grid '" + regionArg.cast<const PyGrid&>().grid->getName() + "' is not a bool grid");
        }
        struct Out
        {
            Follicles f;
            FollicleStats stats;
            bool region;
        };
        const Out out = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            if (fromPath) {
                surface = readScalp(path, interrupter);
                if (regionFromFile) region = readScalpRegion(path);
            }
            Out o;
            o.f = sampleFollicles(surface, region, fp, true, interrupter);
            o.stats = measureFollicles(o.f.positions, surface);
            o.region = bool(region);
            return o;
        });
        return folliclesDict(out.f, out.stats, out.region);
    };
    defineVerb(m, "roots", {"scalp"}, follicleParameters(),
               {{"region", "", pyb::none(),
                 "a bool vdbhair.Grid (scalp()'s region); None: the file's 'region' grid when scalp is a path, else the whole "
                 "surface; False: the whole surface."}},
               "Follicles spread evenly over a scalp (Witkin & Heckbert 1994 repulsion on the zero level\n"
               "set, as Piuze et al. 2011 place roots): ``vdbhair roots``. Identical for any thread count.\n"
               "Give one of ``count`` and ``spacing``.",
               "    scalp: a vdbhair.Grid holding a level set (what scalp() returns), or a path to a scalp .vdb\n"
               "        (its 'surface' and 'region' grids) or to a head mesh.\n",
               "A dict: ``roots --json``'s report key for key (less the file name and the seconds): ``count``,\n"
               "    ``region`` (whether one confined them), ``area``, ``area_without_zero``, ``target_spacing``,\n"
               "    ``iterations``, ``last_move``, ``removed``, ``contour`` (with a region, the first ``contour``\n"
               "    roots are fixed along its rim), ``initial``, ``fissions``, ``deaths``,\n"
               "    ``last_population_change``, ``radius_spread``, ``spacing`` (nearest-neighbour mean, cv, min,\n"
               "    max) and ``max_surface_distance_voxels``; plus ``positions``, ``normals`` (outward) and\n"
               "    ``tangents``: (N, 3) float32 arrays (the roots and their frames, ready for\n"
               "    interpolate(guides, r[\"positions\"], normals=r[\"normals\"])).",
               pyb::cpp_function(rootsImpl, pyb::arg("scalp"), pyb::arg("keywords")));
}

/// scalp: a level set from a file, a Strands' roots, points or a sphere (scalpParameters()).
void defineScalp(pyb::module_& m)
{
    auto scalpImpl = [](const pyb::object& source, const pyb::dict& kw) {
        ScalpBuildParams params;
        applyKeywords(scalpParameters(), kw, params, "scalp");
        const pyb::object normals = kw["normals"], regionArg = kw["region"], regionMask = kw["region_mask"];
        std::optional<std::array<double, 4>> sphere;
        if (!kw["sphere"].is_none()) {
            const std::vector<double> v = kw["sphere"].cast<std::vector<double>>();
            if (v.size() != 4) throw ValueError("scalp: sphere=(cx, cy, cz, r) needs four numbers, got " + std::to_string(v.size()));
            sphere = std::array<double, 4>{v[0], v[1], v[2], v[3]};
        }
        std::optional<std::string> regionVertex;
        if (!params.regionVertex.empty()) regionVertex = params.regionVertex;
        const bool hasSource = !source.is_none();
        if (hasSource == bool(sphere)) throw ValueError("scalp: give one of source (a path, a Strands or (N, 3) points) and sphere=(cx, cy, cz, r)");
        if (sphere && (!((*sphere)[3] > 0.0) || !std::isfinite((*sphere)[3]))) throw ValueError("scalp: sphere=(cx, cy, cz, r) needs r > 0");
        if (int(!regionArg.is_none()) + int(!regionMask.is_none()) + int(bool(regionVertex)) > 1)
            throw ValueError("scalp: more than one of region, region_mask and region_vertex: give one");
        if (regionVertex && !(isPathLike(source) && fileExtension(pathString(source)) == ".ply"))
            throw ValueError("scalp: region_vertex='" + *regionVertex + "' reads a vertex property of a PLY mesh; the source is not a .ply path");
        if (!normals.is_none() && (isPathLike(source) || pyb::isinstance<StrandSet>(source)))
            throw ValueError("scalp: normals go with an (N, 3) array of points as the source");
        ScalpParams sp = params.surface;
        // Arrays are read with the GIL held, before the work.
        std::optional<std::string> path;
        OrientedPoints points;
        if (isPathLike(source)) {
            path = pathString(source, "scalp: source");
        } else if (pyb::isinstance<StrandSet>(source)) {
            points = orientedRoots(source.cast<const StrandSet&>());
            sp.source = "roots of Strands";
        } else if (hasSource) {
            points.positions = toFloat(pointsArgument(source, "scalp: source"));
            if (normals.is_none()) throw ValueError("scalp: points need normals=, an (N, 3) array of outward normals");
            points.normals = toFloat(pointsArgument(normals, "scalp: normals"));
            if (points.normals.size() != points.positions.size())
                throw ValueError("scalp: " + std::to_string(points.normals.size()) + " normals for " + std::to_string(points.positions.size()) + " points");
            sp.source = "points";
        }
        std::vector<Vec3f> regionRoots;
        if (!regionArg.is_none()) regionRoots = rootsArgument(regionArg, "scalp: region");
        openvdb::GridBase::Ptr mask;
        if (!regionMask.is_none()) {
            if (!pyb::isinstance<PyGrid>(regionMask)) throw TypeError("scalp: region_mask must be a vdbhair.Grid (a bool or float grid)");
            mask = regionMask.cast<const PyGrid&>().grid;
        }
        const bool wantRegion = !regionArg.is_none();
        const double regionRadius = params.regionRadius, regionThreshold = params.regionThreshold;
        // What scalp --json reports of the input and the region (ScalpJson.h).
        ScalpFileReport file;
        if (!sphere && !path) file = {"points", 0, {}, points.size(), std::min(points.size(), sp.maxConstraints), {}};
        ScalpRegionSource regionSource;
        if (mask) regionSource = {ScalpRegionSource::Kind::Mask, 0, 0.0, mask->getName(), regionThreshold};
        if (regionVertex) regionSource = {ScalpRegionSource::Kind::Vertex, 0, 0.0, *regionVertex, regionThreshold};
        auto grids = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            openvdb::FloatGrid::Ptr surface;
            if (sphere) surface = scalpFromSphere(Vec3d((*sphere)[0], (*sphere)[1], (*sphere)[2]), (*sphere)[3], sp);
            else if (path) surface = scalpFromFile(*path, sp, &file, true, interrupter);
            else surface = scalpFromPoints(points, sp, true, interrupter);
            openvdb::BoolGrid::Ptr region;
            if (wantRegion) {
                const double radius = regionRadius > 0.0 ? regionRadius : defaultRegionRadius(*surface, regionRoots);
                region = regionFromRoots(*surface, regionRoots, radius, "region", std::uint64_t(1) << 28, defaultRootDistance(*surface));
                regionSource.roots = regionRoots.size();
                regionSource.radius = radius;
            } else if (mask) {
                region = regionFromMask(*surface, *mask, regionThreshold, "region_mask");
            } else if (regionVertex) {
                region = regionFromVertexValues(*surface, readTriangleMesh(*path), readPlyVertexValues(*path, *regionVertex), regionThreshold, *path);
            }
            return std::make_pair(surface, region);
        });
        const pyb::object regionObj = grids.second ? pyb::cast(PyGrid{grids.second}) : pyb::none();
        if (!kw["return_report"].cast<bool>()) return pyb::make_tuple(PyGrid{grids.first}, regionObj);
        // scalp --json's report, less the file name and the seconds.
        const ScalpArea areas = runLong(0, pyb::none(), [&](WorkInterrupter*) { return measureScalpArea(grids.first, grids.second); });
        return pyb::make_tuple(PyGrid{grids.first}, regionObj,
                               toPython(scalpReport(*grids.first, sp.halfWidth, areas, sphere ? nullptr : &file, grids.second.get(), regionSource)));
    };
    defineVerb(m, "scalp", {"source=None"}, scalpParameters(),
               {{"normals", "", pyb::none(), "(N, 3) outward normals of an array source."},
                {"sphere", "Optional[Tuple[float, float, float, float]]", pyb::none(), "(cx, cy, cz, r) in world units, instead of a source."},
                {"region", "", pyb::none(),
                 "a Strands or (N, 3) roots: the hair region is the band within ``region_radius`` of their projections onto the "
                 "surface (roots farther than a tenth of the head are left out)."},
                {"region_mask", "", pyb::none(),
                 "a vdbhair.Grid painting the region instead: a bool grid's true values, or a float grid's values above "
                 "``region_threshold``."},
                {"return_report", "bool", pyb::bool_(false),
                 "also return ``scalp --json``'s report as a dict (less the file name and the seconds: kind, voxel_size, half_width, "
                 "active_voxels, area, area_without_zero, the mesh's repairs or the points used, and the region)."}},
               "A scalp as a VDB level set (Piuze et al. 2011, Sec. 4.3): ``vdbhair scalp``.",
               "    source: a path (a head mesh .obj / .ply with faces: meshToLevelSet with open boundaries\n"
               "        capped; points .ply with nx ny nz, or a strand file whose roots are the points: Turk &\n"
               "        O'Brien's variational implicit), a Strands (its roots, first segments as normals), or an\n"
               "        (N, 3) array of points with ``normals``. None with ``sphere``.\n",
               "(surface, region): the float level set named 'surface' (negative inside, world units) and\n"
               "    the bool grid 'region' or None. ``vdbhair.write_grids(path, [surface, region])`` writes what\n"
               "    ``vdbhair scalp`` writes; (surface, region, report) with return_report.",
               pyb::cpp_function(scalpImpl, pyb::arg("source"), pyb::arg("keywords")));
}

} // namespace

void bindScalp(pyb::module_& m)
{
    defineScalp(m);
    defineRoots(m);
}

} // namespace vdbhair::py
