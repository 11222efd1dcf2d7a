#include "Synthesis.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/synth/DetailTransfer.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/synth/RootScatter.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace vdbhair {

SynthLayout synthLayoutFromName(const std::string& name)
{
    if (name == "example") return SynthLayout::Example;
    if (name == "synthesize") return SynthLayout::Synthesize;
    throw ValueError("layout '" + name + "' is not one of example, synthesize");
}

const char* synthLayoutName(SynthLayout layout) { return layout == SynthLayout::Example ? "example" : "synthesize"; }

void SynthParams::validate(const char* where) const
{
    const auto fail = [&](const char* field, const std::string& value, const std::string& rule) {
        throw ValueError(std::string(where) + ": " + field + (value.empty() ? "" : " " + value) + ": " + rule);
    };
    if (vertices < 4 || vertices > 4096) fail("vertices", std::to_string(vertices), "must be between 4 and 4096");
    if (components < 1) fail("components", std::to_string(components), "must be at least 1");
    if (!(mapSpacing >= 1e-3 && mapSpacing <= 0.5)) fail("mapSpacing", formatNumber(mapSpacing), "must be between 0.001 and 0.5 radians");
    if (!(strandScale > 0.0) || !std::isfinite(strandScale)) fail("strandScale", formatNumber(strandScale), "must be a positive finite factor");
    if (rootIterations < 0 || rootIterations > 1000) fail("rootIterations", std::to_string(rootIterations), "must be between 0 and 1000");
    if (!(voxelSize >= 0.0) || !std::isfinite(voxelSize)) fail("voxelSize", formatNumber(voxelSize), "must be 0 (suggested) or a positive finite length");
    if (!std::isfinite(up.length())) fail("up", "", "must be a finite vector (or 0 for the roots' mean direction)");
    if (!std::isfinite(outputTurn)) fail("outputTurn", formatNumber(outputTurn), "must be a finite angle");
    if (!(placeWeight >= 0.0) || !std::isfinite(placeWeight)) fail("placeWeight", formatNumber(placeWeight), "must be 0 or a positive finite weight");
    cluster.validate(where);
    texture.validate(where);
    match.validate(where);
}

namespace {

using SP = SynthParams;

/// The hierarchy's parameters (Clustering.h): shared by synth, transfer and comb.
void addHierarchyParams(ParamTable<SP>& t)
{
    auto levels = makeParam<SP>("levels", "Levels of the hierarchy, the strands included (the paper: 2 for simple styles, 3 otherwise)", "",
                                member<SP>([](SP& p) -> int& { return p.cluster.levels; }));
    levels.min = 2;
    levels.max = 5;
    t.push_back(levels);
    t.push_back(makeParam<SP>("seed", "Random seed (clustering seeds, texture initialization, roots)", "",
                              member<SP>([](SP& p) -> std::uint64_t& { return p.seed; })));
    auto vertices = makeParam<SP>("vertices", "Vertices per strand, n_s (Table 1)", "", member<SP>([](SP& p) -> int& { return p.vertices; }));
    vertices.min = 4;
    vertices.max = 4096;
    t.push_back(vertices);
    auto threshold = makeParam<SP>("threshold", "Adaptive clustering threshold epsilon, L2 over n_s vertices (Table 1: 0.1-0.3)", "head radii squared",
                                   member<SP>([](SP& p) -> double& { return p.cluster.threshold; }));
    threshold.min = 0.0;
    threshold.aboveMin = true;
    t.push_back(threshold);
    auto initial = makeParam<SP>("initial-clusters", "k0 of adaptive clustering", "", member<SP>([](SP& p) -> int& { return p.cluster.initialClusters; }));
    initial.min = 1;
    t.push_back(initial);
}

/// The coarsest level's feature map and roots (synth only: transfer and comb keep a coarsest level).
void addLayoutParams(ParamTable<SP>& t)
{
    auto spacing = makeParam<SP>("map-spacing", "Feature-map pixel spacing in scalp (u, v)", "radians", member<SP>([](SP& p) -> double& { return p.mapSpacing; }));
    spacing.min = 1e-3;
    spacing.max = 0.5;
    t.push_back(spacing);
    auto layout = makeParam<SP>("layout", "The coarsest level's feature map: synthesize (texture optimization, the paper) or example (the example's own map: "
                                          "a variation that keeps its global flow exactly)", "",
                                named<SP>([](SP& p) -> SynthLayout& { return p.layout; }, synthLayoutName, synthLayoutFromName));
    layout.choices = {"synthesize", "example"};
    t.push_back(layout);
    auto weight = makeParam<SP>("place-weight", "Texture synthesis: how strongly a map pixel keeps content from near its own place", "",
                                member<SP>([](SP& p) -> double& { return p.placeWeight; }));
    weight.min = 0.0;
    weight.zeroMeans = "Kwatra's unguided synthesis";
    t.push_back(weight);
    auto nearby = makeParam<SP>("nearby", "Texture synthesis: the reach of place guidance and of the initial patches' offsets, as a fraction of the map", "",
                                member<SP>([](SP& p) -> double& { return p.texture.nearbyRadius; }));
    nearby.min = 0.0;
    nearby.max = 1.0;
    t.push_back(nearby);
    // exampleDensity as the word a person types.
    auto density = makeParam<SP>("root-density", "New roots where the example's are (example: each drawn around one of the example's roots, so every "
                                                 "region keeps its share; on another --region, at the example's density) or evenly over the region "
                                                 "(even: the paper's)", "",
                                 ParamAccess<SP, std::string>{[](const SP& p) { return std::string(p.exampleDensity ? "example" : "even"); },
                                                              [](SP& p, std::string v) { p.exampleDensity = v == "example"; }});
    density.choices = {"example", "even"};
    t.push_back(density);
    auto frame = makeParam<SP>("map-frame", "The coarsest level's wisps in the feature map: head (offsets along the head's axes: a wisp placed higher or "
                                            "lower on the head hangs as it did) or root (in each root's scalp frame, the paper's: a long wisp placed "
                                            "higher on the head tilts outward with the scalp)", "",
                               ParamAccess<SP, std::string>{[](const SP& p) { return std::string(p.mapInHeadAxes ? "head" : "root"); },
                                                            [](SP& p, std::string v) { p.mapInHeadAxes = v == "head"; }});
    frame.choices = {"head", "root"};
    t.push_back(frame);
}

/// Detail transfer and refinement (DetailTransfer.h, §5.2-5.3): shared by synth and transfer.
void addDetailParams(ParamTable<SP>& t)
{
    auto components = makeParam<SP>("components", "PCA components of the feature maps and of cluster matching, n_f", "",
                                    member<SP>([](SP& p) -> int& { return p.components; }));
    components.min = 1;
    t.push_back(components);
    auto detail = makeParam<SP>("detail", "Detail transfer: edges (each strand's own edges re-laid along the output centre: curls keep their turning), "
                                          "root-frame (displacements in the centre's root frame) or paper (Eq. 7: blended to rotation-minimizing "
                                          "frames toward the tip)", "",
                                named<SP>([](SP& p) -> DetailBlend& { return p.detailBlend; }, detailBlendName, detailBlendFromName));
    detail.choices = {"edges", "root-frame", "paper"};
    t.push_back(detail);
    auto scale = makeParam<SP>("detail-scale", "How detail is laid along a longer or shorter centre: strand (each strand at its own length and pitch), "
                                               "index (vertex by vertex, the paper's: curls stretch with the length) or arc-length (curls keep their "
                                               "size, repeated along a longer wisp)", "",
                               named<SP>([](SP& p) -> DetailScale& { return p.detailScale; }, detailScaleName, detailScaleFromName));
    scale.choices = {"strand", "index", "arc-length"};
    t.push_back(scale);
    // 0 or at least 1, which a range cannot say: DetailMatchParams::validate() checks it.
    auto balance = makeParam<SP>("match-balance", "Each example wisp serves output wisps of at most this times its own share of the output's strands (its "
                                                  "part of the example's), and each example strand at most this times its even share of its output "
                                                  "wisp's, pairs taken by increasing distance at one scale: 0 or a factor of at least 1", "",
                                 member<SP>([](SP& p) -> double& { return p.match.balance; }));
    balance.zeroMeans = "every output wisp takes its nearest, the paper's rule";
    t.push_back(balance);
    auto candidates = makeParam<SP>("match-candidates", "Example wisps considered per output wisp in balanced matching, nearest first", "",
                                    member<SP>([](SP& p) -> int& { return p.match.candidates; }));
    candidates.min = 1;
    t.push_back(candidates);
    auto place = makeParam<SP>("match-place", "How much an output wisp prefers example wisps near its own place on the scalp, against their shape", "",
                               member<SP>([](SP& p) -> double& { return p.match.place; }));
    place.min = 0.0;
    place.zeroMeans = "by shape alone, the paper's rule";
    t.push_back(place);
    auto mode = makeParam<SP>("refine-mode", "Refinement after each level: consistent (keeps detail) or field (the paper's retrace)", "",
                              named<SP>([](SP& p) -> RefineMode& { return p.refineMode; }, refineModeName, refineModeFromName));
    mode.choices = {"consistent", "field"};
    t.push_back(mode);
    auto voxel = makeParam<SP>("voxel-size", "Refinement voxel of the finest level, doubled per coarser level", "world units",
                               member<SP>([](SP& p) -> double& { return p.voxelSize; }));
    voxel.min = 0.0;
    voxel.zeroMeans = findParam(fieldParameters(), "voxel-size")->zeroMeans;  // suggestVoxelSize(), as refine's
    t.push_back(voxel);
}

/// What a run takes besides: the output's count, refinement, the axes, the output turn, measuring.
void addRunParams(ParamTable<SP>& t)
{
    auto strands = makeParam<SP>("strands", "Strands in the output (every level scales alike)", "", member<SP>([](SP& p) -> std::size_t& { return p.strands; }));
    strands.min = 0;
    strands.zeroMeans = "the example's density over the region";
    strands.pythonNone = true;
    t.push_back(strands);
    t.push_back(makeParam<SP>("refine", "Refine every level (Wang et al. §5.3)", "", member<SP>([](SP& p) -> bool& { return p.refine; })));
    t.push_back(makeAxisParam<SP>("up", "The scalp's up axis", [](SP& p) -> Vec3d& { return p.up; },
                                  "the mean direction from the head's centre to the roots"));
    t.push_back(makeAxisParam<SP>("front", "The head's front for the report by region", [](SP& p) -> Vec3d& { return p.front; },
                                  "where the hairline is highest"));
    // Degrees in both front ends, radians in the library.
    t.push_back(makeParam<SP>("output-turn", "With an output scalp: the turn about the up axis of the layout on the other head (heads that face "
                                             "different ways)", "degrees",
                              ParamAccess<SP, double>{[](const SP& p) { return p.outputTurn * 180.0 / M_PI; },
                                                      [](SP& p, double v) { p.outputTurn = v * M_PI / 180.0; }}));
    t.push_back(makeParam<SP>("measure", "Also compare the output with the example as `vdbhair compare` does (the report's \"compare\"; on another "
                                         "head, the output moved back onto the example's scalp): about 1-3 s more at 100,000 strands", "",
                              member<SP>([](SP& p) -> bool& { return p.measure; })));
}

} // namespace

const ParamTable<SynthParams>& synthParameters()
{
    static const ParamTable<SynthParams> table = [] {
        ParamTable<SynthParams> t;
        addHierarchyParams(t);
        addLayoutParams(t);
        addDetailParams(t);
        addRunParams(t);
        return t;
    }();
    return table;
}

namespace {

FeatureImage filledFeatureImage(const FeatureImage& in)
{
    // Breadth-first from the valid pixels, 4-neighbours, in index order: every invalid pixel takes
    // the value of the nearest valid one (in steps) and counts as valid.
    const int C = in.channels;
    FeatureImage filled = in;
    std::vector<std::size_t> queue;
    std::vector<std::uint8_t> done(in.pixelCount(), 0);
    for (std::size_t i = 0; i < in.pixelCount(); ++i)
        if (in.isValid(int(i % std::size_t(in.width)), int(i / std::size_t(in.width)))) {
            done[i] = 1;
            queue.push_back(i);
        }
    for (std::size_t head = 0; head < queue.size(); ++head) {
        const int x = int(queue[head] % std::size_t(in.width)), y = int(queue[head] / std::size_t(in.width));
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k) {
            if (nx[k] < 0 || ny[k] < 0 || nx[k] >= in.width || ny[k] >= in.height) continue;
            const std::size_t j = std::size_t(ny[k]) * in.width + nx[k];
            if (done[j]) continue;
            done[j] = 1;
            std::copy_n(filled.pixel(x, y), C, filled.pixel(nx[k], ny[k]));
            queue.push_back(j);
        }
    }
    std::fill(filled.valid.begin(), filled.valid.end(), std::uint8_t(1));
    return filled;
}

/// The output region in scalp space (empty without one). On another scalp, each point's (u, v)
/// is turned back by @a outputTurn (moveToScalp turns the hairstyle forward at the end).
std::vector<Vec3d> regionInScalpSpace(const std::vector<Vec3d>* outputRegion, const ScalpMap* outputScalp, const ScalpMap& map,
                                      double outputTurn)
{
    std::vector<Vec3d> regionUv;
    if (!outputRegion) return regionUv;
    regionUv.reserve(outputRegion->size());
    const double c = std::cos(outputTurn), sn = std::sin(outputTurn);
    const ScalpSphere unit;
    for (const Vec3d& p : *outputRegion) {
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) throw ValueError("synthesizeHair: a point of the output region is not finite");
        Vec3d uvw = outputScalp ? outputScalp->toScalp(p) : map.toScalp(p);
        if (outputScalp && outputTurn != 0.0) {
            const Vec3d d = scalpToWorld(unit, Vec3d(uvw.x(), uvw.y(), 0.0));
            uvw = worldToScalp(unit, Vec3d(c * d.x() - sn * d.z(), d.y(), sn * d.x() + c * d.z()));
        }
        regionUv.push_back(uvw);
    }
    return regionUv;
}

/// The rows of @a samples as the feature map holds them: when @a headAxes, along the world's axes,
/// one frame for every root (the head's, which does not turn), so a wisp keeps its direction
/// wherever the map reads it; else as they are, in each root's frame.
/// Each vertex of @a row (@a vertices of them, x y z) replaced by @a turn of it.
template <typename Turn>
void turnRow(float* row, int vertices, Turn turn)
{
    for (int v = 0; v < vertices; ++v) {
        float* q = row + 3 * v;
        const Vec3d t = turn(Vec3d(q[0], q[1], q[2]));
        q[0] = float(t.x());
        q[1] = float(t.y());
        q[2] = float(t.z());
    }
}

std::vector<float> mapRows(const StrandSamples& samples, bool headAxes)
{
    std::vector<float> rows(samples.local.begin(), samples.local.end());
    if (!headAxes) return rows;
    for (std::size_t s = 0; s < samples.count(); ++s)
        turnRow(rows.data() + s * samples.dim(), samples.vertices, [&](const Vec3d& q) { return samples.frames[s].toWorld(q); });
    return rows;
}

/// Step 4, the feature maps: the coarsest level's PCA, the uv grid around the example (and the
/// output region), the example's feature map and, with an output region, its mask. Returns the
/// output region's area over the example's (1 without a region).
double buildFeatureMaps(SynthResult& res, const SynthParams& params, const std::vector<Vec3d>& regionUv, bool hasRegion,
                        std::vector<std::uint8_t>& outputMask)
{
    const StrandSamples& finest = res.example.levels.front();
    const StrandSamples& coarsest = res.example.levels.back();
    const std::vector<float> rows = mapRows(coarsest, params.mapInHeadAxes);
    res.pca = fitPca(rows.data(), coarsest.count(), coarsest.dim(), params.components);
    const int nf = res.pca.components;
    std::vector<float> features(coarsest.count() * std::size_t(nf));
    for (std::size_t s = 0; s < coarsest.count(); ++s) res.pca.project(rows.data() + s * coarsest.dim(), features.data() + s * std::size_t(nf));
    std::vector<Vec3d> covered = finest.scalp;
    covered.insert(covered.end(), regionUv.begin(), regionUv.end());
    res.grid = uvGridAround(covered, params.mapSpacing);
    const double maskRadius = std::max(params.mapSpacing, 2.0 * medianUvSpacing(finest.scalp));
    res.inputMap = buildFeatureMap(res.grid, coarsest.scalp, features.data(), nf, finest.scalp, maskRadius);
    if (!hasRegion) return 1.0;
    outputMask = uvMask(res.grid, regionUv, std::max(params.mapSpacing, 2.0 * medianUvSpacing(regionUv)));
    FeatureImage mask(res.grid.width, res.grid.height, 1);
    mask.valid = outputMask;
    const double exampleArea = regionArea(*res.map, res.grid, res.inputMap), outputArea = regionArea(*res.map, res.grid, mask);
    if (!(outputArea > 0.0)) throw ValueError("synthesizeHair: the output region covers no pixel of the feature map");
    res.outputArea = outputArea;
    return exampleArea > 0.0 ? outputArea / exampleArea : 1.0;
}

/// Output strands per level (the example's density over the output region), checked against
/// the vertex cap before any output is made.
std::vector<std::size_t> outputCounts(const ClusterHierarchy& example, const SynthParams& params, double areaRatio)
{
    const int L = params.cluster.levels;
    const double scale = params.strands > 0 ? double(params.strands) / double(example.levels.front().count()) : params.strandScale * areaRatio;
    std::vector<std::size_t> counts(static_cast<std::size_t>(L));
    for (int l = 0; l < L; ++l)
        counts[std::size_t(l)] = std::max<std::size_t>(1, std::size_t(std::llround(double(example.levels[std::size_t(l)].count()) * scale)));
    if (double(counts[0]) * params.vertices > double(params.maxVertices))
        throw LimitError("synthesizeHair: " + std::to_string(counts[0]) + " strands of " + std::to_string(params.vertices) +
                         " vertices exceed the cap of " + std::to_string(params.maxVertices) + " vertices");
    return counts;
}

/// The output feature map by texture optimization of the example's, with two guidance channels
/// holding each pixel's own place (see SynthParams::placeWeight). The output region is the
/// example's.
FeatureImage synthesizeFeatureMap(SynthResult& res, const SynthParams& params, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    TextureParams tp = params.texture;
    tp.seed = params.seed;
    const FeatureImage& in = res.inputMap;
    const int C = in.channels, G = params.placeWeight > 0.0 ? 2 : 0;
    double variance = 0.0;
    std::size_t valid = 0;
    for (int y = 0; y < in.height; ++y)
        for (int x = 0; x < in.width; ++x)
            if (in.isValid(x, y)) {
                ++valid;
                for (int ch = 0; ch < C; ++ch) variance += double(in.pixel(x, y)[ch]) * in.pixel(x, y)[ch];
            }
    const double sigma = valid ? std::sqrt(variance / double(valid)) : 1.0;
    const double reach = std::max(1.0, tp.nearbyRadius * double(std::max(in.width, in.height)));
    const float scale = float(params.placeWeight * (sigma > 0.0 ? sigma : 1.0) / reach);
    // The example's invalid pixels take the value of the nearest valid one (breadth-first
    // from the valid pixels, 4-neighbours, in index order) and count as valid: output windows
    // at the region's edge then match windows that continue the edge outward instead of
    // windows from inside, which averaged the edge's extremes away.
    const FeatureImage filled = filledFeatureImage(in);
    FeatureImage guided(in.width, in.height, C + G);
    for (int y = 0; y < in.height; ++y)
        for (int x = 0; x < in.width; ++x) {
            std::copy_n(filled.pixel(x, y), C, guided.pixel(x, y));
            if (G) {
                guided.pixel(x, y)[C] = float(x) * scale;
                guided.pixel(x, y)[C + 1] = float(y) * scale;
            }
        }
    const FeatureImage out = synthesizeTexture(guided, res.grid.width, res.grid.height, tp, &res.texture, threaded, interrupter);
    FeatureImage outputMap(out.width, out.height, C);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) std::copy_n(out.pixel(x, y), C, outputMap.pixel(x, y));
    outputMap.valid = in.valid;
    return outputMap;
}

/// Roots of output level @a l, scattered over the output map: its own random stream per level.
/// @param exampleRegion whether the output grows on the example's own region
ScatteredRoots scatterLevelRoots(const SynthResult& res, const SynthParams& params, std::size_t count, int l, bool exampleRegion,
                                 bool threaded)
{
    RootScatterParams rp;
    rp.count = count;
    rp.iterations = params.rootIterations;
    rp.seed = params.seed;
    rp.stream = std::uint64_t(l);
    if (!params.exampleDensity) return scatterRoots(*res.map, res.grid, res.outputMap, rp, threaded);
    // On the example's region, around the example's own roots of this level; on another region,
    // at their density per pixel, pixels outside the example's region taking the nearest region
    // pixel's density.
    if (exampleRegion) return scatterAroundRoots(*res.map, res.grid, res.outputMap, res.example.levels[std::size_t(l)].scalp, rp, threaded);
    const FeatureImage density = filledFeatureImage(rootDensity(res.grid, res.example.levels[std::size_t(l)].scalp, res.inputMap));
    return scatterRoots(*res.map, res.grid, res.outputMap, rp, threaded, &density);
}

/// Step 5, the coarsest level from the synthesized map: at each root, the PCA reconstruction of
/// the nearest feature (turned from the map's axes into the root's frame), its root at the root.
void synthesizeCoarsestLevel(SynthResult& res, const SynthParams& params, const ScatteredRoots& roots)
{
    const ScalpMap& map = *res.map;
    const double radius = map.radius();
    const StrandSamples& coarsest = res.example.levels.back();
    StrandSamples& level = res.output.back();
    level.vertices = params.vertices;
    std::vector<float> f(std::size_t(res.pca.components)), row(coarsest.dim());
    for (std::size_t i = 0; i < roots.positions.size(); ++i) {
        if (!nearestFeature(res.outputMap, res.grid, roots.scalp[i].x(), roots.scalp[i].y(), f.data()))
            throw ValueError("synthesizeHair: the output feature map has no valid pixel");
        res.pca.reconstruct(f.data(), row.data());
        const ScalpFrame frame = map.frame(roots.scalp[i].x(), roots.scalp[i].y());
        if (params.mapInHeadAxes) turnRow(row.data(), params.vertices, [&](const Vec3d& q) { return frame.toLocal(q); });
        row[0] = row[1] = row[2] = 0.0f;  // the root is the root
        double len = 0.0;
        for (int v = 1; v < params.vertices; ++v)
            len += std::sqrt(double(row[3 * v] - row[3 * v - 3]) * (row[3 * v] - row[3 * v - 3]) +
                             double(row[3 * v + 1] - row[3 * v - 2]) * (row[3 * v + 1] - row[3 * v - 2]) +
                             double(row[3 * v + 2] - row[3 * v - 1]) * (row[3 * v + 2] - row[3 * v - 1]));
        level.push(row.data(), roots.positions[i], roots.scalp[i], frame,
                   float(len * radius));
    }
}

} // namespace

SynthStageTimer::~SynthStageTimer()
{
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (SynthStage& st : stages)
        if (st.name == name) {
            st.seconds += s;
            return;
        }
    stages.push_back({name, s});
}

ClusterHierarchy hairHierarchy(const StrandSet& strands, const ScalpMap& map, const SynthParams& params, bool threaded,
                               openvdb::util::NullInterrupter* interrupter, std::vector<std::uint32_t>* orderOut)
{
    // In spatial order (Measures.h): clustering walks the root graph, and neighbours near in
    // memory are what makes it fast (100,000 jittered strands in file order: 3.4 s).
    const std::vector<std::uint32_t> order = spatialOrder(strands);
    StrandSamples samples = sampleStrands(strands, map, params.vertices, threaded, &order);
    ClusterParams cp = params.cluster;
    cp.seed = params.seed;
    if (orderOut) *orderOut = order;
    return buildHierarchy(std::move(samples), map, cp, interrupter);
}

SynthResult synthesizeHair(const StrandSet& example, const SynthParams& params, openvdb::FloatGrid::ConstPtr scalp,
                           bool threaded, openvdb::util::NullInterrupter* interrupter, const std::vector<Vec3d>* outputRegion,
                           std::shared_ptr<const ScalpMap> outputScalp)
{
    params.validate("synthesizeHair");
    if (outputRegion && outputRegion->empty()) throw ValueError("synthesizeHair: the output region has no points");
    if (outputScalp && !outputRegion) throw ValueError("synthesizeHair: another scalp for the output needs the region the hair grows in on it");
    const int L = params.cluster.levels;
    SynthResult res;
    // 1. Scalp space.
    {
        SynthStageTimer t{res.stages, "scalp"};
        res.map = hairScalpMap(example, params.up, scalp, &res.up);
    }
    // 2-3. Samples and the example's hierarchy.
    {
        SynthStageTimer t{res.stages, "clustering"};
        res.example = hairHierarchy(example, *res.map, params, threaded, interrupter);
    }
    // The output region in scalp space (the example's when none is given).
    const std::vector<Vec3d> regionUv = regionInScalpSpace(outputRegion, outputScalp.get(), *res.map, params.outputTurn);
    // 4. Feature maps.
    std::vector<std::uint8_t> outputMask;
    double areaRatio = 1.0;
    {
        SynthStageTimer t{res.stages, "feature maps"};
        areaRatio = buildFeatureMaps(res, params, regionUv, outputRegion != nullptr, outputMask);
    }
    const std::vector<std::size_t> counts = outputCounts(res.example, params, areaRatio);
    {
        SynthStageTimer t{res.stages, "texture optimization"};
        if (params.layout == SynthLayout::Example) {
            res.outputMap = outputRegion ? filledFeatureImage(res.inputMap) : res.inputMap;
        } else {
            res.outputMap = synthesizeFeatureMap(res, params, threaded, interrupter);
        }
    }
    if (outputRegion) res.outputMap.valid = outputMask;
    // 5. The coarsest level from the synthesized map.
    res.output.resize(std::size_t(L));
    {
        SynthStageTimer t{res.stages, "coarsest level"};
        synthesizeCoarsestLevel(res, params, scatterLevelRoots(res, params, counts[std::size_t(L - 1)], L - 1, !outputRegion, threaded));
    }
    // 6-7. Finer levels, refined from the coarsest on.
    const double finestVoxel = params.voxelSize > 0.0 ? params.voxelSize : suggestVoxelSize(example);
    // Refined on the example's scalp: another head's obstacle (the output's) is not the one there.
    SynthParams onExample = params;
    if (outputScalp) onExample.head = HeadObstacle();
    const auto rootsOf = [&](int l) { return LevelRoots{scatterLevelRoots(res, params, counts[std::size_t(l)], l, !outputRegion, threaded).positions, {}}; };
    synthesizeFinerLevels(res, res.example, rootsOf, onExample, finestVoxel, /*refineCoarsest=*/true, scalp, threaded, interrupter);
    if (outputScalp) res.strands = moveToScalp(res.strands, *res.map, *outputScalp, params.outputTurn, threaded);
    keepHairOutOfHead(res, synthesisHead(params, scalp, outputScalp != nullptr, example, res.up), outputScalp ? nullptr : &example, threaded);
    return res;
}

void synthesizeFinerLevels(SynthResult& res, const ClusterHierarchy& source,
                           const std::function<LevelRoots(int level)>& rootsOf, const SynthParams& params,
                           double finestVoxel, bool refineCoarsest, openvdb::FloatGrid::ConstPtr scalp, bool threaded,
                           openvdb::util::NullInterrupter* interrupter, int outputVertices)
{
    const int L = int(source.levels.size());
    if (L < 2 || res.output.size() != std::size_t(L) || res.output.back().count() == 0 || !res.map)
        throw ValueError("synthesizeFinerLevels: the coarsest output level and the scalp map must be set for " +
                         std::to_string(L) + " levels");
    const ScalpMap& map = *res.map;
    const double radius = map.radius();
    res.refinedCorrected.assign(std::size_t(L), 0);
    res.refineVoxelSizes.assign(std::size_t(L), 0.0);
    for (int l = 0; l < L; ++l) res.refineVoxelSizes[std::size_t(l)] = finestVoxel * double(1 << l);
    // The head the output is kept out of (SynthParams::head) when one is set, else the scalp's
    // (made once: a level set's interior is filled when it becomes a head); unset: the sphere
    // refineStrands() fits to the roots.
    const HeadObstacle refineHead = !params.head.unset() ? params.head
                                    : scalp              ? HeadObstacle::levelSet(scalp, HeadPolicy::NoDeeper)
                                                         : HeadObstacle();
    // Refinement of one output level (§5.3), in place.
    StrandSet finestStrands;
    const auto refineLevel = [&](int l, bool refine) {
        StrandSamples& level = res.output[std::size_t(l)];
        StrandSet strands = samplesToStrands(level, radius, threaded);
        if (refine && params.refine) {
            SynthStageTimer t{res.stages, "refinement"};
            RefineParams rp;
            rp.levels = 1;
            rp.mode = params.refineMode;
            rp.measure = false;
            rp.field.voxelSize = res.refineVoxelSizes[std::size_t(l)];
            rp.head = refineHead;
            RefineResult rr = refineStrands(std::move(strands), rp, threaded, interrupter);
            if (!rr.levels.empty()) res.refinedCorrected[std::size_t(l)] = rr.levels.front().consistency.corrected;
            strands = std::move(rr.strands);
            StrandSamples again = sampleStrands(strands, map, level.vertices, threaded);
            // Keep the scattered roots' frames and positions exactly (refinement keeps roots).
            level.local.swap(again.local);
            level.lengths.swap(again.lengths);
        }
        if (l == 0) finestStrands = std::move(strands);
    };
    refineLevel(L - 1, refineCoarsest);
    // 6. Finer levels by detail transfer.
    std::vector<std::vector<std::uint32_t>> parent(static_cast<std::size_t>(L));  // parent[l][i]: output strand of level l+1
    for (int l = L - 2; l >= 0; --l) {
        if (interrupter && interrupter->wasInterrupted()) throw InterruptedError("synthesis interrupted");
        {
            SynthStageTimer t{res.stages, "detail transfer"};
            const LevelRoots roots = rootsOf(l);
            const TransferSource src{&source.levels[std::size_t(l)], &source.levels[std::size_t(l + 1)],
                                     &source.clusterings[std::size_t(l)].label};
            res.output[std::size_t(l)] = transferDetail(src, res.output[std::size_t(l + 1)], roots.positions, map, params.components,
                                                        &parent[std::size_t(l)], nullptr, params.detailBlend, threaded, interrupter,
                                                        roots.parent.empty() ? nullptr : &roots.parent, params.detailScale,
                                                        outputVertices, params.match);
        }
        refineLevel(l, true);
    }
    res.strands = std::move(finestStrands);
    // Cluster of every output strand at each coarser level.
    const std::size_t n = res.output[0].count();
    std::vector<std::int32_t> at(n);
    for (std::size_t i = 0; i < n; ++i) at[i] = std::int32_t(i);
    res.clusterOf.clear();
    for (int l = 0; l + 1 < L; ++l) {
        for (std::size_t i = 0; i < n; ++i) at[i] = std::int32_t(parent[std::size_t(l)][std::size_t(at[i])]);
        res.clusterOf.push_back(at);
    }
}

HeadObstacle synthesisHead(const SynthParams& params, openvdb::FloatGrid::ConstPtr scalp, bool otherHead, const StrandSet& roots, const Vec3d& up)
{
    if (!params.head.unset()) return params.head;
    if (otherHead) return HeadObstacle::none();
    if (scalp) return HeadObstacle::levelSet(scalp);
    return headFromRoots(roots, up);
}

/// How far along a new strand the head's push out is spread (HeadCollisionParams::spread, a
/// fraction of its length): a fifth, twice an edit's. New hair meets the head along much of its
/// length (Ruby's long hair, read where the example's lies on her shoulders, is pushed out on 80 %
/// of its strands), not at a stroke's contact: at a tenth its turning distance from the example
/// was 0.27 (the check's bound 0.25; 0.01 without the head), at a fifth 0.22. Six grooms on their
/// heads, seeds 0-2: global checks failing 7 → 4 of 18, region figures within 10 % 509 → 511 of
/// 648, strands with a kink over 45° the same (scripts/head_table.py), the head's time the same.
constexpr double kNewHairSpread = 0.2;

void keepHairOutOfHead(SynthResult& res, const HeadObstacle& head, const StrandSet* reference, bool threaded)
{
    res.head = head.empty() ? std::string("none") : head.describe(false);
    if (head.empty()) return;
    SynthStageTimer t{res.stages, "head"};
    // New hair rises out of the scalp it grows from and goes no deeper than the hair it was made
    // from: each vertex no deeper than the vertices before it, nor than the example's (or the
    // base's) strand with the nearest root at the same arc length (refine --head's rule); on
    // another head, no deeper than its root.
    HeadCollisionParams hp;
    hp.depthRule = HeadDepthRule::Rising;
    hp.spread = kNewHairSpread;
    std::vector<std::uint32_t> nearest;
    if (reference) liftRootsToReference(res.strands, *reference, head, threaded, &nearest);
    const std::vector<float> allowed = reference ? referenceDepthAllowance(res.strands, *reference, head, threaded, nearest.empty() ? nullptr : &nearest)
                                                 : rootDepthAllowance(res.strands, head, threaded);
    res.headPushedOut = resolveHeadCollisions(res.strands, head, allowed, hp, threaded).strandsMoved;
    const double tolerance = headTolerance(head);
    res.enteringHead = countStrandsEnteringHead(res.strands, head, tolerance, threaded);
    if (reference) res.exampleEnteringHead = countStrandsEnteringHead(*reference, head, tolerance, threaded);
}

} // namespace vdbhair
