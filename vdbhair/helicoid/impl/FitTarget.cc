#include "FitTarget.h"

#include <vdbhair/strands/Frames.h>
#include <vdbhair/strands/Measures.h>

#include <cmath>

namespace vdbhair {
namespace fit {

FitTarget makeFitTarget(const Vec3f* points, std::size_t n)
{
    FitTarget t;
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3d p(points[i]);
        if (!t.pts.empty() && p == t.pts.back()) continue;
        t.pts.push_back(p);
    }
    t.arc.resize(t.pts.size());
    if (!t.pts.empty()) t.arc[0] = 0.0;
    for (std::size_t i = 1; i < t.pts.size(); ++i) t.arc[i] = t.arc[i - 1] + (t.pts[i] - t.pts[i - 1]).length();
    t.length = t.arc.empty() ? 0.0 : t.arc.back();
    std::vector<Vec3f> f(t.pts.size());
    for (std::size_t i = 0; i < f.size(); ++i) f[i] = toFloat(t.pts[i]);
    t.curvature.resize(f.size());
    curvatureProfile(f.data(), f.size(), t.curvature.data());
    std::vector<Frame> frames(f.size());
    if (!f.empty()) frenetFrames(f.data(), f.size(), frames.data());
    t.turning.assign(t.pts.size(), 0.0);
    for (std::size_t i = 1; i + 1 < t.pts.size(); ++i) {
        const Vec3d u = (t.pts[i] - t.pts[i - 1]).unitSafe(), v = (t.pts[i + 1] - t.pts[i]).unitSafe();
        t.turning[i] = std::atan2(u.cross(v).length(), u.dot(v));
    }
    t.normal.resize(f.size());
    for (std::size_t i = 0; i < f.size(); ++i) t.normal[i] = Vec3d(frames[i].n);
    if (!f.empty()) t.rootTangent = Vec3d(frames[0].t);
    return t;
}

} // namespace fit
} // namespace vdbhair
