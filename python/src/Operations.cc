// grow, fit, interpolate, reconstruct, render, inspect and compare (synth, transfer and comb: Synthesis.cc).
#include "Common.h"
#include "Params.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/helicoid/HelicoidFit.h>
#include <vdbhair/helicoid/HelicoidJson.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/helicoid/GuideInterpolation.h>
#include <vdbhair/helicoid/HelicoidInterpolation.h>
#include <vdbhair/helicoid/PointInterpolation.h>
#include <vdbhair/helicoid/Reconstruction.h>
#include <vdbhair/helicoid/Scene.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/VdbInspect.h>
#include <vdbhair/io/VdbInspectJson.h>
#include <vdbhair/render/Image.h>
#include <vdbhair/render/SliceRenderer.h>
#include <vdbhair/render/StrandRenderer.h>
#include <vdbhair/scalp/RootValues.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/synth/Comb.h>
#include <vdbhair/synth/HairTransfer.h>
#include <vdbhair/synth/StyleRegions.h>
#include <vdbhair/synth/Synthesis.h>

#include <nlohmann/json.hpp>

#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <tuple>
#include <utility>

namespace vdbhair::py {

namespace {


/// A scene argument: a path to a scene .json, or the scene itself as a dict.
Scene sceneArgument(const pyb::handle& scene, const std::string& where = "grow")
{
    if (isPathLike(scene)) {
        const std::string path = pathString(scene, where + ": scene");
        pyb::gil_scoped_release release;
        return readScene(path);
    }
    if (pyb::isinstance<pyb::dict>(scene)) {
        const std::string text = pyb::module_::import("json").attr("dumps")(scene).cast<std::string>();
        nlohmann::json j;
        try {
            j = nlohmann::json::parse(text);
        } catch (const nlohmann::json::exception& e) {
            throw FormatError(where + "(dict): " + e.what());
        }
        return sceneFromJson(j, where + "(dict)");
    }
    throw TypeError(where + ": scene must be a path to a scene .json or a dict, not " +
                    std::string(pyb::str(scene.get_type().attr("__name__"))));
}

/// interpolate's roots: positions (an array or a Strands' roots), normals=, root_groups=, and
/// density= and length= (a number, one value per root, or what the command reads: a mask, a
/// painted mesh, a list file).
InterpolationRoots interpolationRoots(const pyb::object& rootsArg, const pyb::dict& kw, FrameRule frames)
{
    auto isPath = [](const pyb::object& o) { return pyb::isinstance<pyb::str>(o) || pyb::hasattr(o, "__fspath__"); };
    InterpolationRoots roots;
    if (pyb::isinstance<StrandSet>(rootsArg)) {
        const StrandSet& r = rootsArg.cast<const StrandSet&>();
        for (std::size_t i = 0; i < r.numStrands(); ++i) roots.positions.push_back(Vec3d(r.root(i)));
    } else {
        roots.positions = pointsArgument(rootsArg, "interpolate: roots");
    }
    if (roots.positions.empty()) throw ValueError("interpolate: no roots");
    const pyb::object normalsArg = kw["normals"];
    if (!normalsArg.is_none()) {
        roots.normals = pointsArgument(normalsArg, "interpolate: normals");
        if (roots.normals.size() != roots.positions.size())
            throw ValueError("interpolate: " + std::to_string(roots.normals.size()) + " normals for " + std::to_string(roots.positions.size()) + " roots");
    }
    if (frames == FrameRule::Surface && roots.normals.empty()) throw ValueError("interpolate: frames='surface' needs normals");
    const pyb::object rootGroups = kw["root_groups"];
    if (!rootGroups.is_none()) {
        roots.groups = isPath(rootGroups) ? readRootIds(pyb::str(rootGroups).cast<std::string>(), roots.positions, "interpolate: root_groups=", "roots")
                                              : rootGroups.cast<std::vector<std::int32_t>>();
    }
    for (auto [option, values, grid] : {std::tuple{"density", &roots.density, "density"}, std::tuple{"length", &roots.length, "length"}}) {
        const pyb::object arg = kw[option];
        if (arg.is_none()) continue;
        if (isPath(arg)) {
            *values = readRootValues(pyb::str(arg).cast<std::string>(), roots.positions, std::string("interpolate: ") + option + "=", grid);
        } else if (pyb::isinstance<pyb::float_>(arg) || pyb::isinstance<pyb::int_>(arg)) {
            values->assign(roots.positions.size(), arg.cast<float>());
        } else {
            *values = arg.cast<std::vector<float>>();
            if (values->size() != roots.positions.size())
                throw ValueError(std::string("interpolate: ") + option + "= has " + std::to_string(values->size()) + " values for " +
                                 std::to_string(roots.positions.size()) + " roots: one per root");
        }
    }
    return roots;
}

/// grow: a scene's strands (growParameters()).
void defineGrow(pyb::module_& m)
{
    auto growImpl = [](const pyb::object& sceneArg, const pyb::dict& kw) -> pyb::object {
        const Scene scene = sceneArgument(sceneArg);
        GrowOptions opts;
        applyKeywords(growParameters(), kw, opts, "grow");
        GrowReport report;
        auto strands = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            return std::make_shared<StrandSet>(growScene(scene, opts, true, interrupter, &report));
        });
        if (!kw["return_report"].cast<bool>()) return pyb::cast(strands);
        // `grow --json`'s report (growReport()), less the file names and the seconds.
        return pyb::make_tuple(strands, toPython(growReport(scene, *strands, report)));
    };
    defineVerb(m, "grow", {"scene"}, growParameters(),
               {{"return_report", "bool", pyb::bool_(false),
                 "also return a dict: `grow --json`'s report key for key, less the file names and the seconds (guides, strands, "
                 "vertices, guides_near_axis: guides passing near a piece's singular axis)."}},
               "Grow the strands of a generalized-helicoid scene (Piuze et al. 2011): ``vdbhair grow``.\n\n"
               "Each guide, then its wisp strands; bitwise identical for any thread count. Raises\n"
               "vdbhair.LimitError over max_vertices.",
               "    scene: a path to a scene .json (\"vdbhair\": \"scene/1\"), or the scene as a dict (what fit returns).\n",
               "Strands, or (Strands, report) with return_report.", pyb::cpp_function(growImpl, pyb::arg("scene"), pyb::arg("keywords")));
}

/// fit: p-helicoids fitted to strands (fitParameters()).
void defineFit(pyb::module_& m)
{
    auto fitImpl = [](const StrandsPtr& strands, const pyb::dict& kw) -> pyb::object {
        FitParams fp;
        applyKeywords(fitParameters(), kw, fp, "fit");
        fp.validate("fit");  // its errors name fit's keywords (ParamError)
        const bool skipDegenerate = fp.skipDegenerate, returnReport = renamedKeywordValue(kw, "return_report", "return_summary", "fit").cast<bool>();
        std::vector<std::string> errors;
        const std::vector<StrandFit> fits = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            return fitStrands(*strands, fp, true, &errors, interrupter);
        });
        Scene scene;
        scene.integrator = HelicoidIntegrator::RK4;  // fits are streamlines, regrown exactly (as `vdbhair fit`)
        for (std::size_t i = 0; i < fits.size(); ++i) {
            if (!errors[i].empty()) {
                if (!skipDegenerate) throw ValueError("fit: " + errors[i] + " (skip_degenerate=True leaves such strands out)");
                continue;
            }
            SceneGuide g = guideFromFit(fits[i]);
            g.fit = {{"frechet", fits[i].frechet}, {"coupling", fits[i].coupling}, {"pieces", fits[i].pieces.size()}, {"strand", i},
                     {"step_deviation", fits[i].stepDeviation}};
            scene.guides.push_back(g);
        }
        pyb::object sceneObj = toPython(sceneToJson(scene));
        if (!returnReport) return sceneObj;
        // `fit --json`'s report (fitReport()), less the file name and the rate.
        const pyb::dict d = toPython(fitReport(summarizeFits(*strands, fits, errors, fp.maxError, fp.stepDeviationLimit)));
        return pyb::make_tuple(sceneObj, d);
    };
    defineVerb(m, "fit", {"strands: vdbhair.Strands"}, fitParameters(),
               {{"return_report", "bool", pyb::bool_(false),
                 "also return a dict: `fit --json`'s report key for key, less the file name and strands_per_second (strands, "
                 "fitted, skipped, over_max_error, frechet_relative: the discrete Frechet distance relative to length, mean and "
                 "p95; pieces_per_strand, evaluations_per_strand, step_convergence: the distance between each fit traced at its "
                 "step and at a quarter of it relative to length, mean, max and how many exceed a tenth of max_error; bytes of "
                 "fits and of points, compression)."},
                renamedKeyword("return_summary", "return_report")},
               "Fit p-helicoids to every strand (Piuze et al. 2011, Sec. 5): ``vdbhair fit``. ``lambda_`` is the\n"
               "command's ``--lambda`` (``lambda`` is a Python keyword).",
               "    strands: a Strands.\n",
               "The scene as a dict (one guide per fitted strand, in input order), which grow() regrows\n"
               "    and ``json.dump`` saves as a scene file; or (scene, report) with return_report.",
               pyb::cpp_function(fitImpl, pyb::arg("strands"), pyb::arg("keywords")));
}

/// interpolate: new hairs from guides (interpolateParameters()).
void defineInterpolate(pyb::module_& m)
{
    auto interpolateImpl = [](const pyb::object& guidesArg, const pyb::object& rootsArg, const pyb::dict& kw) -> pyb::object {
        // Arguments first, as the command checks them.
        InterpolateParams op;
        applyKeywords(interpolateParameters(), kw, op, "interpolate");
        try {
            validateGroomParams(op.groom);  // what the ranges do not say: curl needs a frequency
        } catch (const ValueError& e) {
            throw ValueError(std::string("interpolate: ") + e.what());
        }
        op.returnScene = kw["return_scene"].cast<bool>();
        if (op.returnScene && op.method == InterpolationMethod::Points) throw ValueError("interpolate: return_scene=True needs method='helicoid' (points make strands)");
        op.helicoid.up /= op.helicoid.up.length();  // any non-zero (x, y, z) (checked as declared)
        const InterpolationRoots roots = interpolationRoots(rootsArg, kw, op.frames);
        const HeadArgument headArgument(kw["head"], "no-deeper");
        const bool fromStrands = pyb::isinstance<StrandSet>(guidesArg);
        std::shared_ptr<StrandSet> guideStrands = fromStrands ? guidesArg.cast<std::shared_ptr<StrandSet>>() : nullptr;
        const Scene scene = fromStrands ? Scene() : sceneArgument(guidesArg, "interpolate");
        InterpolationGuides guides;
        guides.where = "interpolate(guides)";
        if (fromStrands) guides.strands = guideStrands.get();
        else guides.scene = &scene;
        const pyb::object guideGroups = kw["guide_groups"];
        if (!guideGroups.is_none() && (pyb::isinstance<pyb::str>(guideGroups) || pyb::hasattr(guideGroups, "__fspath__"))) {
            std::vector<Vec3d> guideRoots;
            if (fromStrands) for (std::size_t i = 0; i < guideStrands->numStrands(); ++i) guideRoots.push_back(Vec3d(guideStrands->root(i)));
            else for (const SceneGuide& g : scene.guides) guideRoots.push_back(g.root);
            guides.groups = readRootIds(pyb::str(guideGroups).cast<std::string>(), guideRoots, "interpolate: guide_groups=", "guides");
        } else if (!guideGroups.is_none()) {
            guides.groups = guideGroups.cast<std::vector<std::int32_t>>();
        }
        HeadObstacle head;
        InterpolateResult result = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            head = headArgument.get("interpolate");
            // None: the scene's head sphere, else a sphere fitted to the guide roots (as the command).
            if (head.unset() && !fromStrands && scene.head) head = HeadObstacle::sphere(scene.head->center, scene.head->radius);
            else if (head.unset() && fromStrands) head = headFromRoots(*guideStrands, op.helicoid.up);
            return interpolateGuides(guides, roots, head, op, true, interrupter);
        });
        // `interpolate --json`'s report (interpolateReport()), less the file name and the clock.
        const pyb::object report = kw["return_report"].cast<bool>() ? toPython(interpolateReport(result, op, head)) : pyb::none();
        const pyb::object out = op.returnScene ? toPython(sceneToJson(result.scene)) : pyb::cast(std::make_shared<StrandSet>(std::move(result.strands)));
        return report.is_none() ? out : pyb::make_tuple(out, report);
    };
    defineVerb(m, "interpolate", {"guides", "roots"}, interpolateParameters(),
               {{"normals", "", pyb::none(), "None, or an (N, 3) array of outward normals at the roots (surface frames, Sec. 4.3)."},
                {"guide_groups", "", pyb::none(),
                 "None, one integer group id per guide (new hairs blend guides of one group), or a spec as the command's "
                 "--guide-groups: a list file, \"mask.vdb[:GRID]\", \"head.ply:PROPERTY\", \"head.obj:islands\"."},
                {"root_groups", "", pyb::none(), "None, one group id per root, or a spec as guide_groups (None: the group of the nearest guide)."},
                {"head", "", pyb::none(),
                 "the head new hair may enter no deeper than its guides: None (the scene's head sphere, else a sphere fitted to the "
                 "guide roots), \"none\", a path (mesh or .vdb level set) or (x, y, z, r)."},
                {"return_scene", "bool", pyb::bool_(false), "return the new hairs as a scene dict (helicoid only) instead of growing them."},
                {"return_report", "bool", pyb::bool_(false),
                 "also return a dict: `interpolate --json`'s report key for key, less the file name, seconds and "
                 "strands_per_second (method, settings, guides, strands, roots, groom controls, the head and the shares passing "
                 "into it and leaving the guides' volume, fit_seconds)."},
                {"density", "", pyb::none(),
                 "None, the share of roots that grow hair in [0, 1]: a number, one value per root, or a spec as the command's "
                 "--density (\"mask.vdb[:GRID]\", \"head.ply:PROPERTY\", a text file)."},
                {"length", "", pyb::none(), "None, the share of each new hair's length kept in [0, 1] (0 grows none), as density."}},
               "New hairs from guide hairs (Piuze et al. 2011, Sec. 4): ``vdbhair interpolate``.",
               "    guides: a Strands (blended as they are; fitted first for method=\"helicoid\"), or a scene (a\n"
               "        path to a scene .json or a dict, as fit() returns).\n"
               "    roots: an (N, 3) array of root positions (world units), or a Strands whose roots are used.\n",
               "Strands (one per root, in order), or the scene dict with return_scene; (either, report) with return_report.",
               pyb::cpp_function(interpolateImpl, pyb::arg("guides"), pyb::arg("roots"), pyb::arg("keywords")));
}

/// reconstruct: a hairstyle rebuilt from a share of its strands (reconstructParameters()).
void defineReconstruct(pyb::module_& m)
{
    auto reconstructImpl = [](const StrandsPtr& strands, const pyb::dict& kw) -> pyb::object {
        ReconstructParams p;
        applyKeywords(reconstructParameters(), kw, p, "reconstruct");
        const HeadArgument headArgument(kw["head"], "no-deeper");
        ReconstructResult r = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            const HeadObstacle head = headArgument.get("reconstruct");
            return reconstructHairstyle(*strands, p, true, interrupter, head.unset() || head.empty() ? nullptr : &head);
        });
        // `reconstruct --json`'s report (reconstructReport()), plus the guides' indices and every
        // strand's error each way as arrays (the command's --errors file).
        pyb::dict report = toPython(reconstructReport(r, p));
        report["guide_strands"] = pyb::array_t<std::int64_t>(r.guides.size(), reinterpret_cast<const std::int64_t*>(r.guides.data()));
        pyb::dict perStrand;
        for (const auto& [way, e] : {std::pair<const char*, const ReconstructErrors*>{"helicoid", &r.helicoidErrors},
                                     {"points", &r.pointErrors}, {"nearest", &r.nearestErrors}}) {
            perStrand[way] = pyb::array_t<double>(e->relative.size(), e->relative.data());
        }
        report["per_strand"] = perStrand;
        return pyb::make_tuple(std::make_shared<StrandSet>(std::move(r.helicoid)), std::make_shared<StrandSet>(std::move(r.points)), report);
    };
    defineVerb(m, "reconstruct", {"strands: vdbhair.Strands"}, reconstructParameters(),
               {{"head", "", pyb::none(),
                 "None or \"none\" (no head), a path (mesh or .vdb level set) or (x, y, z, r): the head the shares of strands "
                 "passing into it are measured against (nothing is moved)."}},
               "Rebuild a hairstyle from a share of its strands (Piuze et al. 2011, Sec. 5.4):\n"
               "``vdbhair reconstruct``. The guides are fitted with p-helicoids and new hairs interpolated at every\n"
               "other root; the same guides' points are blended too (the peers' way), and both are measured\n"
               "against the original by the discrete Frechet distance relative to each strand's length.",
               "    strands: a Strands.\n",
               "(helicoid, points, report): both reconstructions as Strands in input order, and a dict:\n"
               "    ``reconstruct --json``'s report key for key, less the file name and the method written\n"
               "    (strands, guides: their count, unfitted, guide_fraction, select, blend, grouping, fit (mean,\n"
               "    p95, pieces_per_strand, seconds), frechet_relative and measures (oriented_points: None, or per\n"
               "    HairGS threshold distance, distance_mm, angle_degrees, precision, recall, f1,\n"
               "    strand_consistency; perm_position, perm_curvature) for ``helicoid``, ``points`` and\n"
               "    ``nearest`` (the baseline: each strand its nearest guide, translated), meters_per_unit,\n"
               "    leaving_guide_volume, entering_head (None without a head)); plus ``guide_strands`` (the guide\n"
               "    strands' indices) and ``per_strand`` (each way's relative error of every strand).",
               pyb::cpp_function(reconstructImpl, pyb::arg("strands"), pyb::arg("keywords")));
}

/// render: a preview image of strands.
/// vdbhair.render(strands, path=None, **keywords): the declared parameters (renderParameters()), then render's own.
pyb::object renderImpl(const StrandsPtr& strands, const pyb::object& pathArg, const pyb::dict& kw)
{
    RenderParams rp;
    applyKeywords(renderParameters(), kw, rp, "render");
    const std::optional<PathArg> path = pathArg.is_none() ? std::nullopt : std::optional<PathArg>(pathArg.cast<PathArg>());
    // Any non-zero (x, y, z) (checked as declared), as a unit vector.
    rp.up /= rp.up.length();
    if (rp.facing) {
        *rp.facing /= rp.facing->length();
        if (std::abs(rp.facing->dot(rp.up)) > 0.5) throw ValueError("render: facing must be perpendicular to up");
    }
    const bool sheet = rp.sheet;
    const StrandsPtr guides = kw["guides"].cast<StrandsPtr>(), reference = kw["reference"].cast<StrandsPtr>();
    const auto head = kw["head"].cast<std::optional<PathArg>>();
    if (path && !isImagePath(*path)) throw ValueError("render: " + *path + ": not an image format OpenImageIO writes (use .png, .exr or .jpg)");
    TriangleMesh headMesh;
    const Image image = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
        RenderParams p = rp;
        p.interrupter = interrupter;
        if (guides) p.guides = guides.get();
        if (reference) p.reference = reference.get();
        if (head) {
            headMesh = readTriangleMesh(*head);
            if (!headMesh.triangles.empty()) p.head = &headMesh;
        }
        return sheet ? renderSheet(*strands, p) : renderStrands(*strands, p);
    });
    if (path) {
        pyb::gil_scoped_release release;
        writeImage(*path, image);
        return pyb::none();
    }
    // What writeImage stores in a .png, made opaque.
    const std::vector<std::uint8_t> srgb = toSrgb8(image);
    pyb::array_t<std::uint8_t> out({pyb::ssize_t(image.height), pyb::ssize_t(image.width), pyb::ssize_t(4)});
    std::uint8_t* o = out.mutable_data();
    const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) o[4 * i + c] = srgb[3 * i + c];
        o[4 * i + 3] = 255;
    }
    return std::move(out);
}

void defineRender(pyb::module_& m)
{
    defineVerb(m, "render", {"strands: vdbhair.Strands", "path: Optional[os.PathLike | str]=None"}, renderParameters(),
               {{"guides", "Optional[vdbhair.Strands]", pyb::none(), "Strands drawn on top in red."},
                {"head", "Optional[os.PathLike | str]", pyb::none(), "a head mesh (.ply, .obj) drawn behind the hair."},
                {"reference", "Optional[vdbhair.Strands]", pyb::none(),
                 "Strands to measure against, for color_by=\"error\" (each vertex's distance to the nearest vertex of reference, "
                 "0 to its 95th percentile)."}},
               "A preview image of strands: lit fibres, depth-correct, anti-aliased (``vdbhair render``).",
               "    strands: a Strands.\n"
               "    path: write the image there (.png, .jpg: sRGB 8 bits; .exr: linear float) and return None;\n"
               "        None returns the image instead.\n",
               "None with a path; otherwise an (height, width, 4) uint8 RGBA array (sRGB, alpha 255).",
               pyb::cpp_function(renderImpl, pyb::arg("strands"), pyb::arg("path"), pyb::arg("keywords")));
}

/// inspect: a description of every grid of a .vdb file (or of one, grid=), and a slice drawn.
/// vdbhair.inspect(path, **keywords): the declared parameters (inspectParameters()), then the image's path.
pyb::object inspectImpl(const PathArg& path, const pyb::dict& kw)
{
    InspectParams ip;
    applyKeywords(inspectParameters(), kw, ip, "inspect");
    const std::string& grid = ip.grid;
    const std::string& slice = ip.slice;
    const std::string output = kw["output"].is_none() ? std::string() : pathString(kw["output"], "output");
    const SliceParams sp = inspectSlice(ip, output, "inspect");
    std::vector<GridReport> reports;
    std::optional<std::pair<std::string, SliceResult>> drawn;
    runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter*) {
        reports = inspectVdbFile(path, grid);
        if (slice.empty()) return 0;
        const std::string name = chooseSliceGrid(reports, grid, path);
        drawn.emplace(name, renderSlice(path, name, sp));
        writeImage(output, drawn->second.image);
        return 0;
    });
    pyb::list grids;
    for (const GridReport& r : reports) grids.append(toPython(gridReportJson(r)));  // `inspect --json`'s "grids", key for key
    if (!drawn) return std::move(grids);
    // `inspect --json`'s "slice", key for key.
    const SliceResult& res = drawn->second;
    const nlohmann::json j = {{"output", output}, {"grid", drawn->first}, {"axis", std::string(1, char('x' + sp.axis))}, {"world", sp.world},
                              {"index_plane", res.indexPlane}, {"active_voxels", res.activeVoxels}, {"range", {res.lo, res.hi}},
                              {"streamlines", res.streamlinesDrawn}, {"width", res.image.width}, {"height", res.image.height}};
    return pyb::make_tuple(grids, toPython(j));
}

void defineInspect(pyb::module_& m)
{
    defineVerb(m, "inspect", {"path: os.PathLike | str"}, inspectParameters(),
               {{"output", "Optional[os.PathLike | str]", pyb::none(), "the slice image (.png, .exr, .jpg)."}},
               "Describe every grid of a .vdb file (``vdbhair inspect --json``), and draw a slice through one\n"
               "(``inspect --slice AXIS=WORLD -o OUT``): vectors coloured by direction, scalars through a colour\n"
               "map, optionally with streamlines of the in-plane field.",
               "    path: the .vdb file.\n",
               "a list of one dict a grid, in file order: ``inspect --json``'s \"grids\", key for key (name, type,\n"
               "    value_type, class, vector_type, voxel_size, active_voxels, active_tiles, leaf_nodes,\n"
               "    memory_bytes, bbox, metadata, points for points grids, index_bbox, tiles_by_level,\n"
               "    internal_nodes, leaf_fill, length or values (statistics: count, min, max, mean, stddev, p01,\n"
               "    median, p99) or points_per_voxel, unit_share, zero_share, mean_vector and coherence for\n"
               "    vectors, and explanation: the metadata in words). With slice: (that list, a dict of the\n"
               "    slice: ``inspect --json``'s\n"
               "    \"slice\", key for key: output, grid, axis, world, index_plane, active_voxels, range,\n"
               "    streamlines, width, height).",
               pyb::cpp_function(inspectImpl, pyb::arg("path"), pyb::arg("keywords")));
}

/// compare: a hairstyle measured against a reference.
/// vdbhair.compare(a, b, **keywords): the declared parameters (compareParameters()), then compare's own.
pyb::dict compareImpl(const StrandsPtr& a, const StrandsPtr& b, const pyb::dict& kw)
{
    CompareParams p;
    applyKeywords(compareParameters(), kw, p, "compare");
    // The older keywords: the unit in metres, thresholds as (distance in metres, angle) pairs.
    const pyb::object metres = renamedKeywordValue(kw, "unit", "meters_per_unit", "compare");
    if (!kw["meters_per_unit"].is_none()) p.metersPerUnit = metres.cast<double>();
    if (!kw["thresholds"].is_none()) {
        renamedKeywordValue(kw, "threshold", "thresholds", "compare");
        p.thresholds.clear();
        for (const auto& [d, angle] : kw["thresholds"].cast<std::vector<std::pair<double, double>>>())
            p.thresholds.push_back({p.metersPerUnit > 0.0 ? d * 1000.0 : d, angle});  // metres to millimetres
    }
    try {
        p.validate();
    } catch (const ValueError& e) {
        throw ValueError(std::string("compare: ") + e.what());
    }
    const HeadArgument headArgument(kw["head"], "no-deeper");
    const HairComparison c = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter*) {
        const HeadObstacle head = headArgument.get("compare");
        return compareHairstyles(*a, *b, p, head.unset() || head.empty() ? nullptr : &head, true);
    });
    // The report's keys and values are the command line's (toJson()), as Python objects.
    pyb::dict report = toPython(toJson(c));
    pyb::dict perStrand;
    perStrand["chamfer"] = pyb::array_t<double>(c.chamfer.perStrandA.size(), c.chamfer.perStrandA.data());
    if (c.paired) {
        perStrand["position"] = pyb::array_t<double>(c.perm.position.size(), c.perm.position.data());
        perStrand["curvature"] = pyb::array_t<double>(c.perm.curvature.size(), c.perm.curvature.data());
        perStrand["frechet"] = pyb::array_t<double>(c.frechet.size(), c.frechet.data());
    }
    report["per_strand"] = perStrand;
    return report;
}

void defineCompare(pyb::module_& m)
{
    defineVerb(m, "compare", {"a: vdbhair.Strands", "b: vdbhair.Strands"}, compareParameters(),
               {{"meters_per_unit", "Optional[float]", pyb::none(),
                 "deprecated spelling of unit, the unit's length in metres (a DeprecationWarning; removed in the next release)."},
                {"thresholds", "", pyb::none(),
                 "deprecated: (distance in metres with a unit, angle in degrees) pairs; use threshold (a DeprecationWarning; removed in the next "
                 "release)."},
                {"head", "", pyb::none(), "None, a path (a mesh or a .vdb level set) or (x, y, z, r), a sphere."}},
               "Compare a hairstyle ``b`` with a reference ``a`` (``vdbhair compare A B --json``): HairGS's\n"
               "oriented-point precision, recall, F1 and strand consistency, the Chamfer distance, Perm's\n"
               "root-aligned position and curvature errors and the discrete Frechet distance over length of the\n"
               "strand pairs (when the strand counts agree), the share of b's strands leaving a's hair volume, and\n"
               "with a head the shares of each passing into it.",
               "    a: the reference Strands.\n"
               "    b: the compared Strands (precision is the share of its oriented points matched in a).\n",
               "A dict with the command line's JSON keys (strands, vertices, meters_per_unit,\n"
               "    oriented_points, chamfer, paired, position_error, curvature_error, frechet, leaving_volume,\n"
               "    volume_voxel, entering_head) and per_strand: NumPy arrays over a's strands (chamfer; with\n"
               "    paired strands also position, curvature and frechet).",
               pyb::cpp_function(compareImpl, pyb::arg("a"), pyb::arg("b"), pyb::arg("keywords")));
}

} // namespace

void bindOperations(pyb::module_& m)
{
    defineGrow(m);
    defineFit(m);
    defineInterpolate(m);
    defineReconstruct(m);
    defineRender(m);
    defineInspect(m);
    defineCompare(m);
}

} // namespace vdbhair::py
