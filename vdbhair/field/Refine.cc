#include "Refine.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/PointCloud.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace vdbhair {

RefineMode refineModeFromName(const std::string& name)
{
    if (name == "consistent") return RefineMode::Consistent;
    if (name == "field") return RefineMode::Field;
    throw ValueError("mode '" + name + "' is not one of consistent, field");
}

const char* refineModeName(RefineMode mode)
{
    return mode == RefineMode::Consistent ? "consistent" : "field";
}

void RefineParams::validate(const char* where) const
{
    if (levels < 1 || levels > kMaxLevels) {
        throw ParamError<ValueError>({std::string(where) + ": ", paramName(refineParameters(), "levels"),
                                      " " + std::to_string(levels) + ": must be between 1 and " + std::to_string(kMaxLevels)});
    }
    consistency.validate(where);
}

void RefineParams::setStep(double step, Integrator integrator)
{
    trace.step = consistency.step = step;
    trace.integrator = consistency.integrator = integrator;
}

const ParamTable<RefineParams>& refineParameters()
{
    using P = RefineParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto add = [&](Param<P> p) { t.push_back(std::move(p)); };
        // The field's: voxel size first (its declaration, TangentField.cc).
        const auto field = [](P& p) -> FieldParams& { return p.field; };
        for (Param<P>& q : nestedParams<P>(fieldParameters(), field, {"voxel-size"})) add(std::move(q));
        auto levels = makeParam<P>("levels", "Levels, coarse (voxel size x 2^(levels-1)) to fine", "", member<P>([](P& p) -> int& { return p.levels; }));
        levels.min = 1;
        levels.max = P::kMaxLevels;
        add(levels);
        auto mode = makeParam<P>("mode", "consistent: fix only strands that stray from the flow, keep every strand's detail; field: replace "
                              "every strand by the field's streamline (Wang et al.)", "",
                      named<P>([](P& p) -> RefineMode& { return p.mode; }, refineModeName, refineModeFromName));
        mode.choices = {"consistent", "field"};
        add(mode);
        for (Param<P>& q : nestedParams<P>(fieldParameters(), field, {"iterations"})) add(std::move(q));
        // One step and one integrator for both modes (setStep()).
        auto step = makeParam<P>("step", "Integration step", "world units",
                      ParamAccess<P, double>{[](const P& p) { return p.trace.step; }, [](P& p, double v) { p.setStep(v, p.trace.integrator); }});
        step.min = 0.0;
        step.zeroMeans = formatNumber(kDefaultStepVoxels) + " of each level's voxel size";
        add(step);
        auto integrator = makeParam<P>("integrator", "The integrator of each step of either mode (euler: the papers' choice)", "",
                            ParamAccess<P, std::string>{[](const P& p) { return std::string(integratorName(p.trace.integrator)); },
                                                        [](P& p, std::string v) { p.setStep(p.trace.step, integratorFromName(v)); }});
        integrator.choices = {"euler", "rk2", "rk3", "rk4"};
        add(integrator);
        auto zStart = makeParam<P>("outlier-start", "consistent mode: the outlier score (deviation over the voxel's spread) where the field starts to take over",
                        "", member<P>([](P& p) -> double& { return p.consistency.zStart; }));
        zStart.min = 0.0;
        add(zStart);
        auto zFull = makeParam<P>("outlier-full", "consistent mode: the outlier score from which the field's direction is followed (above the outlier start)", "",
                       member<P>([](P& p) -> double& { return p.consistency.zFull; }));
        zFull.min = 0.0;
        add(zFull);
        auto spread = makeParam<P>("min-spread", "consistent mode: deviations below this are never outliers", "degrees",
                        member<P>([](P& p) -> double& { return p.consistency.minSpreadDeg; }));
        spread.min = 0.0;
        spread.max = 90.0;
        add(spread);
        add(makeParam<P>("follow-opposed", "consistent mode: a field pointing back along a strand (over 90 degrees from it) may turn it "
                                           "round, as Wang et al.'s streamlines do; off: its pull fades out by 110 degrees (two flows: "
                                           "a parting's sides, curls finer than a voxel), which folds no strand back",
                         "", member<P>([](P& p) -> bool& { return p.consistency.followOpposed; })));
        auto margin = makeParam<P>("margin", "field mode: voxels a strand may continue straight past the field's active region", "voxels",
                        member<P>([](P& p) -> int& { return p.trace.margin; }));
        margin.min = 0;
        margin.max = TraceParams::kMaxMargin;
        add(margin);
        for (Param<P>& q : nestedParams<P>(fieldParameters(), field, {"max-voxels", "max-memory", "space", "up"})) add(std::move(q));
        add(headPolicyParam<P>([](P& p) -> HeadPolicy& { return p.headPolicy; }));
        add(makeParam<P>("measure", "Also measure the output against the input at every level: full length, hair volume, head, curvature, "
                                "tips, displacement, coherence (an extra field estimate per level: about a fifth of the run), and compare "
                                "the output with the input as `vdbhair compare` does (the report's \"compare\")", "",
                     member<P>([](P& p) -> bool& { return p.measure; })));
        return t;
    }();
    return table;
}

namespace {

std::vector<Vec3f> rootsOf(const StrandSet& strands)
{
    std::vector<Vec3f> roots(strands.numStrands());
    for (std::size_t i = 0; i < roots.size(); ++i) roots[i] = strands.root(i);
    return roots;
}

/// The median distance from a root to its nearest other root (upperMedian(); 0 for fewer than two
/// distinct roots).
double medianRootSpacing(const StrandSet& strands)
{
    const std::size_t n = strands.numStrands();
    if (n < 2) return 0.0;
    // The roots copied together: a strand's root is a strand's length away from the next one in
    // the positions, and the tree's build reads every root many times.
    const std::vector<Vec3f> roots = rootsOf(strands);
    const PointCloudOf<Vec3f> cloud{&roots};
    PointKdTreeOf<Vec3f> tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree.buildIndex();
    // At most 4096 roots, evenly spaced in index order: the median is stable long before that.
    const std::size_t stride = std::max<std::size_t>(1, n / 4096);
    std::vector<double> d;
    for (std::size_t i = 0; i < n; i += stride) {
        // The nearest root at a positive distance (duplicated roots are skipped).
        std::uint32_t idx[8];
        float dist2[8];
        const Vec3f& q = strands.root(i);
        const float query[3] = {q.x(), q.y(), q.z()};
        const std::size_t found = tree.knnSearch(query, 8, idx, dist2);
        for (std::size_t k = 0; k < found; ++k) {
            if (dist2[k] > 0.f) {
                d.push_back(std::sqrt(double(dist2[k])));
                break;
            }
        }
    }
    return upperMedian(std::move(d));
}

/// Half the largest extent of the hair: the head radius when the roots do not fit a sphere.
double halfExtent(const StrandSet& strands)
{
    const Vec3f e = computeBBox(strands).extent();
    return 0.5 * double(std::max({e.x(), e.y(), e.z()}));
}

/// The fitted sphere of the roots if it is plausible: a radius no larger than the hair's extent
/// (roots on a nearly flat patch fit a huge sphere).
bool plausibleRootSphere(const StrandSet& strands, ScalpSphere& sphere)
{
    if (strands.numStrands() < 4) return false;
    try {
        sphere = fitScalpSphere(rootsOf(strands));
    } catch (const ValueError&) {
        return false;
    }
    return std::isfinite(sphere.radius) && sphere.radius <= 2.0 * halfExtent(strands);
}

} // namespace

double suggestVoxelSize(const StrandSet& strands)
{
    if (strands.empty()) throw ValueError("suggestVoxelSize: the hairstyle has no strands");
    ScalpSphere sphere;
    const double radius = plausibleRootSphere(strands, sphere) ? sphere.radius : halfExtent(strands);
    const double spacing = medianRootSpacing(strands);
    double h = 3.0 * spacing;
    h = std::min(std::max(h, radius / 64.0), radius / 4.0);
    if (!(h > 0.0) || !std::isfinite(h)) h = 1.0;
    return h;
}

HeadObstacle headFromRoots(const StrandSet& strands, const Vec3d& up)
{
    (void)up;
    ScalpSphere sphere;
    if (!plausibleRootSphere(strands, sphere)) return HeadObstacle::none();
    HeadObstacle head = HeadObstacle::sphere(sphere.center, sphere.radius, kDefaultHeadPolicy);
    head.setLabel("fitted to the roots");
    return head;
}

RefineMemory estimateRefineMemory(const StrandSet& strands, const RefineParams& params)
{
    params.validate("refineStrands");
    if (strands.empty()) throw ValueError("refineStrands: the hairstyle has no strands");
    FieldParams lp = params.field;
    lp.voxelSize = resolveVoxelSize(strands, params.field);
    RefineMemory m;
    for (int level = 0; level < params.levels; ++level) {
        FieldParams l = lp;
        l.voxelSize = lp.voxelSize * double(1 << level);
        m.footprints.push_back(estimateFieldFootprint(strands, l));
    }
    m.bytes = estimatePeakBytes(m.footprints, MemoryUse::Refine);
    m.available = availableMemoryBytes(params.field);
    return m;
}

namespace {

/// refineStrands() of @a strands; @a consumable is @a strands itself when the caller gives it up, else null.
RefineResult refine(const StrandSet& strands, StrandSet* consumable, const RefineParams& params, bool threaded,
                    openvdb::util::NullInterrupter* interrupter)
{
    params.validate("refineStrands");
    if (strands.empty()) throw ValueError("refineStrands: the hairstyle has no strands");
    FieldParams fp = params.field;
    if (fp.voxelSize == 0.0) fp.voxelSize = suggestVoxelSize(strands);

    // Memory, before anything is allocated: the whole refinement's estimate (estimateRefineMemory()'s),
    // checked once, in the same pass over the strands as the input's own field at the finest voxel
    // size. That field's active voxels are the hair volume that every level keeps strands in, and
    // the reference every level is measured against. The estimates below are part of the check
    // and skip their own.
    RefineResult result;
    const TangentField inputField = estimateTangentFieldAfterCheck(strands, fp, MemoryUse::Refine, params.levels, "refineStrands",
                                                                   result.memory.footprints, threaded, interrupter);
    result.memory.bytes = estimatePeakBytes(result.memory.footprints, MemoryUse::Refine);
    result.memory.available = availableMemoryBytes(fp);
    fp.maxMemory = std::numeric_limits<std::uint64_t>::max();
    result.voxelSize = fp.voxelSize;
    result.head = params.head.unset() ? headFromRoots(strands, fp.scalpSphere().up) : params.head;
    result.fields.resize(std::size_t(params.levels));
    result.levels.resize(std::size_t(params.levels));

    StrandSet current;  // the last level's strands (the input's before the first level)
    for (int level = params.levels - 1; level >= 0; --level) {
        FieldParams lp = fp;
        lp.voxelSize = fp.voxelSize * double(1 << level);
        const StrandSet& from = level == params.levels - 1 ? strands : current;
        // With one level, the level's field is the input's (the same strands at the same voxel
        // size): estimated once, shared.
        TangentField f = params.levels == 1 ? inputField : estimateTangentField(from, lp, threaded, interrupter);
        f.tangent->setName(tangentGridName(level, params.levels));
        f.density->setName(densityGridName(level, params.levels));
        f.hairLength->setName(hairLengthGridName(level, params.levels));
        f.coherence->setName(coherenceGridName(level, params.levels));
        f.spread->setName(spreadGridName(level, params.levels));
        for (openvdb::GridBase* g : {static_cast<openvdb::GridBase*>(f.tangent.get()), static_cast<openvdb::GridBase*>(f.density.get()),
                                     static_cast<openvdb::GridBase*>(f.hairLength.get()), static_cast<openvdb::GridBase*>(f.coherence.get()),
                                     static_cast<openvdb::GridBase*>(f.spread.get())}) {
            g->insertMeta("vdbhair_level", openvdb::Int32Metadata(level));
            g->insertMeta("vdbhair_levels", openvdb::Int32Metadata(params.levels));
            g->insertMeta("vdbhair_refine_mode", openvdb::StringMetadata(refineModeName(params.mode)));
        }
        RefineLevel& info = result.levels[std::size_t(level)];
        info.voxelSize = lp.voxelSize;
        if (params.mode == RefineMode::Consistent) {
            // Each level starts from the last one's strands: detail that a level keeps is there for
            // the next. Strands nothing reads again are retraced in their own storage: the last
            // level's always, the input's when the caller gave it up and no measure needs it.
            const bool consume = &from == &current || (consumable && !params.measure);
            if (consume) {
                StrandSet& own = &from == &current ? current : *consumable;
                current = retraceConsistent(std::move(own), f, params.consistency, result.head, &info.consistency, threaded,
                                            interrupter, inputField.tangent.get());
            } else {
                current = retraceConsistent(from, f, params.consistency, result.head, &info.consistency, threaded, interrupter,
                                            inputField.tangent.get());
            }
        } else {
            // The paper: every level retraces the input's roots for the input's lengths and
            // vertex arc lengths, so that early stops at one level do not shorten the next. The
            // last level's strands are not needed once its field is estimated: their storage
            // takes the new ones (retraceStrandsInto).
            retraceStrandsInto(strands, *f.tangent, params.trace, current, &info.trace, nullptr, threaded, interrupter);
        }
        if (params.measure) info.measures = measureRefinement(strands, current, inputField, fp, result.head, threaded);
        result.fields[std::size_t(level)] = std::move(f);
    }
    result.strands = std::move(current);
    return result;
}

} // namespace

RefineResult refineStrands(const StrandSet& strands, const RefineParams& params, bool threaded,
                           openvdb::util::NullInterrupter* interrupter)
{
    return refine(strands, nullptr, params, threaded, interrupter);
}

RefineResult refineStrands(StrandSet&& strands, const RefineParams& params, bool threaded,
                           openvdb::util::NullInterrupter* interrupter)
{
    return refine(strands, &strands, params, threaded, interrupter);
}

} // namespace vdbhair
