#include "PointFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/FileUtil.h>

#include <cstring>

namespace vdbhair {

void writePlyPoints(const std::string& path, const OrientedPoints& points)
{
    const std::string where = "writePlyPoints(" + path + ")";
    const std::size_t n = points.size();
    const bool hasN = !points.normals.empty(), hasT = !points.tangents.empty();
    if (hasN && points.normals.size() != n) throw ValueError(where + ": " + std::to_string(points.normals.size()) + " normals for " + std::to_string(n) + " points; give one per point or none");
    if (hasT && points.tangents.size() != n) throw ValueError(where + ": " + std::to_string(points.tangents.size()) + " tangents for " + std::to_string(n) + " points; give one per point or none");

    std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by vdbhair " VDBHAIR_VERSION_STRING "\n";
    out += "element vertex " + std::to_string(n) + "\n";
    out += "property float x\nproperty float y\nproperty float z\n";
    if (hasN) out += "property float nx\nproperty float ny\nproperty float nz\n";
    if (hasT) out += "property float tx\nproperty float ty\nproperty float tz\n";
    out += "end_header\n";
    const std::size_t stride = 3 * (1 + (hasN ? 1 : 0) + (hasT ? 1 : 0));
    std::vector<float> body;
    body.reserve(n * stride);
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) body.push_back(points.positions[i][k]);
        if (hasN) for (int k = 0; k < 3; ++k) body.push_back(points.normals[i][k]);
        if (hasT) for (int k = 0; k < 3; ++k) body.push_back(points.tangents[i][k]);
    }
    const std::size_t head = out.size();
    out.resize(head + body.size() * sizeof(float));
    if (!body.empty()) std::memcpy(&out[head], body.data(), body.size() * sizeof(float));  // little-endian machine
    writeFileAtomic(path, out, where);
}

} // namespace vdbhair
