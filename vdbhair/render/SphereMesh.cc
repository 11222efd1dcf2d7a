#include "SphereMesh.h"

#include <vdbhair/Exceptions.h>

#include <cmath>
#include <string>

namespace vdbhair {

TriangleMesh makeSphereMesh(const Vec3d& center, double radius, int rings, int segments)
{
    if (!(radius > 0.0) || !std::isfinite(radius)) {
        throw ValueError("makeSphereMesh: radius " + std::to_string(radius) + " must be positive and finite");
    }
    if (rings < 2 || segments < 3 || rings > 4096 || segments > 4096) {
        throw ValueError("makeSphereMesh: " + std::to_string(rings) + " rings and " + std::to_string(segments) +
                         " segments: need 2 to 4096 rings and 3 to 4096 segments");
    }
    TriangleMesh mesh;
    // Vertices: the north pole, rings - 1 circles of latitude, the south pole.
    auto vertex = [&](double polar, double azimuth) {
        const Vec3d p = center + radius * Vec3d(std::sin(polar) * std::cos(azimuth), std::cos(polar),
                                                -std::sin(polar) * std::sin(azimuth));
        mesh.vertices.push_back(Vec3f(float(p.x()), float(p.y()), float(p.z())));
    };
    vertex(0.0, 0.0);
    for (int i = 1; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) vertex(M_PI * i / rings, 2.0 * M_PI * j / segments);
    }
    vertex(M_PI, 0.0);
    const auto north = std::uint32_t(0), south = std::uint32_t(mesh.vertices.size() - 1);
    auto at = [&](int ring, int seg) { return std::uint32_t(1 + (ring - 1) * segments + (seg % segments)); };
    // Triangles, counter-clockwise from outside (azimuth runs counter-clockwise seen from +y).
    for (int j = 0; j < segments; ++j) mesh.triangles.push_back({north, at(1, j), at(1, j + 1)});
    for (int i = 1; i + 1 < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    }
    for (int j = 0; j < segments; ++j) mesh.triangles.push_back({south, at(rings - 1, j + 1), at(rings - 1, j)});
    return mesh;
}

} // namespace vdbhair
