/// @file SynthTestUtil.h
/// @brief Constructed hairstyles with known wisps for the synthesis tests.
#pragma once

#include <vdbhair/Random.h>
#include <vdbhair/strands/StrandSet.h>

#include <cmath>
#include <vector>

namespace vdbhair::test {

/// @brief @a wisps wisps of strands on the upper cap of the unit sphere at the origin: roots in
/// @a wisps sectors of azimuth (Fibonacci-spread, y > 0.3), each wisp's strands leaving the scalp
/// along the normal and bending by a wisp-specific amount and direction (in the root's frame),
/// with a little per-strand noise. @a truth gets each strand's wisp.
inline StrandSet wispHairstyle(std::size_t strands, int wisps, std::vector<int>* truth = nullptr, int vertices = 24,
                               double noise = 0.01, std::uint64_t seed = 7)
{
    StrandSet out;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    std::size_t made = 0;
    for (std::size_t i = 0; made < strands; ++i) {
        const double y = 1.0 - 1.0 * (double(i) + 0.5) / double(strands * 1.6);
        if (y < 0.3) break;
        const double rho = std::sqrt(1.0 - y * y), th = golden * double(i);
        const Vec3d n(rho * std::cos(th), y, rho * std::sin(th));
        double az = std::atan2(n.z(), n.x());
        if (az < 0) az += 2 * M_PI;
        const int w = std::min(wisps - 1, int(az / (2 * M_PI) * wisps));
        // The root's scalp frame: tangent = the rotation of x taking y onto n (as ScalpMap.h).
        const Vec3d yv(0, 1, 0);
        Vec3d axis = yv.cross(n);
        const double s = axis.length(), c = yv.dot(n);
        axis = s > 1e-12 ? axis / s : Vec3d(1, 0, 0);
        const auto rot = [&](const Vec3d& v) { return v * c + axis.cross(v) * s + axis * (axis.dot(v) * (1 - c)); };
        const Vec3d t = rot(Vec3d(1, 0, 0)), b = rot(Vec3d(0, 0, 1));
        const double bend = 0.4 + 0.5 * double(w % 3), dir = 2 * M_PI * double(w) / wisps;
        Rng rng(seed, i);
        std::vector<Vec3f> pts;
        for (int l = 0; l < vertices; ++l) {
            const double a = double(l) / double(vertices - 1);
            const Vec3d local(bend * a * a * std::cos(dir) + noise * (rng.uniform() - 0.5), 0.8 * a,
                              bend * a * a * std::sin(dir) + noise * (rng.uniform() - 0.5));
            pts.emplace_back(n + t * local.x() + n * local.y() + b * local.z());
        }
        out.addStrand(pts);
        if (truth) truth->push_back(w);
        ++made;
    }
    return out;
}

/// @brief Hubert & Arabie's adjusted Rand index of two labellings.
inline double adjustedRandIndex(const std::vector<int>& a, const std::vector<int>& b)
{
    int ka = 0, kb = 0;
    for (int x : a) ka = std::max(ka, x + 1);
    for (int x : b) kb = std::max(kb, x + 1);
    std::vector<double> table(std::size_t(ka) * kb, 0.0), ra(std::size_t(ka), 0.0), rb(std::size_t(kb), 0.0);
    for (std::size_t i = 0; i < a.size(); ++i) {
        table[std::size_t(a[i]) * kb + b[i]] += 1;
        ra[std::size_t(a[i])] += 1;
        rb[std::size_t(b[i])] += 1;
    }
    const auto c2 = [](double x) { return x * (x - 1) / 2; };
    double sumT = 0, sumA = 0, sumB = 0;
    for (double x : table) sumT += c2(x);
    for (double x : ra) sumA += c2(x);
    for (double x : rb) sumB += c2(x);
    const double expected = sumA * sumB / c2(double(a.size()));
    return (sumT - expected) / (0.5 * (sumA + sumB) - expected);
}

} // namespace vdbhair::test
