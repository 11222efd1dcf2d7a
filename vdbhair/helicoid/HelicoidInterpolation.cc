#include "HelicoidInterpolation.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Rotation.h>
#include <vdbhair/helicoid/FrameAverage.h>
#include <vdbhair/strands/Resample.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace vdbhair {

namespace {

bool finite3(const Vec3d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

constexpr double kArcTurn = 0.2;  ///< radians of the most-turning guide per arc (automatic count)
constexpr std::size_t kMinArcs = 16, kMaxArcs = 512;
/// HelicoidBlend::Arcs blends only guides shaped like the heaviest: root-relative points at
/// kShapeSamples equal fractions of the length, a mean distance below kUnlike of the length.
constexpr std::size_t kShapeSamples = 16;
constexpr double kUnlike = 0.25;

/// @a ref turned by the least rotation that takes ref.t onto the unit @a t (a half turn about ref.n
/// when @a t is opposite).
FrameD leastRotationOnto(const FrameD& ref, const Vec3d& t)
{
    Vec3d axis;
    double c, s;
    if (!shortestRotation(ref.t, t, axis, c, s)) return FrameD::fromTangentNormal(t, ref.n);  // t along ref.t or opposite it
    return FrameD::fromTangentNormal(t, rotateAbout(ref.n, axis, c, s));
}

/// The unit tangent at arc length @a s of @a tr (its frames' tangents, linear between points),
/// @a k the point to search from (advanced: calls come in increasing s).
Vec3d tangentAt(const HelicoidTrace& tr, double s, std::size_t& k)
{
    const std::size_t n = tr.arc.size();
    while (k + 2 < n && tr.arc[k + 1] < s) ++k;
    if (n < 2) return tr.frames.front().t;
    const double len = tr.arc[k + 1] - tr.arc[k];
    const double f = len > 0.0 ? std::min(1.0, std::max(0.0, (s - tr.arc[k]) / len)) : 0.0;
    Vec3d t = tr.frames[k].t * (1.0 - f) + tr.frames[k + 1].t * f;
    const double l = t.length();
    return l > 0.0 ? t / l : tr.frames[k].t;
}

} // namespace

const ParamTable<HelicoidInterpolationParams>& helicoidInterpolationParameters()
{
    using P = HelicoidInterpolationParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto blend = makeParam<P>("blend", "helicoid: arcs (each guide re-described as equal circular arcs in its rotation-minimizing frame, so guides "
                                           "blend alike) or fitted (the fits' own pieces, as the paper prints it)", "",
                                  named<P>([](P& p) -> HelicoidBlend& { return p.blend; }, helicoidBlendName, helicoidBlendFromName));
        blend.choices = {"arcs", "fitted"};
        t.push_back(blend);
        auto arcs = makeParam<P>("arcs", "blend arcs: arcs per hair", "", member<P>([](P& p) -> std::size_t& { return p.arcs; }));
        arcs.min = 0;
        arcs.zeroMeans = "one per " + formatNumber(kArcTurn) + " radian of the most-turning guide, " + std::to_string(kMinArcs) + " to " + std::to_string(kMaxArcs);
        t.push_back(arcs);
        auto power = makeParam<P>("power", "helicoid: Shepard exponent p, a guide's weight d^-p at root distance d (the paper uses 3)", "",
                                  member<P>([](P& p) -> double& { return p.shepard.power; }));
        power.min = 0.0;
        power.aboveMin = true;
        t.push_back(power);
        return t;
    }();
    return table;
}

const char* helicoidBlendName(HelicoidBlend blend) { return blend == HelicoidBlend::Arcs ? "arcs" : "fitted"; }

HelicoidBlend helicoidBlendFromName(const std::string& name)
{
    if (name == "arcs") return HelicoidBlend::Arcs;
    if (name == "fitted") return HelicoidBlend::Fitted;
    throw ParamError<ValueError>({paramName(helicoidInterpolationParameters(), "blend"), " '" + name + "' is not one of arcs, fitted"});
}

FrameD surfaceFrame(const Vec3d& normal, const Vec3d& up)
{
    const double len = normal.length();
    if (!(len > 0.0) || !std::isfinite(len)) throw ValueError("surface normal " + formatNumber(len) + " long: must be a non-zero finite vector");
    const Vec3d n = normal / len;
    // up, then x, then z: the first not within ~8° of the normal (as `vdbhair roots`).
    const Vec3d candidates[3] = {up, Vec3d(1.0, 0.0, 0.0), Vec3d(0.0, 0.0, 1.0)};
    for (const Vec3d& c : candidates) {
        const Vec3d u = c - n * n.dot(c);
        if (u.length() > 0.14 * c.length()) return FrameD::fromTangentNormal(n, u);
    }
    return FrameD::fromTangentNormal(n, Vec3d(0.0, 1.0, 0.0) - n * n.y());
}

void validateGuideScene(const Scene& guides)
{
    if (guides.guides.empty()) throw ValueError("no guides: interpolation needs at least one guide");
    if (!(guides.step > 0.0) || !std::isfinite(guides.step)) throw ValueError("scene step " + formatNumber(guides.step) + ": must be a positive finite length");
    for (std::size_t g = 0; g < guides.guides.size(); ++g) {
        const SceneGuide& sg = guides.guides[g];
        const std::string where = "guide " + std::to_string(g) + ": ";
        if (sg.pieces.empty()) throw ValueError(where + "has no pieces");
        if (!finite3(sg.root)) throw ValueError(where + "root is not finite");
        if (!finite3(sg.frame.t) || !finite3(sg.frame.n)) throw ValueError(where + "frame is not finite");
        if (!(sg.step >= 0.0) || !std::isfinite(sg.step)) throw ValueError(where + "step " + formatNumber(sg.step) + ": must be a positive finite length");
        double total = 0.0;
        for (std::size_t i = 0; i < sg.pieces.size(); ++i) {
            const HelicoidPiece& p = sg.pieces[i];
            const std::string pw = where + "piece " + std::to_string(i) + ": ";
            if (!std::isfinite(p.k.kT) || !std::isfinite(p.k.kN) || !std::isfinite(p.k.kB) || !std::isfinite(p.k.alpha)) {
                throw ValueError(pw + "k is not finite; every value of a piece must be a finite number");
            }
            if (!std::isfinite(p.roll)) throw ValueError(pw + "roll is not finite; every value of a piece must be a finite number");
            if (!(p.length >= 0.0) || !std::isfinite(p.length)) throw ValueError(pw + "length " + formatNumber(p.length) + ": must be zero or a positive finite length");
            total += p.length;
        }
        if (!(total > 0.0)) throw ValueError(where + "zero length: a guide must have a positive length");
    }
}

/// One guide, normalized for blending (kT sign rule applied, roll of the first piece folded in).
struct HelicoidInterpolator::Prepared
{
    double length = 0.0, step = 0.0;
    std::vector<HelicoidParams> k;  ///< per piece, kT >= 0 under the sign rule
    std::vector<double> entryRoll;  ///< per piece: its roll about E_T where it begins (index 0 unused)
    std::vector<double> c;          ///< normalized arc length of each breakpoint, #P + 1
};

/// One guide described as equal circular arcs (HelicoidBlend::Arcs).
struct HelicoidInterpolator::ArcGuide
{
    std::vector<double> c;  ///< 2 per arc: the curvature vector in the carried frame's (E_N, E_B)
    std::vector<Vec3d> shape;  ///< kShapeSamples points at equal arc lengths, root to tip, less the root (in W's axes with surface frames)
};

HelicoidInterpolator::HelicoidInterpolator(const Scene& guides, const HelicoidInterpolationParams& params,
                                           const std::vector<Vec3d>& guideNormals)
    : mScene(guides), mParams(params)
{
    validateGuideScene(guides);
    validateShepardParams(params.shepard);
    const std::size_t G = guides.guides.size();
    if (!guideNormals.empty() && guideNormals.size() != G) {
        throw ValueError(std::to_string(guideNormals.size()) + " guide normals for " + std::to_string(G) + " guides");
    }
    mSurface = !guideNormals.empty();
    mGuides.resize(G);
    mFirstFrames.resize(G);
    std::vector<Vec3d> roots(G);
    double minStep = std::numeric_limits<double>::max(), maxLength = 0.0;
    std::size_t maxPieces = 0;
    for (std::size_t g = 0; g < G; ++g) {
        const SceneGuide& sg = guides.guides[g];
        Prepared& p = mGuides[g];
        roots[g] = sg.root;
        p.step = sg.step > 0.0 ? sg.step : guides.step;
        const std::size_t P = sg.pieces.size();
        p.k.resize(P);
        p.entryRoll.assign(P, 0.0);
        p.c.assign(P + 1, 0.0);
        bool previousFlip = false;
        double firstRoll = 0.0;
        for (std::size_t i = 0; i < P; ++i) {
            const HelicoidPiece& pc = sg.pieces[i];
            const bool flip = params.kTSignRule && pc.k.kT < 0.0;
            p.k[i] = pc.k;
            if (flip) p.k[i].kT = -pc.k.kT;
            // A frame after a flipped piece is itself turned by π: a half turn only where the state changes.
            const double roll = pc.roll + (flip != previousFlip ? M_PI : 0.0);
            if (i == 0) firstRoll = roll;
            else p.entryRoll[i] = roll;
            previousFlip = flip;
            p.length += pc.length;
            p.c[i + 1] = p.length;
        }
        for (double& v : p.c) v /= p.length;
        p.c[P] = 1.0;
        FrameD q = sg.frame.rolled(firstRoll);
        if (mSurface) q = relativeFrame(q, surfaceFrame(guideNormals[g], params.up));
        mFirstFrames[g] = q;
        minStep = std::min(minStep, p.step);
        maxLength = std::max(maxLength, p.length);
        maxPieces = std::max(maxPieces, P);
    }
    mNormals = guideNormals;
    if (params.blend == HelicoidBlend::Arcs) {
        prepareArcs(guideNormals);
        maxPieces = std::max(maxPieces, mArcCount);
    }
    const double perHair = maxLength / minStep + double(maxPieces) + 1.0;
    mMaxVertices = perHair < 1e18 ? std::size_t(std::ceil(perHair)) : std::numeric_limits<std::size_t>::max();
    mLocator = std::make_unique<GuideLocator>(std::move(roots));
}

void HelicoidInterpolator::prepareArcs(const std::vector<Vec3d>& guideNormals)
{
    const std::size_t G = mScene.guides.size();
    std::vector<HelicoidTrace> traces(G);
    double maxTurn = 0.0;
    Vec3d meanTangent(0.0);
    for (std::size_t g = 0; g < G; ++g) {
        const SceneGuide& sg = mScene.guides[g];
        tracePHelicoid(sg.root, sg.frame, sg.pieces, mGuides[g].step, mScene.integrator, traces[g]);
        const HelicoidTrace& tr = traces[g];
        double turn = 0.0;
        for (std::size_t k = 1; k < tr.frames.size(); ++k) {
            turn += std::atan2(tr.frames[k - 1].t.cross(tr.frames[k].t).length(), tr.frames[k - 1].t.dot(tr.frames[k].t));
        }
        maxTurn = std::max(maxTurn, turn);
        meanTangent += tr.frames.front().t;
    }
    mArcCount = mParams.arcs ? mParams.arcs
                             : std::min(kMaxArcs, std::max(kMinArcs, std::size_t(std::ceil(maxTurn / kArcTurn))));
    // Without surface normals, one reference frame for every guide.
    const double ml = meanTangent.length();
    const FrameD shared = surfaceFrame(ml > 1e-9 ? meanTangent / ml : mParams.up, mParams.up);
    mArcs.resize(G);
    mArcFrames.resize(G);
    const std::size_t A = mArcCount;
    for (std::size_t g = 0; g < G; ++g) {
        const HelicoidTrace& tr = traces[g];
        ArcGuide& a = mArcs[g];
        const FrameD W = mSurface ? surfaceFrame(guideNormals[g], mParams.up) : shared;
        FrameD R = leastRotationOnto(W, tr.frames.front().t);
        mArcFrames[g] = mSurface ? relativeFrame(R, W) : R;
        // The trace at kShapeSamples + 1 equal arc lengths (the root first), less the root.
        std::vector<Vec3f> traced(tr.points.begin(), tr.points.end()), sampled(kShapeSamples + 1);
        resamplePolyline(traced.data(), traced.size(), sampled.size(), sampled.data());
        a.shape.resize(kShapeSamples);
        for (std::size_t q = 0; q < kShapeSamples; ++q) {
            const Vec3d d = Vec3d(sampled[q + 1]) - Vec3d(sampled[0]);
            a.shape[q] = mSurface ? Vec3d(d.dot(W.t), d.dot(W.n), d.dot(W.b)) : d;
        }
        a.c.assign(2 * A, 0.0);
        const double ds = tr.arc.back() / double(A);
        std::size_t k = 0;
        for (std::size_t j = 0; j < A; ++j) {
            const Vec3d t0 = R.t, t1 = tangentAt(tr, ds * double(j + 1), k);
            const Vec3d axis = t0.cross(t1);
            const double sn = axis.length(), cs = t0.dot(t1);
            if (!(sn > 1e-12) || !(ds > 0.0)) {
                R = FrameD::fromTangentNormal(t1, R.n);
                continue;
            }
            const double theta = std::atan2(sn, cs), kappa = theta / ds;
            const Vec3d bend = (t1 - t0 * cs) / sn;  // unit, across t0 towards t1
            a.c[2 * j] = kappa * bend.dot(R.n);
            a.c[2 * j + 1] = kappa * bend.dot(R.b);
            // Carry the frame along the arc: the rotation about its axis that takes t0 onto t1.
            R = FrameD::fromTangentNormal(t1, rotateAbout(R.n, axis / sn, cs, sn));
        }
    }
}

HelicoidInterpolator::~HelicoidInterpolator() = default;

void HelicoidInterpolator::weights(const Vec3d& root, std::vector<GuideWeight>& out) const
{
    mLocator->shepardWeights(root, mParams.shepard, out);
}

FrameD HelicoidInterpolator::placeFirstFrame(const FrameD& avg, const std::vector<GuideWeight>& ws, const Vec3d* normal) const
{
    if (!mSurface) return avg;
    if (normal) return composeFrames(surfaceFrame(*normal, mParams.up), avg);
    // Guide frames are relative to their surface frames; without a normal here, use the heaviest's.
    std::size_t h = 0;
    for (std::size_t i = 1; i < ws.size(); ++i) if (ws[i].weight > ws[h].weight) h = i;
    return composeFrames(surfaceFrame(mNormals[ws[h].guide], mParams.up), avg);
}

void HelicoidInterpolator::blendWaviness(const std::vector<GuideWeight>& ws, SceneGuide& out) const
{
    // Waviness (Eq. 4) by the same weights.
    double wavyWeight = 0.0;
    for (const GuideWeight& gw : ws) if (mScene.guides[gw.guide].waviness) wavyWeight += gw.weight;
    if (!(wavyWeight > 0.0)) return;
    WavinessParams wp;
    double s = 0.0, c = 0.0;
    for (const GuideWeight& gw : ws) {
        const auto& w = mScene.guides[gw.guide].waviness;
        if (!w) continue;
        wp.amplitude += gw.weight * w->amplitude;
        wp.noise += gw.weight * w->noise;
        wp.frequency += gw.weight / wavyWeight * w->frequency;
        s += gw.weight * std::sin(w->phase);
        c += gw.weight * std::cos(w->phase);
    }
    wp.phase = std::atan2(s, c);
    out.waviness = wp;
}

SceneGuide HelicoidInterpolator::interpolateArcs(const std::vector<GuideWeight>& wsIn, const Vec3d& root, const Vec3d* normal) const
{
    // Only guides shaped like the heaviest take part: blending the bends of hair that goes another
    // way (across a parting, a whorl) sends the new hair sideways or straight out. A guide's
    // unlikeness is the mean distance between its shape and the heaviest's (root-relative points
    // at equal fractions of the length) over the longer length; its weight is multiplied by
    // (1 - (u / kUnlike)²)², zero from kUnlike on.
    thread_local std::vector<GuideWeight> ws;
    ws = wsIn;
    {
        std::size_t h0 = 0;
        for (std::size_t i = 1; i < ws.size(); ++i) if (ws[i].weight > ws[h0].weight) h0 = i;
        const ArcGuide& ref = mArcs[ws[h0].guide];
        double sum = 0.0;
        std::size_t kept = 0;
        for (const GuideWeight& gw : ws) {
            const ArcGuide& g = mArcs[gw.guide];
            double d = 0.0;
            for (std::size_t q = 0; q < kShapeSamples; ++q) d += (g.shape[q] - ref.shape[q]).length();
            const double u = d / double(kShapeSamples) / std::max(mGuides[gw.guide].length, mGuides[ws[h0].guide].length) / kUnlike;
            if (!(u < 1.0)) continue;
            ws[kept] = gw;
            ws[kept].weight *= (1.0 - u * u) * (1.0 - u * u);
            sum += ws[kept++].weight;
        }
        ws.resize(kept);
        for (GuideWeight& gw : ws) gw.weight /= sum;
    }
    SceneGuide out;
    out.root = root;
    const std::size_t A = mArcCount;
    // The new hair's first frame: the weighted mean root tangent, with the heaviest guide's frame
    // carried onto it by the least rotation. Each guide's arcs are turned into that frame's axes
    // (its own first frame carried onto the same tangent differs from it by a roll about it), so
    // curvature vectors of neighbouring guides blend in one gauge whatever their frames' rolls.
    std::size_t h = 0;
    Vec3d tangent(0.0);
    for (std::size_t i = 0; i < ws.size(); ++i) {
        if (ws[i].weight > ws[h].weight) h = i;
        tangent += ws[i].weight * mArcFrames[ws[i].guide].t;
    }
    const double tl = tangent.length();
    tangent = tl > 1e-9 ? tangent / tl : mArcFrames[ws[h].guide].t;
    const FrameD F = leastRotationOnto(mArcFrames[ws[h].guide], tangent);
    double length = 0.0, step = 0.0;
    thread_local std::vector<double> c;
    c.assign(2 * A, 0.0);
    for (const GuideWeight& gw : ws) {
        const ArcGuide& g = mArcs[gw.guide];
        length += gw.weight * mGuides[gw.guide].length;
        step += gw.weight * mGuides[gw.guide].step;
        const Vec3d n = leastRotationOnto(mArcFrames[gw.guide], tangent).n;
        const double cd = n.dot(F.n), sd = n.dot(F.b);  // the roll between the two, as cosine and sine
        for (std::size_t j = 0; j < A; ++j) {
            const double x = g.c[2 * j], y = g.c[2 * j + 1];
            c[2 * j] += gw.weight * (x * cd - y * sd);
            c[2 * j + 1] += gw.weight * (x * sd + y * cd);
        }
    }
    out.step = step;
    out.pieces.resize(A);
    double psiPrev = 0.0, psi0 = 0.0;
    for (std::size_t j = 0; j < A; ++j) {
        const double kappa = std::hypot(c[2 * j], c[2 * j + 1]);
        // A straight arc keeps the previous bending plane (its roll is 0).
        const double psi = kappa > 0.0 ? std::atan2(c[2 * j + 1], c[2 * j]) : psiPrev;
        HelicoidPiece& pc = out.pieces[j];
        pc.k.kT = kappa;
        pc.length = length / double(A);
        if (j == 0) psi0 = psi;
        else pc.roll = std::remainder(psi - psiPrev, 2.0 * M_PI);
        psiPrev = psi;
    }
    out.frame = placeFirstFrame(F, ws, normal).rolled(psi0);
    blendWaviness(ws, out);
    return out;
}

SceneGuide HelicoidInterpolator::interpolate(const Vec3d& root, const Vec3d* normal) const
{
    thread_local std::vector<GuideWeight> ws;
    weights(root, ws);
    if (mParams.blend == HelicoidBlend::Arcs && ws.size() > 1) return interpolateArcs(ws, root, normal);
    if (mParams.pieceCount == PieceCountRule::Heaviest && ws.size() > 1) {
        // Only guides with the heaviest's piece count take part (weights renormalized over them).
        std::size_t h = 0;
        for (std::size_t i = 1; i < ws.size(); ++i) if (ws[i].weight > ws[h].weight) h = i;
        const std::size_t P = mGuides[ws[h].guide].k.size();
        double sum = 0.0;
        std::size_t kept = 0;
        for (const GuideWeight& gw : ws) {
            if (mGuides[gw.guide].k.size() != P) continue;
            ws[kept++] = gw;
            sum += gw.weight;
        }
        ws.resize(kept);
        for (GuideWeight& gw : ws) gw.weight /= sum;
    }
    const bool surface = mSurface && normal;
    const FrameD W = surface ? surfaceFrame(*normal, mParams.up) : FrameD();

    // A single weight: the guide itself, moved to the root (and turned with the surface frame).
    if (ws.size() == 1) {
        SceneGuide out = mScene.guides[ws[0].guide];
        out.root = root;
        out.wisp.reset();
        out.fit = nullptr;
        if (surface) out.frame = composeFrames(W, relativeFrame(out.frame, surfaceFrame(mNormals[ws[0].guide], mParams.up)));
        return out;
    }

    SceneGuide out;
    out.root = root;
    // Frame of the first piece (§4.1, §4.3).
    out.frame = placeFirstFrame(averageFrames(mFirstFrames, ws), ws, normal);

    // Length, step and the piece count.
    double length = 0.0, step = 0.0;
    std::size_t P = 0;
    for (const GuideWeight& gw : ws) {
        const Prepared& g = mGuides[gw.guide];
        length += gw.weight * g.length;
        step += gw.weight * g.step;
        if (gw.weight > 0.0) P = std::max(P, g.k.size());
    }
    out.step = step;

    // Breakpoints b_j = Σ w_i C_i(j / P) and the pieces (§4.2, the rule in the header).
    auto C = [](const Prepared& g, double u) {
        const std::size_t Pi = g.k.size();
        const double x = u * double(Pi);
        const std::size_t m = std::min<std::size_t>(std::size_t(x), Pi - 1);
        return g.c[m] + (x - double(m)) * (g.c[m + 1] - g.c[m]);
    };
    auto pieceOf = [](const Prepared& g, std::size_t j, std::size_t P) {
        const std::size_t Pi = g.k.size();
        return std::min<std::size_t>(std::size_t((double(j) + 0.5) * double(Pi) / double(P)), Pi - 1);
    };
    out.pieces.resize(P);
    double bPrev = 0.0;
    for (std::size_t j = 0; j < P; ++j) {
        double bNext = 1.0;
        if (j + 1 < P) {
            bNext = 0.0;
            for (const GuideWeight& gw : ws) bNext += gw.weight * C(mGuides[gw.guide], double(j + 1) / double(P));
        }
        HelicoidPiece& pc = out.pieces[j];
        double sinSum = 0.0, cosSum = 0.0;
        for (const GuideWeight& gw : ws) {
            const Prepared& g = mGuides[gw.guide];
            const std::size_t m = pieceOf(g, j, P);
            pc.k.kT += gw.weight * g.k[m].kT;
            pc.k.kN += gw.weight * g.k[m].kN;
            pc.k.kB += gw.weight * g.k[m].kB;
            pc.k.alpha += gw.weight * g.k[m].alpha;
            if (j > 0) {
                const double r = (m != pieceOf(g, j - 1, P)) ? g.entryRoll[m] : 0.0;
                sinSum += gw.weight * std::sin(r);
                cosSum += gw.weight * std::cos(r);
            }
        }
        pc.roll = (j > 0 && sinSum != 0.0) ? std::atan2(sinSum, cosSum) : 0.0;
        pc.length = std::max(0.0, bNext - bPrev) * length;
        bPrev = bNext;
    }

    blendWaviness(ws, out);
    return out;
}

Scene interpolateHelicoids(const Scene& guides, const InterpolationRoots& roots, const HelicoidInterpolationParams& params,
                           const std::vector<Vec3d>& guideNormals, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    const std::size_t R = roots.positions.size();
    if (R == 0) throw ValueError("no roots: interpolation needs at least one root");
    if (!roots.normals.empty() && roots.normals.size() != R) {
        throw ValueError(std::to_string(roots.normals.size()) + " root normals for " + std::to_string(R) + " roots");
    }
    for (std::size_t i = 0; i < R; ++i) {
        if (!finite3(roots.positions[i])) throw ValueError("root " + std::to_string(i) + " is not finite");
        if (!roots.normals.empty() && (!finite3(roots.normals[i]) || !(roots.normals[i].length() > 0.0))) {
            throw ValueError("root " + std::to_string(i) + ": normal is zero or not finite");
        }
    }
    // Guide normals: given, or those of the roots nearest the guides.
    std::vector<Vec3d> gn = guideNormals;
    if (gn.empty() && !roots.normals.empty()) {
        validateGuideScene(guides);
        const GuideLocator near(roots.positions);
        gn.reserve(guides.guides.size());
        for (const SceneGuide& g : guides.guides) gn.push_back(roots.normals[near.nearest(g.root)]);
    }
    const HelicoidInterpolator interp(guides, params, gn);
    // Estimate first: never allocate from an unchecked count.
    const double estimate = double(R) * double(interp.maxVerticesPerHair());
    if (estimate > double(params.maxVertices)) {
        throw LimitError(std::to_string(R) + " hairs would grow up to " + formatNumber(estimate) + " vertices, more than the cap of " +
                         std::to_string(params.maxVertices) + " (fewer roots, shorter guides or a larger step)");
    }
    Scene out;
    out.seed = guides.seed;
    out.step = guides.step;
    out.integrator = guides.integrator;
    out.head = guides.head;
    out.guides.resize(R);
    ProgressCounter progress(interrupter, "interpolating helicoids", R, "hairs");
    auto body = [&](const tbb::blocked_range<std::size_t>& r) {
        if (progress.stopped()) return;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            out.guides[i] = interp.interpolate(roots.positions[i], roots.normals.empty() ? nullptr : &roots.normals[i]);
        }
        progress.add(r.size());
    };
    if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, R, 256), body);
    else body(tbb::blocked_range<std::size_t>(0, R));
    if (progress.stopped()) throw InterruptedError("interpolateHelicoids: interrupted");
    return out;
}

Scene guideSceneFromStrands(const StrandSet& strands, const FitParams& fit, const std::string& where, bool threaded,
                            openvdb::util::NullInterrupter* interrupter)
{
    if (strands.empty()) throw ValueError(where + ": no guides: interpolation needs at least one");
    std::vector<std::string> errors;
    const std::vector<StrandFit> fits = fitStrands(strands, fit, threaded, &errors, interrupter);
    Scene scene;
    scene.integrator = HelicoidIntegrator::RK4;
    for (std::size_t i = 0; i < fits.size(); ++i) {
        if (!errors[i].empty()) throw ValueError(where + ": guide " + errors[i] + "; a guide must have a positive length");
        scene.guides.push_back(guideFromFit(fits[i]));
    }
    scene.step = scene.guides.front().step;
    return scene;
}

std::vector<Vec3d> sceneGuideNormals(const Scene& guides)
{
    std::vector<Vec3d> normals;
    if (!guides.head) return normals;
    for (const SceneGuide& g : guides.guides) normals.push_back(g.root - guides.head->center);
    return normals;
}

} // namespace vdbhair
