#include "RootValues.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/IdList.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/scalp/ScalpRegion.h>

#include <openvdb/tools/Interpolation.h>

#include <array>
#include <cerrno>
#include <map>
#include <cmath>
#include <cstdlib>

namespace vdbhair {

namespace {

/// @a spec split at its last ':' after a file name ending in @a ext ("a.vdb:mask" -> "a.vdb", "mask").
bool splitAt(const std::string& spec, const std::string& ext, std::string& file, std::string& rest)
{
    const std::size_t at = spec.rfind(ext + ":");
    if (at != std::string::npos && at + ext.size() + 1 <= spec.size()) {
        file = spec.substr(0, at + ext.size());
        rest = spec.substr(at + ext.size() + 1);
        return true;
    }
    if (spec.size() >= ext.size() && spec.compare(spec.size() - ext.size(), ext.size(), ext) == 0) {
        file = spec;
        rest.clear();
        return true;
    }
    return false;
}

} // namespace

std::vector<float> readRootValues(const std::string& spec, const std::vector<Vec3d>& roots, const std::string& option, const std::string& preferred,
                                  bool nearest)
{
    const std::size_t R = roots.size();
    std::vector<float> out(R);
    // A number.
    {
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(spec.c_str(), &end);
        if (!spec.empty() && *end == '\0' && errno != ERANGE) {
            if (!std::isfinite(v)) throw ValueError(option + " " + spec + ": must be a finite number");
            std::fill(out.begin(), out.end(), float(v));
            return out;
        }
    }
    std::string file, rest;
    if (splitAt(spec, ".vdb", file, rest)) {
        const openvdb::GridBase::Ptr g = readMaskGrid(file, rest, preferred, option + " (name a grid: " + file + ":GRID)");
        if (const auto f = openvdb::GridBase::grid<openvdb::FloatGrid>(g); f && !nearest) {
            const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*f);
            for (std::size_t i = 0; i < R; ++i) out[i] = sampler.wsSample(roots[i]);
        } else if (f) {
            const auto acc = f->getConstAccessor();
            for (std::size_t i = 0; i < R; ++i) out[i] = acc.getValue(f->transform().worldToIndexCellCentered(roots[i]));
        } else {
            const auto b = openvdb::GridBase::grid<openvdb::BoolGrid>(g);
            const auto acc = b->getConstAccessor();
            for (std::size_t i = 0; i < R; ++i) out[i] = acc.getValue(b->transform().worldToIndexCellCentered(roots[i])) ? 1.f : 0.f;
        }
        for (std::size_t i = 0; i < R; ++i) {
            if (!std::isfinite(out[i])) throw ValueError(file + ": grid '" + g->getName() + "' is not finite at root " + std::to_string(i) + " (" + option + ")");
        }
        return out;
    }
    if (splitAt(spec, ".ply", file, rest) && !rest.empty()) {
        const VertexValueSampler sampler(readTriangleMesh(file), readPlyVertexValues(file, rest), file + ":" + rest, nearest ? 1 : 4);
        for (std::size_t i = 0; i < R; ++i) out[i] = float(sampler.at(roots[i]));
        return out;
    }
    if (fileExtension(spec) == ".ply") {
        throw ValueError(option + " " + spec + ": name the vertex property to read: " + spec + ":PROPERTY (e.g. a painted weight, or red)");
    }
    const std::vector<double> v = readValueList(spec, R, "roots");
    for (std::size_t i = 0; i < R; ++i) out[i] = float(v[i]);
    return out;
}

namespace {

/// The connected piece of each vertex of @a mesh (vertices at one position welded), numbered
/// from 0 in the order of their first triangle; unused vertices take their own numbers after.
std::vector<float> meshIslands(const TriangleMesh& mesh)
{
    const std::size_t V = mesh.vertices.size();
    std::vector<std::uint32_t> parent(V);
    for (std::size_t v = 0; v < V; ++v) parent[v] = std::uint32_t(v);
    auto find = [&](std::uint32_t v) {  // iterative, with path halving: no recursion on input depth
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    auto unite = [&](std::uint32_t a, std::uint32_t b) {
        a = find(a), b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    };
    std::map<std::array<float, 3>, std::uint32_t> at;
    for (std::size_t v = 0; v < V; ++v) {
        const auto key = std::array<float, 3>{mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z()};
        const auto it = at.emplace(key, std::uint32_t(v)).first;
        unite(it->second, std::uint32_t(v));
    }
    for (const auto& t : mesh.triangles) {
        unite(t[0], t[1]);
        unite(t[1], t[2]);
    }
    std::vector<std::int64_t> number(V, -1);
    std::int64_t next = 0;
    for (const auto& t : mesh.triangles) {
        const std::uint32_t r = find(t[0]);
        if (number[r] < 0) number[r] = next++;
    }
    std::vector<float> island(V);
    for (std::size_t v = 0; v < V; ++v) {
        const std::uint32_t r = find(std::uint32_t(v));
        if (number[r] < 0) number[r] = next++;
        island[v] = float(number[r]);
    }
    return island;
}

} // namespace

std::vector<std::int32_t> readRootIds(const std::string& spec, const std::vector<Vec3d>& points, const std::string& option, const std::string& what)
{
    std::string file, rest;
    std::vector<float> values;
    if ((splitAt(spec, ".ply", file, rest) || splitAt(spec, ".obj", file, rest)) && rest == "islands") {
        const TriangleMesh mesh = readTriangleMesh(file);
        const VertexValueSampler sampler(mesh, meshIslands(mesh), file + ":islands", 1);
        values.resize(points.size());
        for (std::size_t i = 0; i < points.size(); ++i) values[i] = float(sampler.at(points[i]));
    } else if (splitAt(spec, ".vdb", file, rest) || (splitAt(spec, ".ply", file, rest) && !rest.empty())) {
        values = readRootValues(spec, points, option, "groups", /*nearest=*/true);
    } else {
        return readIdList(spec, points.size(), what);
    }
    std::vector<std::int32_t> ids(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
        const double v = values[i];
        if (!(std::abs(v - std::round(v)) < 1e-4) || !(std::abs(v) < 2147483647.0)) {
            throw ValueError(option + " " + spec + ": the value " + formatNumber(v) + " at " + what.substr(0, what.size() - 1) + " " + std::to_string(i) +
                             " is not an integer group id");
        }
        ids[i] = std::int32_t(std::lround(v));
    }
    return ids;
}

} // namespace vdbhair
