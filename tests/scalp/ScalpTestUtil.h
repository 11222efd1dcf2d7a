/// @file ScalpTestUtil.h
/// @brief Analytic inputs of the scalp tests: spheres as points and as meshes.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>

#include <cmath>

namespace vdbhair::test {

/// @a n Fibonacci points on the sphere (c, r) with outward normals.
inline OrientedPoints fibonacciSphere(std::size_t n, const Vec3d& c, double r)
{
    OrientedPoints pts;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (std::size_t i = 0; i < n; ++i) {
        const double y = 1.0 - 2.0 * (double(i) + 0.5) / double(n);
        const double rho = std::sqrt(1.0 - y * y), th = golden * double(i);
        const Vec3d u(rho * std::cos(th), y, rho * std::sin(th));
        pts.positions.emplace_back(c + u * r);
        pts.normals.emplace_back(u);
    }
    return pts;
}

/// A closed latitude-longitude sphere mesh; with @a openBelow > -1, rings whose y/r is below it
/// are left out (a head open at the neck).
inline TriangleMesh sphereMesh(const Vec3d& c, double r, int rings = 32, int sectors = 48, double openBelow = -2.0)
{
    TriangleMesh m;
    std::vector<std::vector<int>> idx(std::size_t(rings + 1), std::vector<int>(std::size_t(sectors), -1));
    for (int i = 0; i <= rings; ++i) {
        const double th = M_PI * double(i) / double(rings);
        if (std::cos(th) < openBelow) continue;
        for (int j = 0; j < sectors; ++j) {
            const double ph = 2.0 * M_PI * double(j) / double(sectors);
            idx[std::size_t(i)][std::size_t(j)] = int(m.vertices.size());
            m.vertices.emplace_back(c + Vec3d(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)) * r);
        }
    }
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < sectors; ++j) {
            const int a = idx[std::size_t(i)][std::size_t(j)], b = idx[std::size_t(i)][std::size_t((j + 1) % sectors)];
            const int cc = idx[std::size_t(i + 1)][std::size_t(j)], d = idx[std::size_t(i + 1)][std::size_t((j + 1) % sectors)];
            if (a < 0 || b < 0 || cc < 0 || d < 0) continue;
            // Outward orientation (counter-clockwise seen from outside); poles give degenerate
            // triangles, which welding drops.
            m.triangles.push_back({std::uint32_t(a), std::uint32_t(b), std::uint32_t(cc)});
            m.triangles.push_back({std::uint32_t(b), std::uint32_t(d), std::uint32_t(cc)});
        }
    }
    return m;
}

} // namespace vdbhair::test
