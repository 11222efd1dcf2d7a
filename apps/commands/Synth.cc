// vdbhair synth EXAMPLE -o OUT: a new hairstyle in the style of an example (Wang et al. 2009,
// §3-5: hierarchical clustering, PCA feature maps and texture optimization, cluster-oriented
// detail transfer, vector-field refinement per level).
#include "../Command.h"
#include "../HeadOptions.h"
#include "../ParamOptions.h"

#include <vdbhair/synth/StyleRegions.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbStrands.h>
#include <vdbhair/render/StrandRenderer.h>
#include <vdbhair/scalp/ScalpInput.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/synth/HairTransfer.h>
#include <vdbhair/synth/Synthesis.h>
#include <vdbhair/synth/SynthJson.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace vdbhair::app {

namespace {

struct SynthCmdParams
{
    std::string input, output, scalp, saveMaps, region, outputScalp, head;
    SynthParams synth;  ///< its declared parameters (synthParameters()) are options
    bool coarseGuides = false;
    std::string coarse;
    const CLI::Option* detailScaleOption = nullptr;     ///< (given or not: --coarse takes transfer's defaults)
    const CLI::Option* matchCandidatesOption = nullptr;
    const CLI::Option* matchPlaceOption = nullptr;
};

/// The first three channels of a feature map as an RGB picture (each channel scaled by the input
/// map's range over its valid pixels; invalid pixels grey), @a zoom pixels per map pixel, v down.
Image mapImage(const FeatureImage& map, const FeatureImage& ref, int zoom)
{
    float lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
        lo[c] = std::numeric_limits<float>::max();
        hi[c] = -lo[c];
    }
    for (int y = 0; y < ref.height; ++y)
        for (int x = 0; x < ref.width; ++x)
            if (ref.isValid(x, y))
                for (int c = 0; c < std::min(3, ref.channels); ++c) {
                    lo[c] = std::min(lo[c], ref.pixel(x, y)[c]);
                    hi[c] = std::max(hi[c], ref.pixel(x, y)[c]);
                }
    Image img(map.width * zoom, map.height * zoom, Vec3f(0.5f));
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            if (!map.isValid(x, y)) continue;
            Vec3f col(0.0f);
            for (int c = 0; c < std::min(3, map.channels); ++c)
                col[c] = hi[c] > lo[c] ? std::clamp((map.pixel(x, y)[c] - lo[c]) / (hi[c] - lo[c]), 0.0f, 1.0f) : 0.5f;
            for (int j = 0; j < zoom; ++j)
                for (int i = 0; i < zoom; ++i) img.set(x * zoom + i, (map.height - 1 - y) * zoom + j, col);
        }
    return img;
}

/// The points of an output region: a .vdb's bool grid 'region' (its active voxels' centres), a
/// PLY of points (no 'strand' element), or the roots of a hairstyle.
std::vector<Vec3d> readRegionPoints(const std::string& path, const CommonOptions& common)
{
    std::vector<Vec3d> out;
    const std::string ext = fileExtension(path);
    if (ext == ".vdb") {
        if (const openvdb::BoolGrid::Ptr region = readScalpRegion(path)) {
            const openvdb::Index64 n = region->activeVoxelCount();
            if (n > (openvdb::Index64(1) << 27)) throw LimitError(path + ": region of " + std::to_string(n) + " voxels, more than the cap of 2^27");
            out.reserve(std::size_t(n));
            for (auto it = region->cbeginValueOn(); it; ++it) {
                if (it.isVoxelValue()) out.push_back(region->transform().indexToWorld(it.getCoord()));
                else throw FormatError(path + ": grid 'region' has active tiles; a region is a set of voxels");
            }
            if (out.empty()) throw ValueError(path + ": grid 'region' is empty: no place for the hair to grow");
            return out;
        }
    }
    if (ext == ".ply" && plyElementCount(path, "vertex") > 0 && plyElementCount(path, "strand") == 0) {
        const OrientedPoints op = readPlyPoints(path);
        for (const Vec3f& v : op.positions) out.emplace_back(v.x(), v.y(), v.z());
    } else {
        const StrandSet s = loadStrandsOrScene("synth", path, common);
        for (std::size_t i = 0; i < s.numStrands(); ++i) out.emplace_back(s.root(i).x(), s.root(i).y(), s.root(i).z());
    }
    if (out.empty()) throw ValueError(path + ": no points: no place for the hair to grow");
    return out;
}

/// The options into @a p.synth, checked before any work.
void checkOptions(SynthCmdParams& p)
{
    strandFormatFromPath(p.output, /*forWriting=*/true);
    if (p.coarseGuides && p.coarse.empty()) throw ValueError("--coarse-guides: needs --coarse FILE");
    checkParamOptions(synthParameters(), p.synth);
    p.synth.validate("option");
}

/// --coarse: an imposed coarsest level, the example's finer levels transferred onto it
/// (HairTransfer.h), run as `vdbhair transfer` runs it.
int runOnCoarse(SynthCmdParams& p, const CommonOptions& common)
{
    if (p.synth.layout != SynthParams{}.layout) throw ValueError("--layout: has no effect with --coarse (the coarsest level is imposed)");
    TransferParams tp;
    // Transfer's defaults for what was not given.
    if (p.detailScaleOption->count() == 0) p.synth.detailScale = tp.synth.detailScale;
    if (p.matchCandidatesOption->count() == 0) p.synth.match.candidates = tp.synth.match.candidates;
    if (p.matchPlaceOption->count() == 0) p.synth.match.place = tp.synth.match.place;
    p.synth.validate("option");
    tp.synth = p.synth;
    tp.synth.strands = 0;  // the output's count is the transfer's, with guides
    tp.guides = p.coarseGuides;
    if (p.synth.strands > 0) {
        if (!p.coarseGuides) throw ValueError("--strands: with --coarse the output has BASE's strands; --strands needs --coarse-guides");
        tp.strands = p.synth.strands;
    }
    TransferJob job{"synth", p.input, p.coarse, p.output, p.scalp, "EXAMPLE", "--coarse"};
    return runTransferJob(job, tp, common);
}

/// The example, and --strands checked against the vertex cap.
StrandSet readExample(SynthCmdParams& p, const CommonOptions& common)
{
    StrandSet example = loadStrands("synth", p.input, common);
    if (example.numStrands() < 2) throw ValueError(p.input + ": " + std::to_string(example.numStrands()) + " strand: synthesis needs an example of many strands");
    if (p.synth.strands > 0) {
        const double estimate = double(p.synth.strands) * p.synth.vertices;
        if (estimate > double(p.synth.maxVertices))
            throw LimitError("--strands " + std::to_string(p.synth.strands) + ": " + formatValue(estimate) + " vertices exceed the cap of " +
                             std::to_string(p.synth.maxVertices));
    }
    return example;
}

/// Where the new hair grows: the points of --region, else of --output-scalp's region grid; none
/// (the example's region) without either. @a regionFrom is set to the file they came from.
std::vector<Vec3d> readOutputRegion(const SynthCmdParams& p, const CommonOptions& common, std::string& regionFrom)
{
    std::vector<Vec3d> region;
    regionFrom = p.region;
    if (regionFrom.empty() && !p.outputScalp.empty()) {
        if (!readScalpRegion(p.outputScalp))
            throw ValueError("--output-scalp " + p.outputScalp + ": no grid 'region' in it: say where the hair grows on it with --region");
        regionFrom = p.outputScalp;
    }
    if (!regionFrom.empty()) {
        const Stage stage(common, "reading " + regionFrom);
        region = readRegionPoints(regionFrom, common);
    }
    return region;
}

/// --output-scalp (and --output-turn): the scalp map of the other head at @a region's points, and
/// that head as the one the hair grows on; null without --output-scalp.
std::shared_ptr<const ScalpMap> outputScalpMap(SynthCmdParams& p, const CommonOptions& common, const std::vector<Vec3d>& region)
{
    std::shared_ptr<const ScalpMap> outputMap;
    if (p.synth.outputTurn != 0.0 && p.outputScalp.empty()) throw ValueError("--output-turn: needs --output-scalp (it turns the layout on the other head)");
    if (!p.outputScalp.empty()) {
        const openvdb::FloatGrid::Ptr other = readScalpOption(p.outputScalp, common);
        std::vector<Vec3f> pts;
        pts.reserve(region.size());
        for (const Vec3d& q : region) pts.emplace_back(q);
        outputMap = scalpMapOfPoints(pts, p.synth.up, other);
        p.synth.head = HeadObstacle::levelSet(other);  // the head the hair grows on
        p.synth.head.setLabel("--output-scalp " + p.outputScalp);
    }
    return outputMap;
}

/// --save-maps: the input and output feature maps, and the output's coarsest clusters rendered a
/// colour each.
void saveMaps(const std::string& folder, const SynthResult& r, const CommonOptions& common)
{
    const Stage stage(common, "writing maps to " + folder);
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) throw IoError(folder + ": cannot create the folder: " + ec.message());
    const int zoom = std::max(1, 400 / std::max(1, std::max(r.grid.width, r.grid.height)));
    writeImage(folder + "/input_map.png", mapImage(r.inputMap, r.inputMap, zoom));
    writeImage(folder + "/output_map.png", mapImage(r.outputMap, r.inputMap, zoom));
    // The output's clusters at the coarsest level, a colour each.
    StrandSet coloured = r.strands;
    coloured.color.resize(coloured.numVertices());
    const std::vector<std::int32_t>& top = r.clusterOf.back();
    for (std::size_t s = 0; s < coloured.numStrands(); ++s)
        for (std::size_t v = coloured.begin(s); v < coloured.end(s); ++v) coloured.color[v] = idColor(std::uint64_t(top[s]));
    RenderParams rp;
    rp.width = rp.height = 800;
    // The world axis nearest the up used (views are named for axis-aligned heads).
    Vec3d axis(0.0);
    const int k = std::abs(r.up.x()) >= std::max(std::abs(r.up.y()), std::abs(r.up.z())) ? 0 : (std::abs(r.up.y()) >= std::abs(r.up.z()) ? 1 : 2);
    axis[k] = r.up[k] < 0.0 ? -1.0 : 1.0;
    rp.up = axis;
    rp.title = "synth: coarsest clusters";
    writeImage(folder + "/clusters.png", renderStrands(coloured, rp));
}

void reportJson(const SynthCmdParams& p, const StrandSet& example, const SynthResult& r, const std::shared_ptr<const ScalpMap>& outputMap,
                const std::string& regionFrom, double seconds, const SynthMeasures& m)
{
    nlohmann::json j = synthReport(example, r, p.synth, outputMap.get(), {p.scalp, regionFrom, p.outputScalp}, m);
    j["output"] = p.output;
    j["example"] = p.input;
    j["seconds"] = seconds;
    printJson(j);
}

void reportText(const SynthCmdParams& p, const StrandSet& example, const SynthResult& r, const std::shared_ptr<const ScalpMap>& outputMap,
                double seconds, const SynthMeasures& m)
{
    const nlohmann::json& stats = m.stats;
    std::cout << "synthesized " << r.strands.numStrands() << " strands from " << example.numStrands() << " in " << seconds << " s\n";
    for (const SynthStage& s : r.stages) std::cout << "  " << s.name << ": " << s.seconds << " s\n";
    for (std::size_t l = r.output.size(); l-- > 0;)
        std::cout << "  level " << l << ": example " << r.example.levels[l].count() << ", output " << r.output[l].count() << "\n";
    std::cout << "  length distance " << stats["length_distance"] << ", turning distance " << stats["turning_distance"]
              << ", coherence " << stats["coherence"]["output"] << " (example " << stats["coherence"]["example"] << ")"
              << ", copies " << stats["novelty"]["copies"] << "\n";
    if (r.head != "none") {
        char shares[128];
        std::snprintf(shares, sizeof shares, "%.1f %% of the output", 100.0 * double(r.enteringHead) / double(std::max<std::size_t>(1, r.strands.numStrands())));
        std::cout << "  head: " << r.head << " (no new vertex deeper than its root); " << r.headPushedOut << " strands pushed out; passing into it: " << shares;
        if (!outputMap) {
            std::snprintf(shares, sizeof shares, ", %.1f %% of the example", 100.0 * double(r.exampleEnteringHead) / double(example.numStrands()));
            std::cout << shares;
        }
        std::cout << "\n";
    }
    std::cout << "  by region, output (example):\n" << m.regionText;
    if (m.measured) std::cout << "  compared with the example (vdbhair compare): " << summaryLine(m.comparison) << "\n";
    std::cout << "wrote " << p.output << "\n";
}

int runSynth(SynthCmdParams p, const CommonOptions& common)
{
    checkOptions(p);
    if (!p.coarse.empty()) return runOnCoarse(p, common);
    const StrandSet example = readExample(p, common);
    const openvdb::FloatGrid::Ptr scalp = readScalpOption(p.scalp, common);
    std::string regionFrom;
    const std::vector<Vec3d> region = readOutputRegion(p, common, regionFrom);
    const std::shared_ptr<const ScalpMap> outputMap = outputScalpMap(p, common, region);
    p.synth.head = headFromOptions(HeadOptions{p.head}, p.synth.head);

    const auto t0 = std::chrono::steady_clock::now();
    const SynthResult r = synthesizeHair(example, p.synth, scalp, true, common.interrupter, regionFrom.empty() ? nullptr : &region, outputMap);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    {
        const Stage stage(common, "writing " + p.output);
        writeSynthStrands(p.output, r.strands, r.clusterOf);
    }
    if (!p.saveMaps.empty()) saveMaps(p.saveMaps, r, common);
    // The statistics (two tangent fields and a nearest-strand search: a sixth of a large synthesis)
    // are only what the report prints; --quiet without --json prints nothing.
    if (common.quiet && !common.json) return 0;
    SynthMeasures m;
    {
        const Stage stage(common, p.synth.measure ? "measuring the output, comparing with the example" : "measuring the output");
        m = measureSynthesis(example, r, p.synth, outputMap.get(), p.synth.measure);
    }
    if (common.json) reportJson(p, example, r, outputMap, regionFrom, seconds, m);
    else reportText(p, example, r, outputMap, seconds, m);
    return 0;
}

} // namespace

void writeSynthStrands(const std::string& path, const StrandSet& strands, const std::vector<std::vector<std::int32_t>>& clusterOf)
{
    if (fileExtension(path) == ".vdb") {
        // Points carry each strand's cluster at every coarser level (cluster_level_1, ...).
        VdbPointsOptions vo;
        for (std::size_t l = 0; l < clusterOf.size(); ++l)
            vo.strandAttributes.emplace_back("cluster_level_" + std::to_string(l + 1), clusterOf[l]);
        writeVdbStrands(path, strands, vo);
    } else {
        writeStrands(path, strands);
    }
}

/// synth's help for the options whose default `synth --coarse` takes from transfer (runOnCoarse()).
void noteTransferDefaults(CLI::App* sub)
{
    for (const char* name : {"detail-scale", "match-candidates", "match-place"}) {
        CLI::Option* o = sub->get_option(std::string("--") + name);
        o->description(o->get_description() + "; with --coarse: " + findParam(transferParameters(), name)->defaultText() + ", as transfer");
    }
}

Command addSynthCommand(CLI::App& app, CommonOptions& common)
{
    auto params = std::make_shared<SynthCmdParams>();
    CLI::App* sub = addVerb(app, "synth");
    sub->add_option("example", params->input, "The example hairstyle (any strand format)")->required();
    sub->add_option("-o,--output", params->output, "The new hairstyle (any strand format; .vdb points also carry int cluster_level_1.. attributes)")->required();
    sub->add_option("--scalp", params->scalp, "The scalp: a .vdb with a level set 'surface' (vdbhair scalp) or a head mesh (.ply, .obj); default: the sphere fitted to the roots");
    addParamOptions(sub, params->synth, synthParameters());
    noteTransferDefaults(sub);
    params->detailScaleOption = sub->get_option("--detail-scale");
    params->matchCandidatesOption = sub->get_option("--match-candidates");
    params->matchPlaceOption = sub->get_option("--match-place");
    sub->add_option("--region", params->region, "Where the new hair grows (default: the example's region): a scalp .vdb's 'region' grid (vdbhair scalp --region...), roots (.ply points, as vdbhair roots writes) or the roots of a hairstyle; the strand count scales with the area");
    sub->add_option("--head", params->head, "The head new hair may enter no deeper than the example's hair: a mesh (.ply, .obj), a .vdb level set, or 'none' "
                                             "(default: --output-scalp's, else --scalp's surface, else the sphere fitted to the roots)");
    sub->add_option("--output-scalp", params->outputScalp, "Grow the new hair on another head: a scalp .vdb (its 'region' grid is where the hair grows, unless --region says) or a head mesh with --region; the hairstyle moves there through scalp space");
    sub->add_option("--coarse", params->coarse, "Impose a coarsest level instead of synthesizing one (Wang et al. §6): BASE's own coarsest level (a hairstyle, or a scene grown first); the example's finer levels are transferred onto it, on BASE's scalp, with BASE's roots (as vdbhair transfer EXAMPLE BASE)");
    sub->add_flag("--coarse-guides", params->coarseGuides, "With --coarse: BASE's strands are the coarsest level as they are (a few guides); finer roots are spread over the guides' region (--strands sets the output count)");
    sub->add_option("--save-maps", params->saveMaps, "Write input_map.png, output_map.png (first three PCA channels as RGB) and clusters.png to this folder");
    addCommonOptions(sub, common);
    addReadOptions(sub, common);
    sub->footer("Example: vdbhair synth example.hair -o new.hair --levels 3 --seed 1 --json");
    return {sub, [params, &common] { return runSynth(*params, common); }};
}

} // namespace vdbhair::app
