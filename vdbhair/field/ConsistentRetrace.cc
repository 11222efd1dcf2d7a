#include "ConsistentRetrace.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/Memory.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/Progress.h>
#include <vdbhair/field/FieldMapping.h>
#include <vdbhair/field/FieldSampler.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/Simd.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/strands/Measures.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>

namespace vdbhair {

void ConsistencyParams::validate(const char* where) const
{
    // Named as refine declares them (refineParameters()); the rest are no verb's parameters.
    auto fail = [&](const ParamName& name, double value, const ParamText& rule) {
        ParamText text{std::string(where) + ": ", name, " " + formatNumber(value) + ": "};
        text += rule;
        throw ParamError<ValueError>(text);
    };
    const ParamName start = paramName(refineParameters(), "outlier-start");
    resolveStepLength(step, 1.0, where);  // the engine's rule for a step (Streamline.h)
    if (!(zStart >= 0.0) || !std::isfinite(zStart)) fail(start, zStart, {"must be finite and at least 0"});
    if (!(zFull > zStart) || !std::isfinite(zFull))
        fail(paramName(refineParameters(), "outlier-full"), zFull, {"must be finite and above ", start, " " + formatNumber(zStart)});
    if (!(minSpreadDeg >= 0.0 && minSpreadDeg < 90.0)) fail(paramName(refineParameters(), "min-spread"), minSpreadDeg, {"must be in [0, 90) degrees"});
    if (!(returnVoxels > 0.0) || !std::isfinite(returnVoxels)) fail(ParamName{"returnVoxels", "returnVoxels"}, returnVoxels, {"must be positive and finite"});
    if (!(vanishThreshold >= 0.0 && vanishThreshold < 1.0)) fail(ParamName{"vanishThreshold", "vanishThreshold"}, vanishThreshold, {"must be in [0, 1)"});
}

namespace {

using openvdb::Vec3d;
using TreeT = openvdb::Vec3STree;

/// cos 110°: where a field pointing back along the strand stops pulling it (fieldPull()).
constexpr double kOpposedCos = -0.34202014332566873;

double smoothstep(double a, double b, double x)
{
    const double t = std::min(1.0, std::max(0.0, (x - a) / (b - a)));
    return t * t * (3.0 - 2.0 * t);
}

struct Shared
{
    const StrandSet& in;
    const FieldMapping map;
    const FieldMapping volumeMap;
    const BrickedField<TreeT>& tangents;  ///< with the spread grid as its scalar
    const BrickedField<TreeT>& volume;
    /// Whether the hair volume is the tangent field's own grid (volume is tangents, volumeMap is
    /// map): insideField() then samples the tangent field, and direction() reuses that sample.
    bool volumeIsTangent;
    const HairVolume& dilated;
    const HeadObstacle& head;
    const ConsistencyParams& params;
    double step;
    double minSigma;
    double invReturn;  ///< 1 / the return length (world units)
    /// where each strand's retrace goes: a copy of @a in, or @a in itself (then each strand is
    /// traced into a buffer and written over its input once traced)
    StrandSet& out;
    bool inPlace;
};

struct Counts
{
    std::size_t corrected = 0, steps = 0, fieldSteps = 0, noFieldSteps = 0, pushedOut = 0, heldIn = 0, reverted = 0;
    void add(const Counts& o)
    {
        reverted += o.reverted;
        corrected += o.corrected;
        steps += o.steps;
        fieldSteps += o.fieldSteps;
        noFieldSteps += o.noFieldSteps;
        pushedOut += o.pushedOut;
        heldIn += o.heldIn;
    }
};

/// One thread's samplers, and the retrace of one strand at a time.
class StrandTracer
{
public:
    explicit StrandTracer(const Shared& s) : mS(s), mTan(s.tangents), mVolume(s.volume), mDilated(s.dilated), mHead(s.head) {}

    void trace(std::size_t i, Counts& counts)
    {
        const std::size_t n = mS.in.size(i);
        if (mS.inPlace && mBuffer.size() < n) mBuffer.resize(n);
        Vec3f* o = mS.inPlace ? mBuffer.data() : mS.out.data(i);
        switch (mS.params.integrator) {
        case Integrator::Euler: trace<Integrator::Euler>(i, o, counts); break;
        case Integrator::RK2: trace<Integrator::RK2>(i, o, counts); break;
        case Integrator::RK3: trace<Integrator::RK3>(i, o, counts); break;
        case Integrator::RK4: trace<Integrator::RK4>(i, o, counts); break;
        }
        if (mS.inPlace && n > 0) std::memcpy(mS.out.data(i), o, n * sizeof(Vec3f));
    }

private:
    /// Retrace strand @a i of the input into @a o (its vertex count).
    template<Integrator I>
    void trace(std::size_t i, Vec3f* o, Counts& counts)
    {
        BlendSampler blend{*this, &counts};
        StreamlineIntegrator<BlendSampler> integrator(blend, I);
        constexpr bool euler = I == Integrator::Euler;
        const std::size_t n = mS.in.size(i);
        const Vec3f* c = mS.in.data(i);
        const bool haveHead = !mS.head.empty();
        const HeadRule head{haveHead, haveHead && mS.head.policy() == HeadPolicy::NoDeeper};
        Vec3d p(c[0]);
        // KeepOutside holds for the root too: a root inside the head starts on its surface.
        if (head.keepOutside() && mHead.pushOut(p, 0.0)) ++counts.pushedOut;
        o[0] = Vec3f(float(p.x()), float(p.y()), float(p.z()));
        bool corrected = false;
        for (std::size_t j = 0; j + 1 < n; ++j) {
            const InputSegment s(c[j], c[j + 1], mS.step);
            if (s.len > 0.0) {
                // On the input strand (a vertex that rounds to the input's is the input's, below), a
                // segment whose retrace is the segment itself is not traced (keepsOwnDirection()).
                if (euler && p.x() == s.a.x() && p.y() == s.a.y() && p.z() == s.a.z() &&
                    keepsOwnDirection(s.a, s.seg, s.b, s.t, s.m, s.h, head.keepOutside(), counts)) {
                    o[j + 1] = c[j + 1];
                    p = s.b;
                    continue;
                }
                const Vec3d start = p;
                bool pushed = traceSegment<I>(integrator, blend, s, head, p, corrected, counts);
                counts.steps += s.m;
                p = chordAtInputLength(start, p, s);
                // pushOut() moves only a point inside the head (the floor is never positive).
                if (head.have && mHead.distance(p) < 0.0) pushed |= mHead.pushOut(p, head.relative ? depthFloor(s.b) : 0.0);
                if (pushed) ++counts.pushedOut;
            }
            o[j + 1] = Vec3f(float(p.x()), float(p.y()), float(p.z()));
            if (o[j + 1] == c[j + 1]) p = s.b;  // back on the input strand, to the last bit
        }
        if (revertIfOutOfVolume(o, c, n, head.keepOutside())) {
            ++counts.reverted;
            return;
        }
        if (corrected) ++counts.corrected;
    }

    /// The streamline engine's sampler for one sub-step (Streamline.h): the blended direction for
    /// a strand heading `own`. A step's first stage records the field's weight and counts the
    /// sub-step; the later stages of RK2/RK3/RK4 only blend.
    struct BlendSampler
    {
        StrandTracer& tracer;
        Counts* counts;
        Vec3d own = Vec3d(0.0);
        double w = 0.0;  ///< the field's weight at the step's first stage

        SampleStatus startDirection(const Vec3d& p, Vec3d& d)
        {
            w = 0.0;
            d = tracer.direction(p, own, w, *counts);
            return SampleStatus::Ok;
        }
        SampleStatus direction(const Vec3d& p, Vec3d& d)
        {
            double stageW = 0.0;
            Counts stage;
            d = tracer.direction(p, own, stageW, stage);
            return SampleStatus::Ok;
        }
    };

    /// The head's rule for one retrace: whether there is a head, and whether its policy is
    /// NoDeeper (relative to the input strand's depth) rather than KeepOutside.
    struct HeadRule
    {
        bool have, relative;
        bool keepOutside() const { return have && !relative; }
    };

    /// One segment of the input strand, from @a a to @a b, and its sub-steps: m of length h,
    /// at most the step (set only for a segment of positive length).
    struct InputSegment
    {
        Vec3d a, b, seg, t;
        double len, h = 0.0;
        std::size_t m = 0;

        InputSegment(const Vec3f& a_, const Vec3f& b_, double step) : a(a_), b(b_), seg(b - a), len(seg.length())
        {
            if (!(len > 0.0)) return;
            t = seg / len;
            m = std::max<std::size_t>(1, std::size_t(std::ceil(len / step)));
            h = len / double(m);
        }
        /// The input strand's point at sub-step @a k of m.
        Vec3d at(std::size_t k) const { return a + seg * (double(k) / double(m)); }
    };

    /// The sub-steps of input segment @a s from @a p: each the strand's own direction steered
    /// back toward the input strand, blended with the field, held in the hair and out of the
    /// head. Sets @a corrected when the field took over a sub-step; returns whether the head
    /// pushed a sub-step out.
    template<Integrator I>
    bool traceSegment(StreamlineIntegrator<BlendSampler>& integrator, BlendSampler& blend, const InputSegment& s, const HeadRule& head,
                      Vec3d& p, bool& corrected, Counts& counts)
    {
        constexpr bool euler = I == Integrator::Euler;
        bool pushed = false;
        for (std::size_t k = 0; k < s.m; ++k) {
            // The strand's own direction, steered back toward the input strand at this
            // arc length when an earlier correction moved it away: a corrected kink
            // stays local, the rest of the strand stays where it was.
            const Vec3d off = s.at(k) - p;
            Vec3d own = s.t + off * mS.invReturn;
            const double ol = own.length();
            own = ol > 1e-12 ? own / ol : s.t;
            // A step of the engine through the blended direction (with Euler, the default,
            // q = p + h d); d is the step's direction for the constraints below.
            blend.own = own;
            Vec3d q, k1;
            blend.startDirection(p, k1);
            integrator.template advanceFrom<I>(p, k1, s.h, q);  // never fails: without a field the strand keeps its own direction
            if (blend.w >= 0.5) corrected = true;
            Vec3d d = k1;
            if constexpr (!euler) {
                const Vec3d e = q - p;
                const double el = e.length();
                if (el > 1e-12) d = e / el;
            }
            if (!insideField(q)) holdInHair(s, k, p, d, q, counts);
            // Outside the head, or for a guessed head no deeper inside than the input
            // strand at this arc length (HeadPolicy). The floor is never positive, so a
            // step that ends outside the head needs neither it nor anything below.
            const double dq = head.have ? mHead.distance(q) : 0.0;
            if (dq < 0.0) {
                const double floor = head.relative ? depthFloor(s.at(k + 1)) : 0.0;
                if (dq < floor) pushed |= slideAlongHead(p, s.h, floor, d, q);
            }
            p = q;
        }
        return pushed;
    }

    /// The step from @a p to @a q (direction @a d) would leave the hair: head for the input
    /// strand's own point at the step's end instead (the input lies inside the hair by definition).
    void holdInHair(const InputSegment& s, std::size_t k, const Vec3d& p, Vec3d& d, Vec3d& q, Counts& counts)
    {
        const Vec3d back = s.at(k + 1) - p;
        const double bl = back.length();
        if (bl > 1e-12) {
            d = back / bl;
            q = p + s.h * d;
            ++counts.heldIn;
        }
    }

    /// The step from @a p to @a q (direction @a d, length @a h) ends deeper in the head than
    /// @a floor: slide along the head, dropping the step's inward component (the step keeps its
    /// length), then move out what the surface's curvature left in. Returns whether q was pushed out.
    bool slideAlongHead(const Vec3d& p, double h, double floor, Vec3d& d, Vec3d& q)
    {
        bool pushed = false;
        const Vec3d nrm = mHead.normal(p);
        const double dn = d.dot(nrm);
        if (dn < 0.0) {
            const Vec3d slide = d - dn * nrm;
            const double sl = slide.length();
            if (sl > 1e-12) d = slide / sl;
            q = p + h * d;
        }
        // Out of the head at the step's own length: push out and pull the step back to length
        // h, a few times (a fixed point on the surface for steps much shorter than the head's
        // radius), then make sure.
        for (int it = 0; it < 3 && mHead.pushOut(q, floor); ++it) {
            pushed = true;
            const Vec3d e = q - p;
            const double el = e.length();
            if (el > 1e-12) q = p + e * (h / el);
        }
        pushed |= mHead.pushOut(q, floor);
        return pushed;
    }

    /// The output segment from @a start: the chord of the sub-steps (ending at @a p) at the input
    /// segment's own length. A path that bends inside a segment would otherwise shorten the
    /// polyline (its chord is shorter than its arc), and the strand with it.
    Vec3d chordAtInputLength(const Vec3d& start, const Vec3d& p, const InputSegment& s)
    {
        const Vec3d chord = p - start;
        const double cl = chord.length();
        if (!(cl > 1e-12)) return p;
        const Vec3d scaled = start + chord * (s.len / cl);
        if (insideField(scaled) || !insideField(p)) return scaled;
        // The chord at full length would leave the hair: aim at the input vertex.
        const Vec3d toB = s.b - start;
        const double tl = toB.length();
        return tl > 1e-12 ? start + toB * (s.len / tl) : scaled;
    }

    /// Only where the output @a o differs from the input @a c can it have left the volume on its
    /// own (containsChanged()): most strands come out unchanged, bit for bit (57-68 % of them on
    /// the benchmark's set and on real hair), and their test costs one comparison. When the
    /// corrections took the strand out of the hair volume (chords across a gap, a slide along
    /// the head), the strand is left as it was, out of the head if it must be (@a keepOutside);
    /// returns whether it was.
    bool revertIfOutOfVolume(Vec3f* o, const Vec3f* c, std::size_t n, bool keepOutside)
    {
        if (mDilated.containsChanged(o, c, n) || !mDilated.containsPolyline(c, n)) return false;
        for (std::size_t j = 0; j < n; ++j) {
            Vec3d q(c[j]);
            if (keepOutside) mHead.pushOut(q, 0.0);
            o[j] = Vec3f(float(q.x()), float(q.y()), float(q.z()));
        }
        return true;
    }

    /// How deep (a negative distance) a retraced vertex may be inside a NoDeeper head where the
    /// input vertex at the same arc length is at @a input: on or outside the surface where the
    /// input was outside it; where the input was inside, as deep plus half a sub-step, so that
    /// sub-voxel differences from the input are not pushed (each push turns a step off the flow).
    double depthFloor(const Vec3d& input)
    {
        const double d = mHead.distance(input);
        return d < 0.0 ? d - 0.5 * mS.step : 0.0;
    }

    /// Whether any corner of the hair volume's cell around world point @a q is active.
    bool insideField(const Vec3d& q)
    {
        const Vec3d iq = mS.volumeMap.worldToIndex(q);
        if (!mS.volumeIsTangent) return mVolume.sample(iq)[3] > 0.f;
        // The hair volume is the tangent field: keep the whole sample, since q is most often the
        // next sub-step's start, where direction() samples the tangent field at the same index
        // point (the same mapping of the same grid). Measured: sampling the spread here too, at
        // the same cell, was slower (insideField() also tests chord ends that are never a
        // sub-step's start, and those spread samples were wasted).
        mLastTan = mTan.sample(iq);
        mLastTanAt = iq;
        mHaveLastTan = true;
        return mLastTan[3] > 0.f;
    }

    /// The tangent field's sample at index point @a ip: the last sample kept (insideField(),
    /// keepsOwnDirection()) when it was taken at the same point, bit for bit (then the value a
    /// new sample would give), else a new one.
    Float4 sampleTangent(const Vec3d& ip)
    {
        if (mHaveLastTan && std::memcmp(&ip, &mLastTanAt, sizeof ip) == 0) return mLastTan;
        return mTan.sample(ip);
    }

    /// The field's pull on a strand heading @a t at index point @a ip, where the tangent field's
    /// sample is @a r: its unit direction @a v and weight @a w (0: the strand keeps its own
    /// direction, and @a v may be unset). Counts the sub-step as outside the field, or as
    /// following it (w >= 0.5).
    void fieldPull(const Float4& r, const Vec3d& ip, const Vec3d& t, Vec3d& v, double& w, Counts& counts)
    {
        w = 0.0;
        const double weight = r[3];
        if (!(weight > 0.0)) {
            ++counts.noFieldSteps;
            return;
        }
        v = Vec3d(r[0], r[1], r[2]);
        const double len = v.length();
        if (!(len > mS.params.vanishThreshold * weight)) {
            ++counts.noFieldSteps;
            return;
        }
        v /= len;
        const double cosA = t.dot(v);
        const double delta = cosA > 0.0 ? std::sqrt(std::max(0.0, 1.0 - cosA * cosA)) : 1.0;
        // sigma >= minSigma, so z = delta / sigma <= delta / minSigma (division rounds
        // monotonically): a strand that strays less than zStart floors keeps its own direction
        // (w = 0) whatever the voxel's spread, which then need not be sampled (half the sub-steps
        // of the benchmark's jittered set, 8 % of a real hairstyle's).
        if (mS.minSigma > 0.0 && delta / mS.minSigma < mS.params.zStart) return;
        // The spread through the tangent's cell, with its weights: the active corners' mean.
        const double spread = std::max(0.0, double(mTan.sampleScalar(ip)) / weight);
        const double sigma = std::max(mS.minSigma, std::sqrt(spread));
        w = smoothstep(mS.params.zStart, mS.params.zFull, delta / sigma);
        // A field pointing back along the strand taken for another flow (followOpposed false):
        // its pull fades from 90 to 110 degrees (ConsistentRetrace.h).
        if (cosA < 0.0 && !mS.params.followOpposed) w *= smoothstep(kOpposedCos, 0.0, cosA);
        if (w >= 0.5) ++counts.fieldSteps;
    }

    /// The blended direction at @a p for a strand heading @a t; @a w receives the field's weight.
    Vec3d direction(const Vec3d& p, const Vec3d& t, double& w, Counts& counts)
    {
        const Vec3d ip = mS.map.worldToIndex(p);
        Vec3d v;
        fieldPull(sampleTangent(ip), ip, t, v, w, counts);
        if (w <= 0.0) return t;
        Vec3d d = (1.0 - w) * t + w * v;
        const double dl = d.length();
        return dl > 1e-12 ? d / dl : v;
    }

    /// Whether the retrace of input segment a -> b (unit direction @a t, @a m sub-steps of length
    /// @a h, forward Euler) from p = a is the segment itself, and then its sub-steps' counts go to @a counts.
    /// It is where the strand's own direction wins at every sub-step's start on the segment
    /// (the field's weight is 0) and, for a KeepOutside head, every sub-step ends outside the
    /// head: in exact arithmetic each sub-step then moves h along t (the return pull aims at
    /// the point it reaches, a step held in the hair heads for that same point, a NoDeeper head's
    /// floor lies below it), and the chord is the segment. The samples of the segment's points
    /// do not depend on each other, so they overlap where the trace waits for each sub-step's end
    /// before the next: most sub-steps of real hair are of such segments.
    bool keepsOwnDirection(const Vec3d& a, const Vec3d& seg, const Vec3d& b, const Vec3d& t, std::size_t m, double h,
                           bool keepOutside, Counts& counts)
    {
        Counts own;
        for (std::size_t k = 0; k <= m; ++k) {
            const Vec3d x = k == m ? b : a + seg * (double(k) / double(m));  // the points of the trace's sub-steps
            const Vec3d ip = mS.map.worldToIndex(x);
            // A segment's start is the last one's end, sampled there already (a third of the
            // samples of a segment of two sub-steps): reused, bit for bit, and the end kept for the next.
            const Float4 r = k == 0 ? sampleTangent(ip) : mTan.sample(ip);
            if (k == m) {
                mLastTan = r;
                mLastTanAt = ip;
                mHaveLastTan = true;
            }
            if (k > 0) {
                // The end of sub-step k - 1, as insideField() and the head's test see it.
                const bool inside = mS.volumeIsTangent ? r[3] > 0.f : mVolume.sample(mS.volumeMap.worldToIndex(x))[3] > 0.f;
                if (!inside && h > 1e-12) ++own.heldIn;  // as the trace counts it
                if (keepOutside && mHead.distance(x) < 0.0) return false;
            }
            if (k < m) {
                Vec3d v;
                double w;
                fieldPull(r, ip, t, v, w, own);
                if (w > 0.0) return false;
            }
        }
        own.steps = m;
        counts.add(own);
        return true;
    }

    const Shared& mS;
    std::vector<Vec3f> mBuffer;  ///< one strand's retrace when in place
    FieldSampler<TreeT> mTan, mVolume;
    HairVolume::Probe mDilated;
    HeadObstacle::Probe mHead;
    Float4 mLastTan = {0.f, 0.f, 0.f, 0.f};  ///< the last sample of the tangent field kept for reuse (insideField(), keepsOwnDirection()),
    Vec3d mLastTanAt = Vec3d(0.0);            ///< at this index point
    bool mHaveLastTan = false;
};

} // namespace

namespace {

/// retraceConsistent() of @a strands into @a out: a copy of them, or @a strands itself.
void retraceInto(const StrandSet& strands, StrandSet& out, const TangentField& field, const ConsistencyParams& params,
                 const HeadObstacle& head, ConsistencyStats* stats, bool threaded, openvdb::util::NullInterrupter* interrupter,
                 const openvdb::Vec3SGrid* hairVolume)
{
    params.validate("retraceConsistent");
    if (!field.tangent || !field.spread) throw ValueError("retraceConsistent: the field needs its tangent and spread grids");
    const FieldMapping map = FieldMapping::fromGrid(*field.tangent);
    const double step = resolveStepLength(params.step, map.worldVoxelSize(), "retraceConsistent");
    // A strand needs about length / step sub-steps: refuse a step that would take forever. The
    // length is summed per chunk of strands in parallel, then over the chunks in order: the same
    // sum for any thread count.
    constexpr std::size_t kChunk = 256;
    const std::size_t nS = strands.numStrands(), nChunks = (nS + kChunk - 1) / kChunk;
    std::vector<double> lengths(nChunks, 0.0);
    const auto measureChunk = [&](std::size_t c) {
        double sum = 0.0;
        for (std::size_t i = c * kChunk, last = std::min(nS, i + kChunk); i < last; ++i) {
            const Vec3f* s = strands.data(i);
            for (std::size_t j = 0; j + 1 < strands.size(i); ++j) sum += double((s[j + 1] - s[j]).length());
        }
        lengths[c] = sum;
    };
    forEachIndex(nChunks, threaded, measureChunk, 16);
    double total = 0.0;
    for (double l : lengths) total += l;
    if (total / step > 4e9) {
        throw LimitError("retraceConsistent: step " + std::to_string(step) + " needs about " + std::to_string(total / step) +
                         " sub-steps for a hairstyle of total length " + std::to_string(total) + " (at most 4e9)");
    }

    // The spread beside the tangent in each brick, a float per voxel: sampled at the tangent's
    // cell, without a second brick lookup, in a quarter of the bytes of a vector brick.
    const BrickedField<TreeT> tangents(field.tangent->tree(), &field.spread->tree());
    const openvdb::Vec3SGrid& volumeGrid = hairVolume ? *hairVolume : *field.tangent;
    // The field's own bricks when the hair volume is its grid (one-level refinement).
    std::unique_ptr<const BrickedField<TreeT>> ownVolume;
    if (&volumeGrid != field.tangent.get()) ownVolume.reset(new BrickedField<TreeT>(volumeGrid.tree()));
    const BrickedField<TreeT>& volume = ownVolume ? *ownVolume : tangents;
    const HairVolume dilated(volumeGrid);
    const Shared shared{strands, map, FieldMapping::fromGrid(volumeGrid), tangents, volume, !ownVolume, dilated, head, params, step,
                        std::sin(params.minSpreadDeg * M_PI / 180.0), 1.0 / (params.returnVoxels * map.worldVoxelSize()), out,
                        &out == &strands};

    // Strands in spatial order (Measures.h): neighbouring strands sample the same bricks, which
    // then stay in cache (synthesized roots come in random order). Each strand is traced on its
    // own and the counts are integers, so the order changes nothing in the result.
    const std::vector<std::uint32_t> order = spatialOrder(strands);

    std::vector<Counts> counts(nChunks);
    ProgressCounter progress(interrupter, "retracing (consistent)", nS, "strands");
    auto run = [&](std::size_t c) {
        if (progress.stopped()) return;
        StrandTracer tracer(shared);
        const std::size_t first = c * kChunk, last = std::min(nS, first + kChunk);
        for (std::size_t o = first; o < last; ++o) {
            // The spatial order scatters strands over memory, and a strand's first read of its
            // input vertices waited for memory (perf: a tenth of trace()'s time on that load):
            // fetch a later strand's input meanwhile. A hint only.
            if (o + 2 < last) prefetchBytes(strands.data(order[o + 2]), strands.size(order[o + 2]) * sizeof(Vec3f));
            tracer.trace(order[o], counts[c]);
        }
        progress.add(last - first);
    };
    if (threaded) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nChunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t c = r.begin(); c != r.end(); ++c) run(c);
        });
    } else {
        for (std::size_t c = 0; c < nChunks; ++c) run(c);
    }
    progress.finish();
    if (progress.stopped()) throw InterruptedError("retraceConsistent: interrupted");
    if (stats) {
        Counts all;
        for (const Counts& c : counts) all.add(c);  // in chunk order
        *stats = ConsistencyStats{nS, all.corrected, all.steps, all.fieldSteps, all.noFieldSteps, all.pushedOut, all.heldIn, all.reverted};
    }
}

} // namespace

StrandSet retraceConsistent(const StrandSet& strands, const TangentField& field, const ConsistencyParams& params,
                            const HeadObstacle& head, ConsistencyStats* stats, bool threaded,
                            openvdb::util::NullInterrupter* interrupter, const openvdb::Vec3SGrid* hairVolume)
{
    // Topology and attributes; positions are overwritten. The positions' storage is reserved
    // first, hinted for huge pages (Memory.h): copy-assignment keeps storage that is large enough,
    // so the copy faults in 2 MiB pages instead of 4 KiB ones (a 77 MB set: 19,000 faults fewer).
    StrandSet out;
    reserveHugePages(out.positions, strands.numVertices());
    out = strands;
    retraceInto(strands, out, field, params, head, stats, threaded, interrupter, hairVolume);
    return out;
}

StrandSet retraceConsistent(StrandSet&& strands, const TangentField& field, const ConsistencyParams& params,
                            const HeadObstacle& head, ConsistencyStats* stats, bool threaded,
                            openvdb::util::NullInterrupter* interrupter, const openvdb::Vec3SGrid* hairVolume)
{
    StrandSet out = std::move(strands);
    retraceInto(out, out, field, params, head, stats, threaded, interrupter, hairVolume);
    return out;
}

} // namespace vdbhair
