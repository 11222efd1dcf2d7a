#include "Streamline.h"
#include "SamplerRetrace.h"

#include <vdbhair/Exceptions.h>

#include <cmath>

namespace vdbhair {

Integrator integratorFromName(const std::string& name)
{
    if (name == "euler") return Integrator::Euler;
    if (name == "rk2") return Integrator::RK2;
    if (name == "rk3") return Integrator::RK3;
    if (name == "rk4") return Integrator::RK4;
    throw ValueError("integrator '" + name + "' is not one of euler, rk2, rk3, rk4");
}

const char* retraceVerticesName(RetraceVertices vertices)
{
    return vertices == RetraceVertices::Input ? "input" : "steps";
}

RetraceVertices retraceVerticesFromName(const std::string& name)
{
    if (name == "input") return RetraceVertices::Input;
    if (name == "steps") return RetraceVertices::Steps;
    throw ValueError("vertices '" + name + "' is not one of input, steps");
}

const ParamTable<TraceParams>& traceParameters()
{
    using P = TraceParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto step = makeParam<P>("step", "Integration step", "world units", member<P>([](P& p) -> double& { return p.step; }));
        step.min = 0.0;
        step.zeroMeans = formatNumber(kDefaultStepVoxels) + " of the field's voxel size";
        t.push_back(step);
        auto integrator = makeParam<P>("integrator", "The integrator of each step (euler: the papers' choice)", "",
                                       named<P>([](P& p) -> Integrator& { return p.integrator; }, integratorName, integratorFromName));
        integrator.choices = {"euler", "rk2", "rk3", "rk4"};
        t.push_back(integrator);
        auto vanish = makeParam<P>("vanish", "Stop where the blended direction's length falls below this fraction", "",
                                   member<P>([](P& p) -> double& { return p.vanishThreshold; }));
        vanish.min = 0.0;
        vanish.max = 1.0;
        t.push_back(vanish);
        auto maxSteps = makeParam<P>("max-steps", "Stop a strand after this many steps", "", member<P>([](P& p) -> std::size_t& { return p.maxSteps; }));
        maxSteps.zeroMeans = "no limit";
        t.push_back(maxSteps);
        auto margin = makeParam<P>("margin", "Voxels a strand may continue straight past the field's active region (0: stop there, the papers' rule)",
                                   "voxels", member<P>([](P& p) -> int& { return p.margin; }));
        margin.min = 0;
        margin.max = P::kMaxMargin;
        t.push_back(margin);
        auto vertices = makeParam<P>("vertices", "input: the input's vertex count and arc lengths; steps: every step", "",
                                     named<P>([](P& p) -> RetraceVertices& { return p.vertices; }, retraceVerticesName, retraceVerticesFromName));
        vertices.choices = {"input", "steps"};
        t.push_back(vertices);
        return t;
    }();
    return table;
}

const ParamTable<RetraceParams>& retraceParameters()
{
    using P = RetraceParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t = nestedParams<P>(traceParameters(), [](P& p) -> TraceParams& { return p.trace; });
        t.push_back(makeParam<P>("measure", "Also report the mean angle between strand tangents and the field before and after (the report's "
                                            "tangent_angle_deg; samples the field at every input and output vertex: about half of the run)",
                                 "", member<P>([](P& p) -> bool& { return p.measure; })));
        return t;
    }();
    return table;
}

const char* integratorName(Integrator integrator)
{
    switch (integrator) {
    case Integrator::RK2: return "rk2";
    case Integrator::RK3: return "rk3";
    case Integrator::RK4: return "rk4";
    default: return "euler";
    }
}

double resolveStepLength(double step, double voxelSize, const std::string& where)
{
    if (step < 0.0 || !std::isfinite(step)) {
        throw ParamError<ValueError>({where + ": ", paramName(traceParameters(), "step"),
                                      " " + std::to_string(step) + " must be 0 (half a voxel) or a positive finite length"});
    }
    return step > 0.0 ? step : kDefaultStepVoxels * voxelSize;
}

std::size_t stepCount(double length, double step)
{
    if (!(length > 0.0)) return 0;
    return std::max<std::size_t>(1, std::size_t(std::ceil(length / step - 1e-9)));
}

double retraceArcLengths(const Vec3f* v, std::size_t n, double* out)
{
    if (n == 0) return 0.0;
    double s = 0.0;
    out[0] = 0.0;
    for (std::size_t j = 1; j < n; ++j) {
        const float dx = v[j].x() - v[j - 1].x(), dy = v[j].y() - v[j - 1].y(), dz = v[j].z() - v[j - 1].z();
        s += double(std::sqrt(dx * dx + dy * dy + dz * dz));
        out[j] = s;
    }
    return s;
}

void TraceParams::validate(const std::string& where) const
{
    resolveStepLength(step, 1.0, where);
    if (margin < 0 || margin > kMaxMargin) {
        throw ParamError<ValueError>({where + ": ", paramName(traceParameters(), "margin"),
                                      " " + std::to_string(margin) + " voxels must be between 0 and " + std::to_string(kMaxMargin)});
    }
    if (vanishThreshold < 0.0 || !(vanishThreshold < 1.0)) {
        throw ParamError<ValueError>({where + ": ", paramName(traceParameters(), "vanish"), " " + std::to_string(vanishThreshold) + " must be in [0, 1)"});
    }
}

TraceStats TraceStats::count(const std::vector<StopReason>& reasons, const std::vector<std::size_t>& steps)
{
    TraceStats stats;
    stats.strands = reasons.size();
    for (std::size_t i = 0; i < reasons.size(); ++i) {
        stats.steps += i < steps.size() ? steps[i] : 0;
        switch (reasons[i]) {
        case StopReason::FullLength: ++stats.fullLength; break;
        case StopReason::Vanished: ++stats.vanished; break;
        case StopReason::LeftField: ++stats.leftField; break;
        case StopReason::MaxSteps: ++stats.maxSteps; break;
        }
    }
    return stats;
}

namespace {
Vec3f toF(const Vec3d& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }
} // namespace

void writeAtArcLengths(const std::vector<Vec3d>& pts, double length, double step, StopReason reason,
                       const double* target, std::size_t n, std::vector<Vec3f>& out)
{
    out.clear();
    if (n == 0 || pts.empty()) return;
    const std::size_t needed = stepCount(length, step);
    const std::size_t taken = pts.size() - 1;
    const double reached = taken == needed ? length : double(taken) * step;
    // Step m spans arc lengths [m·step, (m+1)·step], the last step of a full-length trace
    // [(needed - 1)·step, length].
    for (std::size_t j = 0; j < n && target[j] <= reached + 1e-12 * length; ++j) {
        if (taken == 0) {
            out.push_back(toF(pts[0]));
            continue;
        }
        const std::size_t m = std::min(std::size_t(target[j] / step), taken - 1);
        const double seg = m + 1 == needed ? length - double(needed - 1) * step : step;
        const double f = std::min(1.0, std::max(0.0, (target[j] - double(m) * step) / seg));
        out.push_back(toF(pts[m] + f * (pts[m + 1] - pts[m])));
    }
    if (out.empty()) out.push_back(toF(pts[0]));
    if (reason == StopReason::FullLength) out.back() = toF(pts.back());  // exactly the traced tip
    else if (out.back() != toF(pts.back())) out.push_back(toF(pts.back()));  // where it stopped
    if (out.size() < 2) out.push_back(out.back());
    if (out.size() > n) out.resize(n);
}

void writeSteps(const std::vector<Vec3d>& pts, std::vector<Vec3f>& out)
{
    out.resize(pts.size());
    for (std::size_t m = 0; m < pts.size(); ++m) out[m] = toF(pts[m]);
    if (pts.size() == 1) out.push_back(out[0]);
}

void assembleRetrace(const StrandSet& in, bool inputMode, const std::vector<std::vector<Vec3f>>& traced, StrandSet& out)
{
    const std::size_t nS = in.numStrands();
    out.clear();
    std::size_t total = 0;
    for (const std::vector<Vec3f>& t : traced) total += t.size();
    out.reserve(nS, total);
    for (std::size_t i = 0; i < nS; ++i) out.addStrand(traced[i]);
    out.defaults = in.defaults;
    out.rootUV = in.rootUV;
    out.strandId = in.strandId;
    if (!inputMode) return;
    // Per-vertex attributes: the prefix of each input strand's that its output kept.
    auto keep = [&](const auto& from, auto& to) {
        if (from.empty()) return;
        to.resize(total);
        for (std::size_t i = 0; i < nS; ++i) {
            std::copy_n(from.begin() + std::ptrdiff_t(in.begin(i)), out.size(i), to.begin() + std::ptrdiff_t(out.begin(i)));
        }
    };
    keep(in.thickness, out.thickness);
    keep(in.transparency, out.transparency);
    keep(in.color, out.color);
}

} // namespace vdbhair
