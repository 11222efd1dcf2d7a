#include "Scene.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Memory.h>
#include <vdbhair/Progress.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/JsonFile.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <set>

namespace vdbhair {

namespace {

using json = nlohmann::json;

/// Parses with key paths in every message.
struct Parser
{
    std::string where;

    [[noreturn]] void fail(const std::string& path, const std::string& rule) const
    {
        throw FormatError(where + ": " + path + ": " + rule);
    }
    void allowOnly(const json& j, const std::string& path, const std::set<std::string>& keys) const
    {
        if (!j.is_object()) fail(path, "expected an object");
        for (auto it = j.begin(); it != j.end(); ++it) {
            if (!keys.count(it.key())) {
                std::string list;
                for (const auto& k : keys) list += (list.empty() ? "" : ", ") + k;
                fail(path.empty() ? it.key() : path + "." + it.key(), "unknown key (allowed here: " + list + ")");
            }
        }
    }
    const json& require(const json& j, const std::string& path, const std::string& key) const
    {
        if (!j.contains(key)) fail(path.empty() ? key : path + "." + key, "missing");
        return j.at(key);
    }
    double number(const json& j, const std::string& path) const
    {
        if (!j.is_number()) fail(path, "expected a number, got " + std::string(j.type_name()));
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(path, "expected a finite number");
        return v;
    }
    Vec3d vec3(const json& j, const std::string& path) const
    {
        if (!j.is_array() || j.size() != 3) fail(path, "expected 3 numbers");
        return Vec3d(number(j[0], path + "[0]"), number(j[1], path + "[1]"), number(j[2], path + "[2]"));
    }
    std::uint64_t count(const json& j, const std::string& path) const
    {
        if (!j.is_number_integer() || j.get<std::int64_t>() < 0) fail(path, "expected a non-negative integer");
        return j.get<std::uint64_t>();
    }
};

std::string idx(const std::string& base, std::size_t i) { return base + "[" + std::to_string(i) + "]"; }

} // namespace

Scene sceneFromJson(const json& j, const std::string& where)
{
    Parser P{where};
    P.allowOnly(j, "", {"vdbhair", "seed", "step", "integrator", "guides", "head"});
    const json& tag = P.require(j, "", "vdbhair");
    if (!tag.is_string() || tag.get<std::string>() != "scene/1") P.fail("vdbhair", "expected \"scene/1\"");
    Scene s;
    if (j.contains("seed")) s.seed = P.count(j["seed"], "seed");
    if (j.contains("step")) {
        s.step = P.number(j["step"], "step");
        if (!(s.step > 0.0)) P.fail("step", "must be positive");
    }
    if (j.contains("integrator")) {
        const json& ij = j["integrator"];
        if (ij == "euler") s.integrator = HelicoidIntegrator::Euler;
        else if (ij == "rk4") s.integrator = HelicoidIntegrator::RK4;
        else P.fail("integrator", "expected \"euler\" or \"rk4\"");
    }
    if (j.contains("head")) {
        const json& hj = j["head"];
        P.allowOnly(hj, "head", {"sphere"});
        const json& sj = P.require(hj, "head", "sphere");
        if (!sj.is_array() || sj.size() != 4) P.fail("head.sphere", "expected 4 numbers (cx, cy, cz, r)");
        SceneHead head;
        head.center = Vec3d(P.number(sj[0], "head.sphere[0]"), P.number(sj[1], "head.sphere[1]"), P.number(sj[2], "head.sphere[2]"));
        head.radius = P.number(sj[3], "head.sphere[3]");
        if (!(head.radius > 0.0)) P.fail("head.sphere[3]", "the radius must be positive, got " + sj[3].dump());
        s.head = head;
    }
    const json& guides = P.require(j, "", "guides");
    if (!guides.is_array()) P.fail("guides", "expected an array");
    for (std::size_t g = 0; g < guides.size(); ++g) {
        const std::string gp = idx("guides", g);
        const json& gj = guides[g];
        P.allowOnly(gj, gp, {"root", "frame", "pieces", "waviness", "wisp", "fit", "step"});
        SceneGuide guide;
        guide.root = P.vec3(P.require(gj, gp, "root"), gp + ".root");
        const json& fj = P.require(gj, gp, "frame");
        P.allowOnly(fj, gp + ".frame", {"tangent", "normal"});
        const Vec3d t = P.vec3(P.require(fj, gp + ".frame", "tangent"), gp + ".frame.tangent");
        const Vec3d n = P.vec3(P.require(fj, gp + ".frame", "normal"), gp + ".frame.normal");
        try {
            guide.frame = FrameD::fromTangentNormal(t, n);
        } catch (const ValueError& e) {
            P.fail(gp + ".frame", e.what());
        }
        const json& pj = P.require(gj, gp, "pieces");
        if (!pj.is_array() || pj.empty()) P.fail(gp + ".pieces", "expected a non-empty array");
        for (std::size_t i = 0; i < pj.size(); ++i) {
            const std::string pp = idx(gp + ".pieces", i);
            P.allowOnly(pj[i], pp, {"k", "length", "roll"});
            const json& kj = P.require(pj[i], pp, "k");
            if (!kj.is_array() || kj.size() != 4) P.fail(pp + ".k", "expected 4 numbers (kT, kN, kB, alpha)");
            HelicoidPiece piece;
            piece.k = {P.number(kj[0], pp + ".k[0]"), P.number(kj[1], pp + ".k[1]"), P.number(kj[2], pp + ".k[2]"),
                       P.number(kj[3], pp + ".k[3]")};
            piece.length = P.number(P.require(pj[i], pp, "length"), pp + ".length");
            if (piece.length < 0.0) P.fail(pp + ".length", "must not be negative");
            if (pj[i].contains("roll")) piece.roll = P.number(pj[i]["roll"], pp + ".roll");
            guide.pieces.push_back(piece);
        }
        double total = 0.0;
        for (const HelicoidPiece& piece : guide.pieces) total += piece.length;
        if (!(total > 0.0)) P.fail(gp + ".pieces", "the pieces' lengths add up to 0; a strand needs a positive length");
        if (gj.contains("waviness")) {
            const json& wj = gj["waviness"];
            const std::string wp = gp + ".waviness";
            P.allowOnly(wj, wp, {"amplitude", "frequency", "phase", "noise"});
            WavinessParams w;
            w.amplitude = P.number(P.require(wj, wp, "amplitude"), wp + ".amplitude");
            w.frequency = P.number(P.require(wj, wp, "frequency"), wp + ".frequency");
            if (wj.contains("phase")) w.phase = P.number(wj["phase"], wp + ".phase");
            if (wj.contains("noise")) w.noise = P.number(wj["noise"], wp + ".noise");
            if (w.amplitude < 0.0) P.fail(wp + ".amplitude", "must not be negative");
            if (w.noise < 0.0) P.fail(wp + ".noise", "must not be negative");
            guide.waviness = w;
        }
        if (gj.contains("wisp")) {
            const json& wj = gj["wisp"];
            const std::string wp = gp + ".wisp";
            P.allowOnly(wj, wp, {"count", "radius", "fanning", "normal", "strays"});
            WispParams w;
            w.count = std::size_t(P.count(P.require(wj, wp, "count"), wp + ".count"));
            w.radius = P.number(P.require(wj, wp, "radius"), wp + ".radius");
            if (wj.contains("fanning")) w.fanning = P.number(wj["fanning"], wp + ".fanning");
            if (w.radius < 0.0) P.fail(wp + ".radius", "must not be negative");
            if (w.fanning < 0.0) P.fail(wp + ".fanning", "must not be negative");
            if (wj.contains("normal")) {
                const Vec3d n = P.vec3(wj["normal"], wp + ".normal");
                const double len = n.length();
                if (!(len > 1e-12) || !std::isfinite(len)) P.fail(wp + ".normal", "must be a non-zero vector (the scalp's normal at the root)");
                w.normal = n / len;
            }
            if (wj.contains("strays")) {
                w.strays = P.number(wj["strays"], wp + ".strays");
                if (w.strays < 0.0 || w.strays > 1.0) P.fail(wp + ".strays", "must be a fraction in [0, 1], got " + wj["strays"].dump());
            }
            guide.wisp = w;
        }
        if (gj.contains("fit")) guide.fit = gj["fit"];
        if (gj.contains("step")) {
            guide.step = P.number(gj["step"], gp + ".step");
            if (!(guide.step > 0.0)) P.fail(gp + ".step", "must be positive");
        }
        s.guides.push_back(std::move(guide));
    }
    return s;
}

json sceneToJson(const Scene& s)
{
    json guides = json::array();
    for (const SceneGuide& g : s.guides) {
        json pieces = json::array();
        for (const HelicoidPiece& p : g.pieces) {
            json pj = {{"k", {p.k.kT, p.k.kN, p.k.kB, p.k.alpha}}, {"length", p.length}};
            if (p.roll != 0.0) pj["roll"] = p.roll;
            pieces.push_back(pj);
        }
        json gj = {{"root", {g.root.x(), g.root.y(), g.root.z()}},
                   {"frame", {{"tangent", {g.frame.t.x(), g.frame.t.y(), g.frame.t.z()}},
                              {"normal", {g.frame.n.x(), g.frame.n.y(), g.frame.n.z()}}}},
                   {"pieces", pieces}};
        if (g.waviness) {
            gj["waviness"] = {{"amplitude", g.waviness->amplitude}, {"frequency", g.waviness->frequency}};
            if (g.waviness->phase != 0.0) gj["waviness"]["phase"] = g.waviness->phase;
            if (g.waviness->noise != 0.0) gj["waviness"]["noise"] = g.waviness->noise;
        }
        if (g.wisp) {
            gj["wisp"] = {{"count", g.wisp->count}, {"radius", g.wisp->radius}, {"fanning", g.wisp->fanning}};
            if (g.wisp->normal.length() > 0.0) gj["wisp"]["normal"] = {g.wisp->normal.x(), g.wisp->normal.y(), g.wisp->normal.z()};
            if (g.wisp->strays > 0.0) gj["wisp"]["strays"] = g.wisp->strays;
        }
        if (!g.fit.is_null()) gj["fit"] = g.fit;
        if (g.step > 0.0) gj["step"] = g.step;
        guides.push_back(gj);
    }
    json out = {{"vdbhair", "scene/1"}, {"seed", s.seed}, {"step", s.step}, {"guides", guides}};
    if (s.integrator == HelicoidIntegrator::RK4) out["integrator"] = "rk4";
    if (s.head) out["head"] = {{"sphere", {s.head->center.x(), s.head->center.y(), s.head->center.z(), s.head->radius}}};
    return out;
}

Scene readScene(const std::string& path)
{
    return sceneFromJson(readJsonFile(path, kMaxSceneDepth, "a scene"), path);
}


void writeScene(const std::string& path, const Scene& scene)
{
    const json j = sceneToJson(scene);
    // One guide per line: readable, diffable, and still one JSON document.
    std::string out = "{\"vdbhair\": \"scene/1\", \"seed\": " + std::to_string(scene.seed) + ", \"step\": " +
                      j["step"].dump() + (j.contains("integrator") ? ", \"integrator\": " + j["integrator"].dump() : std::string()) +
                      (j.contains("head") ? ", \"head\": " + j["head"].dump() : std::string()) +
                      ",\n \"guides\": [\n";
    for (std::size_t i = 0; i < j["guides"].size(); ++i) {
        out += "  " + j["guides"][i].dump() + (i + 1 < j["guides"].size() ? ",\n" : "\n");
    }
    out += " ]}\n";
    writeFileAtomic(path, out, "writeScene(" + path + ")");
}

std::size_t sceneVertexCount(const Scene& scene)
{
    std::size_t total = 0;
    constexpr std::size_t kMax = std::numeric_limits<std::size_t>::max() / 4;
    for (const SceneGuide& g : scene.guides) {
        double perStrand = 1.0;
        const double step = g.step > 0.0 ? g.step : scene.step;
        for (const HelicoidPiece& p : g.pieces) perStrand += std::ceil(p.length / step);
        const double strands = 1.0 + (g.wisp ? double(g.wisp->count) : 0.0);
        const double v = perStrand * strands;
        if (v > double(kMax) || double(total) + v > double(kMax)) return kMax;
        total += std::size_t(v);
    }
    return total;
}

StrandSet growGuides(const Scene& scene, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    Scene bare = scene;
    for (SceneGuide& g : bare.guides) g.wisp.reset();
    return growScene(bare, {}, threaded, interrupter);
}

namespace {

/// The scene's step, and its vertices against the cap and the memory at hand, before any work.
void checkGrowable(const Scene& scene, const GrowOptions& options)
{
    if (!(scene.step > 0.0) || !std::isfinite(scene.step)) {
        throw ValueError("growScene: step " + std::to_string(scene.step) + " must be a positive length");
    }
    const std::size_t estimate = sceneVertexCount(scene);
    std::size_t wisps = 0;
    for (const SceneGuide& g : scene.guides) wisps += g.wisp ? g.wisp->count : 0;
    const std::string what = "about " + formatNumber(double(estimate)) + " vertices of " + std::to_string(sizeof(Vec3f)) + " bytes: " +
                             std::to_string(scene.guides.size()) + " guides and " + std::to_string(wisps) + " wisp strands";
    if (estimate > options.maxVertices) {
        throw LimitError("growScene: the scene would grow " + what + " (" + formatBytes(std::uint64_t(estimate) * sizeof(Vec3f)) +
                         "), more than the cap of " + std::to_string(options.maxVertices) + " vertices (fewer wisps, shorter pieces or a larger step)");
    }
    checkMemory("growScene", std::uint64_t(estimate) * sizeof(Vec3f), what, "fewer wisps, shorter pieces or a larger step");
}

/// One strand of the scene: a guide's own (wisp 0) or one of its wisp strands.
struct GrowItem
{
    std::size_t guide, wisp;
};

/// Grows a scene's strands into a laid-out StrandSet: the guides with wisps traced first (their
/// wisps need the traces), then every strand, over ranges of items (in parallel or not).
struct SceneGrower
{
    const Scene& scene;
    HelicoidIntegrator integrator;
    bool report;  ///< whether each guide's clearance from its pieces' singular axes is measured
    std::vector<GrowItem> items;
    StrandSet out;
    std::vector<HelicoidTrace> guideTraces;
    std::vector<double> clearance;  ///< per guide, in steps (written once per guide); with report
    ProgressCounter progress;

    SceneGrower(const Scene& scene_, HelicoidIntegrator integrator_, bool report_, openvdb::util::NullInterrupter* interrupter)
        : scene(scene_), integrator(integrator_), report(report_), guideTraces(scene_.guides.size()),
          clearance(report_ ? scene_.guides.size() : 0, std::numeric_limits<double>::infinity()),
          progress(interrupter, "growing strands", scene_.guides.size() + layOut(), "traces")
    {
    }

    double stepOf(const SceneGuide& g) const { return g.step > 0.0 ? g.step : scene.step; }

    /// Layout: guide g, then its wisps; every strand of a guide has the guide's vertex count.
    /// Returns the strand count (progress: guides traced, then strands grown).
    std::size_t layOut()
    {
        std::vector<std::uint32_t> offsets{0};
        for (std::size_t g = 0; g < scene.guides.size(); ++g) {
            const SceneGuide& guide = scene.guides[g];
            std::size_t n = 1;
            for (const HelicoidPiece& p : guide.pieces) n += stepCount(p.length, stepOf(guide));
            const std::size_t strands = 1 + (guide.wisp ? guide.wisp->count : 0);
            for (std::size_t w = 0; w < strands; ++w) {
                items.push_back({g, w});
                offsets.push_back(std::uint32_t(offsets.back() + n));
            }
        }
        out.offsets = offsets;
        reserveHugePages(out.positions, offsets.back());  // fresh pages 2 MiB at a time (Memory.h)
        out.positions.resize(offsets.back());
        return items.size();
    }

    /// Only guides with wisps are traced ahead (their wisps need the trace); the others are
    /// traced where their strand is written, so many wispless guides (interpolated hair) never
    /// hold all their traces at once.
    void traceGuides(const tbb::blocked_range<std::size_t>& r)
    {
        for (std::size_t g = r.begin(); g != r.end(); ++g) {
            if (progress.stopped() || progress.add(1)) return;
            if (!scene.guides[g].wisp) continue;
            tracePHelicoid(scene.guides[g].root, scene.guides[g].frame, scene.guides[g].pieces, stepOf(scene.guides[g]),
                           integrator, guideTraces[g]);
            if (report) clearance[g] = traceClearance(guideTraces[g], stepOf(scene.guides[g]));
        }
    }

    /// Hairs without wisps or waviness (interpolated hair) need their points only.
    bool pointsOnly(const GrowItem& x) const
    {
        const SceneGuide& g = scene.guides[x.guide];
        return !g.wisp && !g.waviness && !report;
    }

    /// A run of points-only items from @a i (up to 64, within the range's end @a end) through the
    /// lane kernel at once. Returns how many.
    std::size_t growPointsRun(std::size_t i, std::size_t end)
    {
        constexpr std::size_t kRun = 64;
        PHelicoidRequest run[kRun];
        Vec3f* dst[kRun];
        std::size_t count = 0;
        while (count < kRun && i + count != end && pointsOnly(items[i + count])) {
            const SceneGuide& g = scene.guides[items[i + count].guide];
            run[count] = PHelicoidRequest{g.root, g.frame, &g.pieces, stepOf(g)};
            dst[count] = out.positions.data() + out.offsets[i + count];
            ++count;
        }
        tracePHelicoidPoints(run, count, integrator, dst);
        return count;
    }

    /// Scratch of one range: wisp strands of one guide are traced a batch at a time (see
    /// tracePHelicoids).
    static constexpr std::size_t kBatch = 8;
    struct Scratch
    {
        HelicoidTrace traces[kBatch];
        HelicoidTrace own;  ///< a wispless guide's trace
        std::vector<Rng> rngs;
    };

    /// Item @a i's strand, with the next wisp strands of its guide (up to kBatch, within @a end):
    /// traced, then wavy or copied. Returns how many.
    std::size_t growBatch(std::size_t i, std::size_t end, Scratch& s)
    {
        const GrowItem& it = items[i];
        const SceneGuide& guide = scene.guides[it.guide];
        std::size_t count = 1;
        s.rngs.assign(1, Rng(scene.seed, it.guide, it.wisp));
        const HelicoidTrace* batch[kBatch] = {&guideTraces[it.guide]};
        if (!guide.wisp) {
            tracePHelicoid(guide.root, guide.frame, guide.pieces, stepOf(guide), integrator, s.own);
            if (report) clearance[it.guide] = traceClearance(s.own, stepOf(guide));
            batch[0] = &s.own;
        } else if (it.wisp > 0) {
            while (count < kBatch && i + count != end && items[i + count].guide == it.guide) {
                s.rngs.emplace_back(scene.seed, it.guide, items[i + count].wisp);
                ++count;
            }
            traceWisps(guideTraces[it.guide], guide.pieces, *guide.wisp, stepOf(guide), integrator, s.rngs.data(), count, s.traces,
                       guide.waviness.has_value());
            for (std::size_t b = 0; b < count; ++b) batch[b] = &s.traces[b];
        }
        for (std::size_t b = 0; b < count; ++b) {
            const HelicoidTrace& trace = *batch[b];
            Vec3f* dst = out.positions.data() + out.offsets[i + b];
            if (guide.waviness) {
                applyWaviness(trace, *guide.waviness, s.rngs[b], dst);
            } else {
                for (std::size_t k = 0; k < trace.points.size(); ++k) {
                    dst[k] = Vec3f(float(trace.points[k].x()), float(trace.points[k].y()), float(trace.points[k].z()));
                }
            }
        }
        return count;
    }

    void growItems(const tbb::blocked_range<std::size_t>& r)
    {
        Scratch scratch;
        for (std::size_t i = r.begin(); i != r.end();) {
            if (progress.stopped()) return;
            const std::size_t count = pointsOnly(items[i]) ? growPointsRun(i, r.end()) : growBatch(i, r.end(), scratch);
            i += count;
            progress.add(count);
        }
    }
};

/// The guides nearer a singular axis than options.nearAxisSteps, and the nearest one.
GrowReport clearanceReport(const std::vector<double>& clearance, double nearAxisSteps)
{
    GrowReport report;
    for (std::size_t g = 0; g < clearance.size(); ++g) {
        if (clearance[g] < nearAxisSteps) ++report.nearAxis;
        if (clearance[g] < report.nearestClearance) {
            report.nearestClearance = clearance[g];
            report.nearestGuide = g;
        }
    }
    return report;
}

} // namespace

const ParamTable<GrowOptions>& growParameters()
{
    using P = GrowOptions;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        // "scene" stands for no override.
        ParamAccess<P, std::string> integratorAccess{
            [](const P& p) -> std::string { return !p.integrator ? "scene" : *p.integrator == HelicoidIntegrator::RK4 ? "rk4" : "euler"; },
            [](P& p, std::string v) {
                if (v == "scene") p.integrator.reset();
                else if (v == "euler") p.integrator = HelicoidIntegrator::Euler;
                else if (v == "rk4") p.integrator = HelicoidIntegrator::RK4;
                else throw ValueError("integrator '" + v + "' is not one of scene, euler, rk4");
            }};
        auto integrator = makeParam<P>("integrator", "euler (Eq. 3, the paper's), rk4, or scene (the scene's own, else euler)", "", integratorAccess);
        integrator.choices = {"scene", "euler", "rk4"};
        integrator.pythonNone = true;
        t.push_back(integrator);
        t.push_back(makeParam<P>("max-vertices", "Refuse scenes that would grow more vertices (12 bytes each)", "",
                                 member<P>([](P& p) -> std::size_t& { return p.maxVertices; })));
        return t;
    }();
    return table;
}

StrandSet growScene(const Scene& scene, const GrowOptions& options, bool threaded, openvdb::util::NullInterrupter* interrupter,
                    GrowReport* report)
{
    checkGrowable(scene, options);
    const HelicoidIntegrator integrator = options.integrator ? *options.integrator : scene.integrator;
    SceneGrower grower(scene, integrator, report != nullptr, interrupter);
    const auto traceGuides = [&](const tbb::blocked_range<std::size_t>& r) { grower.traceGuides(r); };
    const auto growItems = [&](const tbb::blocked_range<std::size_t>& r) { grower.growItems(r); };
    if (threaded) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, scene.guides.size(), 1), traceGuides);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grower.items.size(), 16), growItems);
    } else {
        traceGuides(tbb::blocked_range<std::size_t>(0, scene.guides.size()));
        growItems(tbb::blocked_range<std::size_t>(0, grower.items.size()));
    }
    if (grower.progress.stopped()) throw InterruptedError("growScene: interrupted");
    if (report) *report = clearanceReport(grower.clearance, options.nearAxisSteps);
    return std::move(grower.out);
}

} // namespace vdbhair
