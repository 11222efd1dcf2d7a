#include "RootEnd.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/ReadOptions.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vdbhair {

const char* rootEndName(RootEnd end)
{
    switch (end) {
    case RootEnd::First: return "first";
    case RootEnd::Last: return "last";
    case RootEnd::Auto: return "auto";
    }
    return "first";
}

RootEnd rootEndFromName(const std::string& name)
{
    if (name == "first") return RootEnd::First;
    if (name == "last") return RootEnd::Last;
    if (name == "auto") return RootEnd::Auto;
    throw ParamError<ValueError>({readOptionSetting(ParamName{"--roots", "roots"}), "'" + name + "': must be first, last or auto"});
}

void reverseStrand(StrandSet& strands, std::size_t i)
{
    const std::size_t b = strands.offsets[i], e = strands.offsets[i + 1];
    std::reverse(strands.positions.begin() + b, strands.positions.begin() + e);
    if (!strands.thickness.empty()) std::reverse(strands.thickness.begin() + b, strands.thickness.begin() + e);
    if (!strands.transparency.empty()) std::reverse(strands.transparency.begin() + b, strands.transparency.begin() + e);
    if (!strands.color.empty()) std::reverse(strands.color.begin() + b, strands.color.begin() + e);
}

namespace {

struct Sphere { Eigen::Vector3d center{0, 0, 0}; double radius = 0.0; bool valid = false; };

/// Least-squares sphere through @a pts (Coope 1993, "Circle fitting by linear and nonlinear least
/// squares": |p|^2 = 2 c.p + (r^2 - |c|^2) is linear in c and r^2 - |c|^2), on points centred and
/// scaled to unit RMS so that the normal equations stay well conditioned at any unit.
Sphere fitSphere(const std::vector<Eigen::Vector3d>& pts)
{
    Sphere s;
    if (pts.size() < 4) return s;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : pts) mean += p;
    mean /= double(pts.size());
    double ss = 0.0;
    for (const auto& p : pts) ss += (p - mean).squaredNorm();
    const double scale = std::sqrt(ss / double(pts.size()));
    if (!(scale > 0.0)) return s;
    Eigen::Matrix4d ata = Eigen::Matrix4d::Zero();
    Eigen::Vector4d atb = Eigen::Vector4d::Zero();
    for (const auto& p : pts) {
        const Eigen::Vector3d q = (p - mean) / scale;
        const Eigen::Vector4d row(2 * q.x(), 2 * q.y(), 2 * q.z(), 1.0);
        ata += row * row.transpose();
        atb += row * q.squaredNorm();
    }
    const Eigen::Vector4d x = ata.colPivHouseholderQr().solve(atb);
    const Eigen::Vector3d c = x.head<3>();
    const double r2 = x[3] + c.squaredNorm();
    if (!std::isfinite(r2) || r2 <= 0.0) return s;
    s.center = c * scale + mean;
    s.radius = std::sqrt(r2) * scale;
    s.valid = std::isfinite(s.radius) && s.center.allFinite();
    return s;
}

Eigen::Vector3d toEigen(const Vec3f& p) { return Eigen::Vector3d(p.x(), p.y(), p.z()); }

/// The share of every vertex lying outside @a s (beyond 0.98 of its radius: roots sit on the
/// sphere, so a strict test would count half of them inside).
double shareOutside(const StrandSet& strands, const Sphere& s)
{
    if (!s.valid || strands.positions.empty()) return 0.0;
    const double r2 = 0.98 * 0.98 * s.radius * s.radius;
    std::size_t out = 0;
    for (const Vec3f& p : strands.positions) out += (toEigen(p) - s.center).squaredNorm() >= r2;
    return double(out) / double(strands.positions.size());
}

std::string percent(double share)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", 100.0 * share);
    return buf;
}

} // namespace

RootEndDecision orientStrandRoots(StrandSet& strands, RootEnd end, const SurfaceDistanceFn& headDistance)
{
    RootEndDecision d;
    const std::size_t n = strands.numStrands();
    d.strands = n;
    if (end == RootEnd::First || n == 0) return d;
    if (end == RootEnd::Auto) {
        if (headDistance) {
            // The majority of strands: the end nearer the head's surface.
            d.usedHead = true;
            std::size_t firstNearer = 0, lastNearer = 0;
            for (std::size_t i = 0; i < n; ++i) {
                const double a = headDistance(strands.positions[strands.offsets[i]]);
                const double b = headDistance(strands.positions[strands.offsets[i + 1] - 1]);
                firstNearer += a < b;
                lastNearer += b < a;
            }
            d.scoreFirst = double(firstNearer) / double(n);
            d.scoreLast = double(lastNearer) / double(n);
        } else {
            if (n < kAutoRootsMinStrands) {
                d.decided = false;
                return d;
            }
            std::vector<Eigen::Vector3d> firstEnds, lastEnds;
            firstEnds.reserve(n);
            lastEnds.reserve(n);
            for (std::size_t i = 0; i < n; ++i) {
                firstEnds.push_back(toEigen(strands.positions[strands.offsets[i]]));
                lastEnds.push_back(toEigen(strands.positions[strands.offsets[i + 1] - 1]));
            }
            d.scoreFirst = shareOutside(strands, fitSphere(firstEnds));
            d.scoreLast = shareOutside(strands, fitSphere(lastEnds));
        }
        d.reversed = d.scoreLast > d.scoreFirst;  // a tie keeps the stored order
    } else {
        d.reversed = true;
    }
    if (d.reversed) {
        for (std::size_t i = 0; i < n; ++i) reverseStrand(strands, i);
    }
    return d;
}

std::string describeRootEndDecision(const RootEndDecision& d, const std::string& setting)
{
    if (!d.decided) {
        return setting + ": " + std::to_string(d.strands) + " strand(s) are too few to tell the root end without a head (" +
               std::to_string(kAutoRootsMinStrands) + " needed); kept as stored (first vertex = root); give the head or choose first or last";
    }
    if (!d.reversed) return "";
    const std::string why = d.usedHead
        ? "the last vertex is nearer the head in " + percent(d.scoreLast) + " % of the strands, the first in " + percent(d.scoreFirst) + " %"
        : percent(d.scoreLast) + " % of the hair lies outside the sphere through the last vertices, " + percent(d.scoreFirst) +
              " % outside the sphere through the first";
    return setting + " reversed 100 % of the strands (" + std::to_string(d.strands) + " of " + std::to_string(d.strands) +
           "): the roots were stored last (" + why + ")";
}

} // namespace vdbhair
