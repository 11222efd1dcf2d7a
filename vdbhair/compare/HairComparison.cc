#include "HairComparison.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parallel.h>
#include <vdbhair/Quantile.h>
#include <vdbhair/field/HairVolume.h>
#include <vdbhair/field/HeadCollision.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/helicoid/Frechet.h>
#include <vdbhair/strands/Measures.h>
#include <vdbhair/strands/Resample.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace vdbhair {

namespace {

/// The names of compare's unit and thresholds, as each front end spells them (their declarations
/// below cannot call paramName() while the table is being built).
const ParamName kUnitName{"--unit", "unit"}, kThresholdName{"--threshold", "threshold"};

/// The unit as a person types it: a name (mm, cm, dm, m, in), else its length in metres; "" unknown.
std::string unitText(double metersPerUnit)
{
    if (metersPerUnit == 0.0) return "";
    for (const char* name : {"mm", "cm", "dm", "m", "in"}) if (metersPerUnitFromName(name, "") == metersPerUnit) return name;
    return formatNumber(metersPerUnit);
}

/// "D:ANGLE" thresholds, separated by spaces, as CompareParams::thresholds.
/// @throw ParamError<ValueError> naming the threshold that is not one.
std::vector<OrientedThreshold> parseThresholds(const std::string& text)
{
    std::vector<OrientedThreshold> out;
    std::size_t at = 0;
    while ((at = text.find_first_not_of(' ', at)) != std::string::npos) {
        const std::size_t end = std::min(text.find(' ', at), text.size());
        const std::string item = text.substr(at, end - at);
        at = end;
        const std::size_t colon = item.find(':');
        char* end1 = nullptr;
        char* end2 = nullptr;
        const std::string d = item.substr(0, colon), angle = colon == std::string::npos ? std::string() : item.substr(colon + 1);
        const double dv = std::strtod(d.c_str(), &end1), av = std::strtod(angle.c_str(), &end2);
        if (colon == std::string::npos || d.empty() || angle.empty() || *end1 != '\0' || *end2 != '\0' || !(dv > 0.0) || !std::isfinite(dv) ||
            !(av >= 0.0 && av <= 180.0)) {
            throw ParamError<ValueError>({kThresholdName, " '" + item + "': expected DISTANCE:ANGLE, a positive distance (millimetres with ", kUnitName,
                                          ", else file units) and an angle in [0, 180] degrees, e.g. 2:20"});
        }
        out.push_back({dv, av});
    }
    return out;
}

} // namespace

const ParamTable<CompareParams>& compareParameters()
{
    using P = CompareParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        ParamAccess<P, std::string> unitAccess{[](const P& p) { return unitText(p.metersPerUnit); }, [](P& p, std::string v) {
                                                   if (v.empty()) {
                                                       p.metersPerUnit = 0.0;
                                                       return;
                                                   }
                                                   try {
                                                       p.metersPerUnit = metersPerUnitFromName(v, "");
                                                   } catch (const ValueError&) {
                                                       throw ParamError<ValueError>({kUnitName, " '" + v + "': expected mm, cm, dm, m, in or the unit's length in "
                                                                                                            "metres (0.01 for centimetres)"});
                                                   }
                                               }};
        auto unit = makeParam<P>("unit", "The files' unit: mm, cm, dm, m, in, or its length in metres; needed for HairGS's thresholds in millimetres "
                                         "(not given: unknown)", "", unitAccess);
        unit.pythonNone = true;
        t.push_back(unit);
        ParamAccess<P, std::string> thresholdAccess{[](const P& p) {
                                                        std::string s;
                                                        for (const OrientedThreshold& th : p.thresholds)
                                                            s += (s.empty() ? "" : " ") + formatNumber(th.distance) + ":" + formatNumber(th.angleDegrees);
                                                        return s;
                                                    },
                                                    [](P& p, std::string v) { p.thresholds = parseThresholds(v); }};
        auto threshold = makeParam<P>("threshold", "An oriented-point threshold DISTANCE:ANGLE (millimetres with a unit, else file units; "
                                                   "several: repeat it; default with a unit: HairGS's 2:20 3:30 4:40 4:90)", "", thresholdAccess);
        threshold.repeats = true;
        threshold.pythonNone = true;
        t.push_back(threshold);
        t.push_back(makeParam<P>("bidirectional", "Oriented points match whichever way round their directions point", "",
                                 member<P>([](P& p) -> bool& { return p.bidirectional; })));
        auto samples = makeParam<P>("samples", "Points per strand for the strand-pair measures, 100 as in Perm", "",
                                    member<P>([](P& p) -> std::size_t& { return p.samples; }));
        samples.min = double(CompareParams::kMinSamples);
        t.push_back(samples);
        // On by default: the flag turns it off (--no-pair-strands; --unpaired, its older name).
        auto pair = makeParam<P>("pair-strands", "Pair strand i of A with strand i of B when the counts agree (off for hairstyles whose strands do "
                                                 "not correspond, such as a synthesis)", "", member<P>([](P& p) -> bool& { return p.pairStrands; }));
        pair.oldFlags = {"--unpaired"};
        t.push_back(pair);
        return t;
    }();
    return table;
}

void CompareParams::validate() const
{
    if (!(metersPerUnit >= 0.0) || !std::isfinite(metersPerUnit)) {
        throw ParamError<ValueError>({kUnitName, " " + std::to_string(metersPerUnit) + ": must be a positive length in metres, or 0 for unknown"});
    }
    if (samples < kMinSamples) {
        throw ParamError<ValueError>({paramName(compareParameters(), "samples"),
                                      " " + std::to_string(samples) + ": must be at least " + std::to_string(kMinSamples) + " (a curvature needs three points)"});
    }
    for (const OrientedThreshold& t : thresholds) {
        if (!(t.distance > 0.0) || !std::isfinite(t.distance)) {
            throw ParamError<ValueError>({kThresholdName, ": distance " + std::to_string(t.distance) + ": must be positive and finite"});
        }
        if (!(t.angleDegrees >= 0.0 && t.angleDegrees <= 180.0)) {
            throw ParamError<ValueError>({kThresholdName, ": angle " + std::to_string(t.angleDegrees) + ": must be in [0, 180] degrees"});
        }
    }
}

namespace {

/// The discrete Fréchet distance of each strand pair over the length of A's strand (see the header).
std::vector<double> relativeFrechetPairs(const StrandSet& a, const StrandSet& b, std::size_t samples, bool threaded)
{
    std::vector<double> out(a.numStrands(), 0.0);
    forEachRange(a.numStrands(), threaded, 16, [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<Vec3f> ra(samples), rb(samples);
        std::vector<Vec3d> da(samples), db(samples);
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (a.size(i) == 0 || b.size(i) == 0) continue;
            const double length = polylineLength(a.positions.data() + a.begin(i), a.size(i));
            if (!(length > 0.0)) continue;
            resamplePolyline(a.positions.data() + a.begin(i), a.size(i), samples, ra.data());
            resamplePolyline(b.positions.data() + b.begin(i), b.size(i), samples, rb.data());
            for (std::size_t k = 0; k < samples; ++k) {
                da[k] = Vec3d(ra[k].x(), ra[k].y(), ra[k].z());
                db[k] = Vec3d(rb[k].x(), rb[k].y(), rb[k].z());
            }
            out[i] = discreteFrechet(da.data(), samples, db.data(), samples) / length;
        }
    });
    return out;
}

} // namespace

HairComparison compareHairstyles(const StrandSet& a, const StrandSet& b, const CompareParams& params,
                                 const HeadObstacle* head, bool threaded)
{
    params.validate();
    HairComparison c;
    c.strandsA = a.numStrands();
    c.strandsB = b.numStrands();
    c.verticesA = a.numVertices();
    c.verticesB = b.numVertices();
    c.metersPerUnit = params.metersPerUnit;

    std::vector<OrientedThreshold> thresholds = params.thresholds;
    if (params.metersPerUnit > 0.0) {
        for (OrientedThreshold& t : thresholds) t.distance /= 1000.0;  // millimetres to metres
    }
    if (thresholds.empty() && params.metersPerUnit > 0.0) thresholds = hairGsThresholds();
    if (params.metersPerUnit > 0.0) {
        for (OrientedThreshold& t : thresholds) t.distance /= params.metersPerUnit;  // metres to file units
    }
    if (a.positions.empty() || b.positions.empty()) throw ValueError("compare: a hairstyle has no vertex");
    const StrandIndex ia(a, threaded), ib(b, threaded);
    if (!thresholds.empty()) c.oriented = matchOrientedPoints(ib, ia, thresholds, params.bidirectional, threaded);

    c.chamfer = chamferDistances(ia, ib, threaded);

    c.paired = params.pairStrands && a.numStrands() == b.numStrands();
    if (c.paired) {
        c.perm = strandPairErrors(a, b, params.samples, threaded);
        c.frechet = relativeFrechetPairs(a, b, params.samples, threaded);
        for (double f : c.frechet) {
            c.frechetMean += f;
            c.frechetMax = std::max(c.frechetMax, f);
        }
        if (!c.frechet.empty()) {
            c.frechetMean /= double(c.frechet.size());
            c.frechetP95 = nearestRankQuantile(c.frechet, 0.95);
        }
    }

    c.volumeVoxel = suggestVoxelSize(a);
    if (c.strandsB) c.leavingVolume = double(countStrandsLeavingVolume(b, a, c.volumeVoxel, threaded)) / double(c.strandsB);

    if (head && !head->unset() && !head->empty()) {
        c.headMeasured = true;
        const double tolerance = headTolerance(*head);
        if (c.strandsA) c.enteringHeadA = double(countStrandsEnteringHead(a, *head, tolerance, threaded)) / double(c.strandsA);
        if (c.strandsB) c.enteringHeadB = double(countStrandsEnteringHead(b, *head, tolerance, threaded)) / double(c.strandsB);
    }
    return c;
}

HairComparison measureAgainst(const StrandSet& reference, const StrandSet& output, const HeadObstacle* head, bool corresponding)
{
    CompareParams cp;
    cp.metersPerUnit = reference.metersPerUnit;
    cp.pairStrands = corresponding;
    return compareHairstyles(reference, output, cp, head && !head->unset() && !head->empty() ? head : nullptr);
}

std::string summaryLine(const HairComparison& c)
{
    char buf[320];
    std::string s;
    std::snprintf(buf, sizeof buf, "Chamfer %.4g", c.chamfer.mean);
    s += buf;
    if (!c.oriented.empty()) {
        const OrientedMatch& m = c.oriented.front();
        if (c.metersPerUnit > 0.0) std::snprintf(buf, sizeof buf, ", F1 %.3f at %.3g mm / %.3g deg", m.f1, m.threshold.distance * c.metersPerUnit * 1000.0, m.threshold.angleDegrees);
        else std::snprintf(buf, sizeof buf, ", F1 %.3f at %.3g / %.3g deg", m.f1, m.threshold.distance, m.threshold.angleDegrees);
        s += buf;
    } else if (c.metersPerUnit <= 0.0) {
        s += ", no F1 (the file carries no unit; vdbhair compare --unit)";
    }
    if (c.paired) {
        std::snprintf(buf, sizeof buf, ", position error %.4g, Frechet / length mean %.3g", c.perm.meanPosition, c.frechetMean);
        s += buf;
    }
    std::snprintf(buf, sizeof buf, ", %.1f %% of strands leave its volume", 100.0 * c.leavingVolume);
    s += buf;
    return s;
}

nlohmann::json toJson(const HairComparison& c)
{
    nlohmann::json j;
    j["strands"] = {{"a", c.strandsA}, {"b", c.strandsB}};
    j["vertices"] = {{"a", c.verticesA}, {"b", c.verticesB}};
    j["meters_per_unit"] = c.metersPerUnit > 0.0 ? nlohmann::json(c.metersPerUnit) : nlohmann::json(nullptr);
    j["oriented_points"] = toJson(c.oriented, c.metersPerUnit);
    j["chamfer"] = {{"a_to_b", c.chamfer.aToB}, {"b_to_a", c.chamfer.bToA}, {"mean", c.chamfer.mean}};
    j["paired"] = c.paired;
    if (c.paired) {
        j["position_error"] = c.perm.meanPosition;
        j["curvature_error"] = c.perm.meanCurvature;
        j["frechet"] = {{"mean", c.frechetMean}, {"p95", c.frechetP95}, {"max", c.frechetMax}};
    } else {
        j["position_error"] = nullptr;
        j["curvature_error"] = nullptr;
        j["frechet"] = nullptr;
    }
    j["leaving_volume"] = c.leavingVolume;
    j["volume_voxel"] = c.volumeVoxel;
    j["entering_head"] = c.headMeasured ? nlohmann::json({{"a", c.enteringHeadA}, {"b", c.enteringHeadB}}) : nlohmann::json(nullptr);
    return j;
}

} // namespace vdbhair
