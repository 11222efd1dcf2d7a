#include "Comb.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/io/JsonFile.h>
#include <vdbhair/strands/Resample.h>
#include <vdbhair/synth/SynthesisReport.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

namespace vdbhair {

namespace {

// Combing composes each edge's turns (C = R C) and blends neighbouring edges' rotations by
// slerp (retransferDetail()), which needs rotations as quaternions; Rotation.h turns vectors
// (Rodrigues) and has neither composition nor slerp, so the turns here stay Eigen quaternions.
using Quat = Eigen::Quaterniond;
using EVec = Eigen::Vector3d;

EVec toE(const Vec3d& v) { return EVec(v.x(), v.y(), v.z()); }

/// The largest angle between consecutive edges of the polyline @a p of @a n vertices, degrees
/// (zero-length edges skipped).
double maxEdgeTurnDegrees(const Vec3f* p, std::size_t n)
{
    double worst = 0.0;
    for (std::size_t v = 1; v + 1 < n; ++v) {
        const Vec3d a(p[v] - p[v - 1]), b(p[v + 1] - p[v]);
        const double la = a.length(), lb = b.length();
        if (!(la > 0.0) || !(lb > 0.0)) continue;
        worst = std::max(worst, std::acos(std::clamp(a.dot(b) / (la * lb), -1.0, 1.0)));
    }
    return worst * 180.0 / M_PI;
}

/// Whether the strand @a after (@a n vertices) turns by over kKinkDegrees between two edges and
/// the same strand @a before did not: a kink the comb (or the head's push) made.
bool gainsKink(const Vec3f* before, const Vec3f* after, std::size_t n)
{
    return maxEdgeTurnDegrees(after, n) > kKinkDegrees && !(maxEdgeTurnDegrees(before, n) > kKinkDegrees);
}
Vec3d fromE(const EVec& v) { return Vec3d(v.x(), v.y(), v.z()); }
Quat toQuat(const std::array<double, 4>& q) { return Quat(q[0], q[1], q[2], q[3]); }
std::array<double, 4> fromQuat(const Quat& q) { return {q.w(), q.x(), q.y(), q.z()}; }

/// Distance from @a p to the stroke and the direction of its nearest segment.
double strokeDistance(const CombStroke& s, const Vec3d& p, Vec3d* dir)
{
    double best = std::numeric_limits<double>::max();
    for (std::size_t k = 0; k + 1 < s.points.size(); ++k) {
        const Vec3d a = s.points[k], ab = s.points[k + 1] - a;
        const double len2 = ab.lengthSqr();
        const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
        const double d = (p - (a + ab * t)).length();
        if (d < best && len2 > 0.0) {
            best = d;
            if (dir) *dir = ab / std::sqrt(len2);
        }
    }
    return best;
}

double influence(const CombStroke& s, double d)
{
    if (!(d < s.radius)) return 0.0;
    const double q = (d * d) / (s.radius * s.radius), x = 1.0 - q * q;
    return s.strength * x * x;
}

/// A rotation turning unit @a u toward unit @a d by @a fraction of the angle between them.
Quat turnToward(const EVec& u, const EVec& d, double fraction)
{
    const double c = std::clamp(u.dot(d), -1.0, 1.0);
    const double angle = std::acos(c);
    if (angle < 1e-12 || fraction <= 0.0) return Quat::Identity();
    EVec axis = u.cross(d);
    if (axis.norm() < 1e-9) {  // opposite: any axis perpendicular to u
        axis = u.cross(std::abs(u.x()) < 0.9 ? EVec::UnitX() : EVec::UnitY());
    }
    return Quat(Eigen::AngleAxisd(fraction * angle, axis.normalized()));
}

} // namespace

void validateStroke(const CombStroke& s, std::size_t index, const std::string& where)
{
    const std::string at = where + ": strokes[" + std::to_string(index) + "]";
    if (s.points.size() < 2)
        throw ValueError(at + ".points: " + std::to_string(s.points.size()) + " point" + (s.points.size() == 1 ? "" : "s") +
                         ": a stroke needs at least 2");
    for (std::size_t i = 0; i < s.points.size(); ++i)
        if (!std::isfinite(s.points[i].x()) || !std::isfinite(s.points[i].y()) || !std::isfinite(s.points[i].z()))
            throw ValueError(at + ".points[" + std::to_string(i) + "]: not finite");
    bool moves = false;
    for (std::size_t i = 1; i < s.points.size(); ++i) moves = moves || (s.points[i] - s.points[i - 1]).lengthSqr() > 0.0;
    if (!moves) throw ValueError(at + ".points: every point is the same: a stroke needs a direction");
    if (!(s.radius > 0.0) || !std::isfinite(s.radius))
        throw ValueError(at + ".radius: " + std::to_string(s.radius) + ": must be a positive finite length");
    if (!(s.strength >= 0.0 && s.strength <= 1.0))
        throw ValueError(at + ".strength: " + std::to_string(s.strength) + ": must be 0 to 1");
}

std::vector<CombStroke> readStrokes(const std::string& path)
{
    const nlohmann::json j = readJsonFile(path, 8, "a stroke file");
    const auto fail = [&](const std::string& where, const std::string& what) { throw FormatError(path + ": " + where + ": " + what); };
    const auto number = [&](const nlohmann::json& v, const std::string& where) {
        if (!v.is_number()) fail(where, "must be a number");
        return v.get<double>();
    };
    std::vector<const nlohmann::json*> items;
    if (!j.is_object()) fail("(top level)", "must be an object with \"strokes\" (or one stroke)");
    if (j.contains("strokes")) {
        for (auto it = j.begin(); it != j.end(); ++it)
            if (it.key() != "strokes" && it.key() != "vdbhair") fail(it.key(), "unknown key (expected vdbhair, strokes)");
        if (!j["strokes"].is_array()) fail("strokes", "must be an array of strokes");
        for (const nlohmann::json& s : j["strokes"]) items.push_back(&s);
        if (items.empty()) fail("strokes", "empty: at least one stroke is needed");
    } else {
        items.push_back(&j);
    }
    std::vector<CombStroke> out;
    for (std::size_t i = 0; i < items.size(); ++i) {
        const nlohmann::json& s = *items[i];
        const std::string where = j.contains("strokes") ? "strokes[" + std::to_string(i) + "]" : std::string("(top level)");
        if (!s.is_object()) fail(where, "must be an object with points, radius and strength");
        for (auto it = s.begin(); it != s.end(); ++it)
            if (it.key() != "points" && it.key() != "radius" && it.key() != "strength" && it.key() != "vdbhair")
                fail(where + "." + it.key(), "unknown key (expected points, radius, strength)");
        if (!s.contains("points") || !s["points"].is_array()) fail(where + ".points", "missing: an array of [x, y, z]");
        if (!s.contains("radius")) fail(where + ".radius", "missing: the stroke's radius in world units");
        CombStroke st;
        for (std::size_t k = 0; k < s["points"].size(); ++k) {
            const nlohmann::json& p = s["points"][k];
            const std::string pw = where + ".points[" + std::to_string(k) + "]";
            if (!p.is_array() || p.size() != 3) fail(pw, "must be [x, y, z]");
            st.points.emplace_back(number(p[0], pw), number(p[1], pw), number(p[2], pw));
        }
        st.radius = number(s["radius"], where + ".radius");
        if (s.contains("strength")) st.strength = number(s["strength"], where + ".strength");
        try {
            validateStroke(st, i, path);
        } catch (const ValueError& e) {
            throw FormatError(e.what());
        }
        out.push_back(std::move(st));
    }
    return out;
}

const ParamTable<CombParams>& combParameters()
{
    using P = CombParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t = nestedParams<P>(synthParameters(), [](P& p) -> SynthParams& { return p.synth; },
                                          {"levels", "seed", "vertices", "threshold", "initial-clusters", "up"});
        auto smoothing = makeParam<P>("smoothing", "Sigma of the strand directions the strokes turn, a fraction of the vertices (detail below it rides along)", "",
                                      member<P>([](P& p) -> double& { return p.smoothing; }));
        smoothing.min = 0.0;
        smoothing.max = 1.0;
        t.push_back(smoothing);
        t.push_back(headPolicyParam<P>([](P& p) -> HeadPolicy& { return p.headPolicy; }));
        return t;
    }();
    return table;
}

void CombParams::validate(const char* where) const
{
    synth.validate(where);
    if (!(smoothing >= 0.0 && smoothing <= 1.0))
        throw ValueError(std::string(where) + ": smoothing " + std::to_string(smoothing) + ": 0 to 1 (a fraction of the strand's vertices)");
}

bool combPolyline(const std::vector<Vec3d>& p, const std::vector<std::vector<Vec3d>>& members, const CombStroke& stroke,
                  double sigma, std::vector<Vec3d>& out, std::vector<std::array<double, 4>>& rotations, double maxTurnPerLength)
{
    const std::size_t n = p.size();
    out = p;
    rotations.assign(n > 0 ? n - 1 : 0, fromQuat(Quat::Identity()));
    if (n < 2) return false;
    std::vector<Vec3d> smooth(n);
    smoothPolyline(p.data(), n, sigma, smooth.data());
    // Where the stroke is felt: along the members (the wisp's strands, all of n points), or the strand itself.
    std::vector<const std::vector<Vec3d>*> feel;
    for (const std::vector<Vec3d>& m : members)
        if (m.size() == n) feel.push_back(&m);
    if (feel.empty()) feel.push_back(&p);
    std::vector<EVec> at(feel.size());
    for (std::size_t m = 0; m < feel.size(); ++m) at[m] = toE((*feel[m])[0]);
    Quat C = Quat::Identity();
    bool touched = false;
    EVec q = toE(p[0]);
    for (std::size_t i = 0; i + 1 < n; ++i) {
        const EVec e = toE(p[i + 1] - p[i]);
        const double len = e.norm();
        // The stroke's mean influence over the wisp at this vertex, and its direction weighted by it.
        double w = 0.0;
        Vec3d dir(0.0);
        for (std::size_t m = 0; m < feel.size(); ++m) {
            const EVec em = toE((*feel[m])[i + 1] - (*feel[m])[i]);
            Vec3d d;
            const double wm = influence(stroke, strokeDistance(stroke, fromE(at[m] + C * (0.5 * em)), &d));
            w += wm;
            dir += d * wm;
        }
        w /= double(feel.size());
        if (w > 0.0 && len > 0.0 && dir.length() > 0.0) {
            EVec t = toE(smooth[i + 1] - smooth[i]);
            t = t.norm() > 0.0 ? EVec(t.normalized()) : EVec(e / len);
            double f = w >= 1.0 ? 1.0 : 1.0 - std::pow(1.0 - w, len / stroke.radius);
            const EVec from = (C * t).normalized(), to = toE(dir.unitSafe());
            if (maxTurnPerLength > 0.0) {
                const double angle = std::acos(std::clamp(from.dot(to), -1.0, 1.0));
                if (f * angle > maxTurnPerLength * len) f = maxTurnPerLength * len / angle;
            }
            const Quat R = turnToward(from, to, f);
            C = (R * C).normalized();
            touched = true;
        }
        rotations[i] = fromQuat(C);
        q += C * e;
        out[i + 1] = fromE(q);
        for (std::size_t m = 0; m < feel.size(); ++m) at[m] += C * toE((*feel[m])[i + 1] - (*feel[m])[i]);
    }
    if (!touched) out = p;
    return touched;
}

namespace {

/// The most one stroke turns a wisp over the length of its strands' longest edge (radians): a
/// strand sampled at 16 vertices (`straight.hair`: its last edges a tenth of its length) cannot
/// bend more sharply than its edges show, and a stroke about an edge wide turned its wisp's centre
/// (32 vertices) so fast that its strands, turned at their edges' midpoints, kinked at one vertex
/// by 45-66 degrees (128 strands of one random sweep).
constexpr double kMaxCombTurnPerEdge = 40.0 * M_PI / 180.0;

/// One combHair() call: its inputs, the hierarchy, and what each step leaves for the next.
struct CombRun
{
    CombRun(const StrandSet& input, const std::vector<CombStroke>& combStrokes, const CombParams& p, bool runThreaded)
        : strands(input), strokes(combStrokes), params(p), threaded(runThreaded), n(input.numStrands())
    {
    }

    const StrandSet& strands;
    const std::vector<CombStroke>& strokes;
    const CombParams& params;
    const bool threaded;
    const std::size_t n;  ///< strands
    // clusterHair()
    std::shared_ptr<ScalpMap> map;
    ClusterHierarchy h;
    std::vector<std::uint32_t> order;  ///< the input strand of each of level 0's rows
    // deformCoarsest()
    std::size_t K = 0, ns = 0;                                           ///< coarsest strands; their vertices
    std::vector<std::vector<Vec3d>> centre;                              ///< the coarsest strands combed (world)
    std::vector<std::vector<Quat, Eigen::aligned_allocator<Quat>>> rot;  ///< per coarsest strand, its edges' rotations
    std::vector<std::uint8_t> touched;                                   ///< coarsest strands some stroke reached

    template<typename BodyT>
    void forEach(std::size_t count, BodyT&& fn) const
    {
        forEachIndex(count, threaded, fn, 16);
    }
};

/// The hierarchy, as synthesis builds it, and each strand's coarsest cluster (CombResult::cluster).
void clusterHair(CombRun& run, openvdb::FloatGrid::ConstPtr scalp, openvdb::util::NullInterrupter* interrupter, CombResult& res)
{
    {
        SynthStageTimer t{res.stages, "clustering"};
        run.map = hairScalpMap(run.strands, run.params.synth.up, scalp);
        run.h = hairHierarchy(run.strands, *run.map, run.params.synth, run.threaded, interrupter, &run.order);
    }
    res.cluster.assign(run.n, 0);
    for (std::size_t i = 0; i < run.n; ++i) {
        std::uint32_t c = std::uint32_t(i);
        for (const Clustering& cl : run.h.clusterings) c = cl.label[c];
        res.cluster[run.order[i]] = std::int32_t(c);
    }
}

/// Step 1, the coarsest strands deformed stroke after stroke; their rotations composed per edge.
void deformCoarsest(CombRun& run, CombResult& res)
{
    const StrandSamples& coarse = run.h.levels.back();
    const std::size_t K = run.K = coarse.count(), ns = run.ns = std::size_t(coarse.vertices);
    const double sigma = run.params.smoothing * double(ns);
    run.centre.resize(K);
    run.rot.resize(K);
    run.touched.assign(K, 0);
    SynthStageTimer t{res.stages, "coarsest deformation"};
    // The members of every coarsest cluster, as level 0's samples (rows in spatial order).
    std::vector<std::vector<std::uint32_t>> members(K);
    for (std::size_t i = 0; i < run.n; ++i) members[std::size_t(res.cluster[run.order[i]])].push_back(std::uint32_t(i));
    const StrandSamples& fine = run.h.levels.front();
    run.forEach(K, [&](std::size_t c) {
        const auto world = [&](const StrandSamples& set, std::size_t i) {
            std::vector<Vec3f> w(ns);
            sampleToWorld(set.row(i), set.vertices, set.roots[i], set.frames[i], run.map->radius(), w.data());
            return std::vector<Vec3d>(w.begin(), w.end());
        };
        std::vector<Vec3d> p = world(coarse, c), q;
        std::vector<std::vector<Vec3d>> wisp;
        for (std::uint32_t m : members[c]) wisp.push_back(world(fine, m));
        run.rot[c].assign(ns - 1, Quat::Identity());
        // The longest edge of the wisp's strands as given: the stroke bends the wisp by at most
        // kMaxCombTurnPerEdge over that length.
        double longest = 0.0;
        for (std::uint32_t m : members[c]) {
            const std::size_t s = run.order[m];
            const Vec3f* v = run.strands.data(s);
            for (std::size_t k = 1; k < run.strands.size(s); ++k) longest = std::max(longest, double((v[k] - v[k - 1]).length()));
        }
        const double maxTurn = longest > 0.0 ? kMaxCombTurnPerEdge / longest : 0.0;
        std::vector<std::array<double, 4>> r;
        for (const CombStroke& s : run.strokes) {
            if (!combPolyline(p, wisp, s, sigma, q, r, maxTurn)) continue;
            run.touched[c] = 1;
            for (std::size_t i = 0; i + 1 < ns; ++i) run.rot[c][i] = (toQuat(r[i]) * run.rot[c][i]).normalized();
            // The members as the stroke left them: their edges turned by the same rotations.
            for (std::vector<Vec3d>& m : wisp) {
                Vec3d at = m[0];
                for (std::size_t i = 0; i + 1 < ns; ++i) {
                    const Vec3d e = m[i + 1] - m[i];
                    m[i] = at;
                    at += fromE(toQuat(r[i]) * toE(e));
                }
                m[ns - 1] = at;
            }
            p.swap(q);
        }
        run.centre[c] = std::move(p);
    });
}

/// Arc length along the original coarsest strand @a c of each of its edges' midpoints.
std::vector<double> centreEdgeMidpoints(const CombRun& run, std::size_t c)
{
    const StrandSamples& coarse = run.h.levels.back();
    const std::size_t ns = run.ns;
    std::vector<Vec3f> w(ns);
    sampleToWorld(coarse.row(c), coarse.vertices, coarse.roots[c], coarse.frames[c], run.map->radius(), w.data());
    std::vector<double> mids(ns - 1);
    double a = 0.0;
    for (std::size_t i = 0; i + 1 < ns; ++i) {
        const double len = (Vec3d(w[i + 1]) - Vec3d(w[i])).length();
        mids[i] = a + 0.5 * len;
        a += len;
    }
    return mids;
}

/// Strand @a s of the input with its edges turned by its centre's rotations (midpoints @a mids)
/// at its arc length, each rotation taken @a share of the way from none (slerp), into @a out.
void retransferStrand(const CombRun& run, std::size_t s, std::size_t c, const std::vector<double>& m, double share, Vec3f* out)
{
    const Vec3f* in = run.strands.data(s);
    const auto& R = run.rot[c];
    const Quat none = Quat::Identity();
    const auto part = [&](const Quat& q) { return share >= 1.0 ? q : none.slerp(share, q); };
    EVec q = toE(Vec3d(in[0]));
    out[0] = in[0];
    double a = 0.0;
    std::size_t k = 0;
    for (std::size_t v = 0; v + 1 < run.strands.size(s); ++v) {
        const EVec e = toE(Vec3d(in[v + 1]) - Vec3d(in[v]));
        const double mid = a + 0.5 * e.norm();
        a += e.norm();
        while (k + 1 < m.size() && m[k + 1] <= mid) ++k;
        Quat Q;
        if (mid <= m.front()) Q = R.front();
        else if (k + 1 >= m.size()) Q = R.back();
        else Q = R[k].slerp((mid - m[k]) / std::max(1e-300, m[k + 1] - m[k]), R[k + 1]);
        q += part(Q) * e;
        out[v + 1] = Vec3f(fromE(q));
    }
}

/// Step 2, every strand of a combed cluster: its edges turned by its centre's rotations at its
/// arc length, into CombResult::strands (a copy of the input).
void retransferDetail(const CombRun& run, CombResult& res, std::vector<std::vector<double>>& mids)
{
    res.strands = run.strands;
    SynthStageTimer t{res.stages, "detail re-transfer"};
    mids.assign(run.K, {});
    run.forEach(run.K, [&](std::size_t c) {
        if (run.touched[c]) mids[c] = centreEdgeMidpoints(run, c);
    });
    run.forEach(run.n, [&](std::size_t s) {
        const std::size_t c = std::size_t(res.cluster[s]);
        if (run.touched[c]) retransferStrand(run, s, c, mids[c], 1.0, res.strands.data(s));
    });
}

/// Strands @a which of @a res.strands (the input's strands @a which, combed) swept out of @a head
/// along their length, no vertex deeper inside it than the input's (NoDeeper) or none inside
/// (KeepOutside) (HeadCollision.h: a strand that meets the head follows it over a length instead
/// of bending at one vertex). @return how many the head moved.
std::size_t keepStrandsOutOfHead(const CombRun& run, const HeadObstacle& head, const std::vector<char>& which, CombResult& res)
{
    const StrandSet& strands = run.strands;
    const std::size_t n = run.n;
    const bool relative = head.policy() == HeadPolicy::NoDeeper;
    StrandSet combed = selectStrands(res.strands, which);
    std::vector<float> allowed(combed.numVertices(), 0.f);
    if (relative) {
        std::size_t w = 0;
        HeadObstacle::Probe probe(head);
        for (std::size_t s = 0; s < n; ++s) {
            if (!which[s]) continue;
            float* a = allowed.data() + w;
            for (std::size_t v = 0; v < strands.size(s); ++v, ++w) allowed[w] = float(std::max(0.0, -probe.distance(Vec3d(strands.data(s)[v]))));
            // Where the input leaves the head, the combed strand rises over a length.
            limitAllowanceFall(res.strands.data(s), strands.size(s), a);
        }
    }
    const HeadCollisionStats hc = resolveHeadCollisions(combed, head, allowed, {}, run.threaded);
    std::size_t t = 0;
    for (std::size_t s = 0; s < n; ++s) {
        if (!which[s]) continue;
        std::copy(combed.data(t), combed.data(t) + combed.size(t), res.strands.data(s));
        ++t;
    }
    return hc.strandsMoved;
}

/// Strands of @a res.strands with a turn over kKinkDegrees between two edges that their input
/// strand does not have, among @a among.
std::vector<char> newlyKinked(const CombRun& run, const CombResult& res, const std::vector<char>& among)
{
    std::vector<char> kinked(run.n, 0);
    run.forEach(run.n, [&](std::size_t s) {
        const std::size_t m = run.strands.size(s);
        if (among[s] && m >= 2) kinked[s] = char(gainsKink(run.strands.data(s), res.strands.data(s), m));
    });
    return kinked;
}

/// How many halvings comb's back-off searches the share of a kinked strand's turn in: the kept
/// share is within 1/64 of the largest that makes no new kink (where that is one interval).
constexpr int kBackOffSteps = 6;

/// Step 2b, the head and the back-off: the combed strands swept out of @a head (when not empty);
/// then every strand with a new kink (a turn over kKinkDegrees between two edges that its input
/// does not have: the comb's turn and the head's push together bend it at one vertex) is combed
/// again with a share of its centre's rotations (each rotation slerped from none), the largest
/// found by halving the interval (kBackOffSteps) with which neither makes a new kink; a share of
/// 0 is the input itself, which the head leaves as it is (no vertex deeper than the input's), so
/// no strand ends with a new kink. @return how many strands were combed less.
std::size_t settleCombedStrands(const CombRun& run, const HeadObstacle& head, const std::vector<std::vector<double>>& mids, CombResult& res)
{
    const std::size_t n = run.n;
    std::vector<char> moved(n, 0);
    for (std::size_t s = 0; s < n; ++s) moved[s] = char(run.touched[std::size_t(res.cluster[s])]);
    if (!head.empty()) res.stats.headDeflected = keepStrandsOutOfHead(run, head, moved, res);
    std::vector<char> kinked = newlyKinked(run, res, moved);
    std::vector<double> lo(n, 0.0), hi(n, 1.0);
    std::size_t backedOff = 0;
    for (std::size_t s = 0; s < n; ++s) backedOff += std::size_t(kinked[s]);
    if (backedOff == 0) return 0;
    SynthStageTimer t{res.stages, "back-off"};
    const std::vector<char> backing = kinked;
    const auto combAt = [&](const std::vector<double>& share) {
        run.forEach(n, [&](std::size_t s) {
            if (backing[s]) retransferStrand(run, s, std::size_t(res.cluster[s]), mids[std::size_t(res.cluster[s])], share[s], res.strands.data(s));
        });
        if (!head.empty()) keepStrandsOutOfHead(run, head, backing, res);
    };
    std::vector<double> share(n, 0.0);
    for (int step = 0; step < kBackOffSteps; ++step) {
        for (std::size_t s = 0; s < n; ++s) share[s] = 0.5 * (lo[s] + hi[s]);
        combAt(share);
        kinked = newlyKinked(run, res, backing);
        for (std::size_t s = 0; s < n; ++s)
            if (backing[s]) (kinked[s] ? hi[s] : lo[s]) = share[s];
    }
    combAt(lo);
    return backedOff;
}

/// Step 3, what the strokes did (CombStats), from the input and the combed strands.
void measureComb(const CombRun& run, const HeadObstacle& head, CombResult& res)
{
    const StrandSet& strands = run.strands;
    const std::vector<CombStroke>& strokes = run.strokes;
    const std::size_t n = run.n;
    CombStats& st = res.stats;
    st.clusters = run.K;
    st.head = head.empty() ? std::string("none") : head.describe();
    for (std::uint8_t u : run.touched) st.combedClusters += u;
    std::vector<std::uint8_t> moved(n, 0);
    for (std::size_t s = 0; s < n; ++s) moved[s] = run.touched[std::size_t(res.cluster[s])];
    for (std::uint8_t u : moved) st.movedStrands += u;
    {
        // Per strand partial sums, added in strand order (the same on any thread count).
        std::vector<double> before(n, 0.0), after(n, 0.0);
        std::vector<std::size_t> count(n, 0), insideBefore(n, 0), insideAfter(n, 0);
        std::vector<std::uint8_t> kinked(n, 0);
        run.forEach(n, [&](std::size_t s) {
            const Vec3f* a = strands.data(s);
            const Vec3f* b = res.strands.data(s);
            const std::size_t m = strands.size(s);
            if (moved[s] && !head.empty()) {
                HeadObstacle::Probe probe(head);
                for (std::size_t v = 0; v < m; ++v) {
                    insideBefore[s] += probe.distance(Vec3d(a[v])) < 0.0;
                    insideAfter[s] += probe.distance(Vec3d(b[v])) < 0.0;
                }
            }
            if (m < 2) return;
            if (moved[s]) kinked[s] = gainsKink(a, b, m);
            for (const CombStroke& k : strokes)
                for (std::size_t v = 0; v < m; ++v) {
                    Vec3d dirA, dirB;
                    if (!(strokeDistance(k, Vec3d(a[v]), &dirA) < k.radius)) continue;
                    strokeDistance(k, Vec3d(b[v]), &dirB);
                    const std::size_t i = std::min(v, m - 2);
                    const Vec3d ta = (Vec3d(a[i + 1]) - Vec3d(a[i])).unitSafe(), tb = (Vec3d(b[i + 1]) - Vec3d(b[i])).unitSafe();
                    before[s] += std::acos(std::clamp(ta.dot(dirA), -1.0, 1.0));
                    after[s] += std::acos(std::clamp(tb.dot(dirB), -1.0, 1.0));
                    ++count[s];
                }
        });
        double sb = 0.0, sa = 0.0;
        for (std::size_t s = 0; s < n; ++s) {
            sb += before[s];
            sa += after[s];
            st.reachVertices += count[s];
            st.insideHeadBefore += insideBefore[s];
            st.insideHeadAfter += insideAfter[s];
            st.newKinks += kinked[s];
        }
        if (st.reachVertices) {
            st.angleBefore = sb / double(st.reachVertices) * 180.0 / M_PI;
            st.angleAfter = sa / double(st.reachVertices) * 180.0 / M_PI;
        }
    }
    if (st.movedStrands) {
        StrandSet a, b;
        for (std::size_t s = 0; s < n; ++s)
            if (moved[s]) {
                a.addStrand(strands.data(s), strands.size(s));
                b.addStrand(res.strands.data(s), res.strands.size(s));
            }
        const std::vector<double> ta = turningPerLength(a), tb = turningPerLength(b);
        for (double x : ta) st.turningBefore += x;
        for (double x : tb) st.turningAfter += x;
        st.turningBefore /= double(ta.size());
        st.turningAfter /= double(tb.size());
    }
}

} // namespace

CombResult combHair(const StrandSet& strands, const std::vector<CombStroke>& strokes, const CombParams& params,
                    openvdb::FloatGrid::ConstPtr scalp, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    params.validate("combHair");
    for (std::size_t i = 0; i < strokes.size(); ++i) validateStroke(strokes[i], i, "combHair");
    if (strokes.empty()) throw ValueError("combHair: no strokes");
    if (strands.numStrands() == 0) throw ValueError("combHair: no strands to comb");
    CombRun run(strands, strokes, params, threaded);
    CombResult res;
    clusterHair(run, scalp, interrupter, res);
    deformCoarsest(run, res);
    if (interrupter && interrupter->wasInterrupted()) throw InterruptedError("combing interrupted");
    // The head the combed strands are kept out of (keepOutOfHead()).
    const HeadObstacle head = !params.head.unset() ? params.head
                              : scalp             ? HeadObstacle::levelSet(scalp, HeadPolicy::NoDeeper)
                                                  : headFromRoots(strands);
    std::vector<std::vector<double>> mids;
    retransferDetail(run, res, mids);
    res.stats.backedOff = settleCombedStrands(run, head, mids, res);
    measureComb(run, head, res);
    return res;
}

} // namespace vdbhair
