// The one translation unit that includes OpenVDB's mesh-to-volume and level-set tools for scalps.
#include "ScalpSurface.h"

#include <vdbhair/Format.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/Progress.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/VariationalImplicit.h>

#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <unordered_map>
#include <unordered_set>

namespace vdbhair {

namespace {


/// The voxel size to use, checked (OpenVDB's transforms refuse less than 2e-5... keep it sane).
double resolveVoxelSize(const ScalpParams& params, const BBox& box, const std::string& where)
{
    const double h = params.voxelSize > 0.0 ? params.voxelSize : defaultScalpVoxelSize(box);
    if (!(h >= 1e-5) || !std::isfinite(h)) {
        throw ValueError(where + ": voxel size " + formatNumber(h) + " must be a finite length of at least 1e-5");
    }
    if (!(params.halfWidth >= ScalpParams::kMinHalfWidth) || !(params.halfWidth <= ScalpParams::kMaxHalfWidth)) {
        throw ValueError(where + ": half width " + formatNumber(params.halfWidth) + " voxels must be between " +
                         formatNumber(ScalpParams::kMinHalfWidth) + " and " + formatNumber(ScalpParams::kMaxHalfWidth));
    }
    return h;
}

void checkBandEstimate(double area, double h, const ScalpParams& params, const std::string& where)
{
    const std::uint64_t estimate = estimateBandVoxels(area, h, params.halfWidth);
    if (estimate > params.maxVoxels) {
        throw LimitError(where + ": voxel size " + formatNumber(h) + " would make about " + std::to_string(estimate) +
                         " narrow-band voxels (surface area " + formatNumber(area) + ", half width " + formatNumber(params.halfWidth) +
                         "), more than the cap of " + std::to_string(params.maxVoxels) + "; use a larger voxel size");
    }
}

/// Whether the level set has an inside with volume: a value (voxel or tile) at least 1.5 voxels
/// deep. A flat or open sheet gets negative values only in the voxels it crosses.
bool hasInside(const openvdb::FloatGrid& grid)
{
    const float deep = -1.5f * float(grid.voxelSize().x());
    for (auto it = grid.tree().cbeginValueAll(); it; ++it) {
        if (*it <= deep) return true;
    }
    return false;
}

/// The mesh's surface area, for the band estimate (before anything is allocated).
double meshArea(const TriangleMesh& mesh)
{
    double area = 0.0;
    for (const auto& t : mesh.triangles) {
        const Vec3d a(mesh.vertices[t[0]]), b(mesh.vertices[t[1]]), c(mesh.vertices[t[2]]);
        area += 0.5 * (b - a).cross(c - a).length();
    }
    return area;
}

/// A mesh as OpenVDB's mesh-to-volume takes it.
struct VolumeMesh
{
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> tris;
};

/// The mesh with vertices at identical positions welded, and the triangles that welding
/// collapsed dropped.
VolumeMesh weldVertices(const TriangleMesh& mesh, ScalpMeshReport& rep)
{
    VolumeMesh vm;
    std::vector<std::uint32_t> remap(mesh.vertices.size());
    {
        std::map<std::array<float, 3>, std::uint32_t> seen;
        for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
            const Vec3f& p = mesh.vertices[i];
            const auto [it, inserted] = seen.emplace(std::array<float, 3>{p.x(), p.y(), p.z()}, std::uint32_t(vm.points.size()));
            if (inserted) vm.points.push_back(p);
            else ++rep.weldedVertices;
            remap[i] = it->second;
        }
    }
    vm.tris.reserve(mesh.triangles.size());
    for (const auto& t : mesh.triangles) {
        const openvdb::Vec3I w(remap[t[0]], remap[t[1]], remap[t[2]]);
        if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) continue;  // collapsed by welding
        vm.tris.push_back(w);
    }
    return vm;
}

/// The boundary edges (of one triangle), directed as in their triangle: a -> b, and each
/// vertex's count of boundary edges ending at it.
struct BoundaryEdges
{
    std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> next;
    std::unordered_map<std::uint32_t, int> inDegree;
};

BoundaryEdges boundaryEdges(const std::vector<openvdb::Vec3I>& tris, ScalpMeshReport& rep)
{
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edgeUse;
    for (const auto& t : tris) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = t[k], b = t[(k + 1) % 3];
            ++edgeUse[{std::min(a, b), std::max(a, b)}];
        }
    }
    BoundaryEdges be;
    for (const auto& t : tris) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = t[k], b = t[(k + 1) % 3];
            const int use = edgeUse[{std::min(a, b), std::max(a, b)}];
            if (use == 1) {
                be.next[a].push_back(b);
                ++be.inDegree[b];
            }
        }
    }
    for (const auto& e : edgeUse) {
        if (e.second == 1) ++rep.boundaryEdges;
        if (e.second > 2) ++rep.nonManifoldEdges;
    }
    return be;
}

/// Cap each simple boundary loop with a fan to its centroid (in a fixed order: by start
/// vertex), and count the edges left open: boundary edges that start on no capped loop.
void capBoundaryLoops(VolumeMesh& vm, BoundaryEdges& be, ScalpMeshReport& rep)
{
    auto& next = be.next;
    auto& inDegree = be.inDegree;
    std::vector<std::uint32_t> starts;
    for (const auto& kv : next) starts.push_back(kv.first);
    std::sort(starts.begin(), starts.end());
    std::unordered_map<std::uint32_t, bool> done;
    std::unordered_set<std::uint32_t> cappedVertex;
    auto simple = [&](std::uint32_t v) { return next.count(v) && next[v].size() == 1 && inDegree[v] == 1; };
    for (std::uint32_t s : starts) {
        if (done[s] || !simple(s)) continue;
        std::vector<std::uint32_t> loop{s};
        bool closed = false, ok = true;
        std::uint32_t v = s;
        while (true) {
            const std::uint32_t w = next[v][0];
            if (w == s) { closed = true; break; }
            if (!simple(w) || done[w] || loop.size() > vm.tris.size()) { ok = false; break; }
            loop.push_back(w);
            v = w;
        }
        for (std::uint32_t u : loop) done[u] = true;
        if (!closed || !ok || loop.size() < 3) continue;
        Vec3d c(0.0);
        for (std::uint32_t u : loop) c += Vec3d(vm.points[u]);
        c /= double(loop.size());
        const std::uint32_t ci = std::uint32_t(vm.points.size());
        vm.points.emplace_back(float(c.x()), float(c.y()), float(c.z()));
        for (std::size_t i = 0; i < loop.size(); ++i) {
            // The boundary edge runs a -> b in its triangle; the cap runs b -> a.
            vm.tris.emplace_back(loop[(i + 1) % loop.size()], loop[i], ci);
        }
        for (std::uint32_t u : loop) cappedVertex.insert(u);
        ++rep.cappedLoops;
    }
    for (const auto& kv : next) {
        if (!cappedVertex.count(kv.first)) rep.openEdges += kv.second.size();
    }
}

/// OpenVDB's narrow-band level set of the mesh at voxel size @a h, checked to have an inside.
openvdb::FloatGrid::Ptr meshLevelSet(const VolumeMesh& vm, double h, float halfWidth, const ScalpMeshReport& rep,
                                     openvdb::util::NullInterrupter* interrupter, const std::string& where)
{
    const openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(h);
    openvdb::FloatGrid::Ptr grid;
    const std::vector<openvdb::Vec4I> quads;
    if (interrupter) {
        grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*interrupter, *xform, vm.points, vm.tris, quads, halfWidth);
        if (interrupter->wasInterrupted()) throw InterruptedError(where + ": interrupted");
    } else {
        grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, vm.points, vm.tris, quads, halfWidth);
    }
    if (!hasInside(*grid)) {
        throw FormatError(where + ": the level set has no inside: the mesh is not a closed surface (" +
                          std::to_string(rep.boundaryEdges) + " boundary edges after welding, " + std::to_string(rep.cappedLoops) +
                          " loops capped, " + std::to_string(rep.openEdges) + " edges on no simple loop, " +
                          std::to_string(rep.nonManifoldEdges) + " non-manifold edges)");
    }
    return grid;
}

} // namespace

double defaultScalpVoxelSize(const BBox& box)
{
    const Vec3f e = box.extent();
    return double(std::max({e.x(), e.y(), e.z()})) / 100.0;
}

std::uint64_t estimateBandVoxels(double area, double voxelSize, double halfWidth)
{
    const double v = 1.1 * area / (voxelSize * voxelSize) * 2.0 * halfWidth;
    return v >= 1.8e19 ? std::numeric_limits<std::uint64_t>::max() : std::uint64_t(std::ceil(v));
}

void stampScalpGrid(openvdb::FloatGrid& grid, const std::string& kind, const ScalpParams& params)
{
    grid.setName("surface");
    grid.setGridClass(openvdb::GRID_LEVEL_SET);
    grid.setCreator("vdbhair " VDBHAIR_VERSION_STRING);
    grid.insertMeta("vdbhair_scalp_kind", openvdb::StringMetadata(kind));
    grid.insertMeta("vdbhair_source", openvdb::StringMetadata(params.source.empty() ? kind : params.source));
    grid.insertMeta("vdbhair_voxel_size", openvdb::DoubleMetadata(grid.voxelSize().x()));
    grid.insertMeta("vdbhair_half_width", openvdb::FloatMetadata(params.halfWidth));
}

openvdb::FloatGrid::Ptr scalpFromMesh(const TriangleMesh& mesh, const ScalpParams& params, ScalpMeshReport* report,
                                      openvdb::util::NullInterrupter* interrupter)
{
    initializeOpenVdb();
    const std::string where = "scalpFromMesh(" + (params.source.empty() ? std::string("mesh") : params.source) + ")";
    if (mesh.triangles.empty()) throw ValueError(where + ": the mesh has no triangles; a level set needs a closed surface");
    const BBox box = meshBBox(mesh);
    const Vec3f ext = box.extent();
    if (!(std::max({ext.x(), ext.y(), ext.z()}) > 0.f)) throw ValueError(where + ": all vertices are at one position; the mesh encloses nothing");
    const double h = resolveVoxelSize(params, box, where);
    checkBandEstimate(meshArea(mesh), h, params, where);

    ScalpMeshReport rep;
    VolumeMesh vm = weldVertices(mesh, rep);
    BoundaryEdges be = boundaryEdges(vm.tris, rep);
    capBoundaryLoops(vm, be, rep);
    const openvdb::FloatGrid::Ptr grid = meshLevelSet(vm, h, params.halfWidth, rep, interrupter, where);
    stampScalpGrid(*grid, "mesh", params);
    grid->insertMeta("vdbhair_capped_loops", openvdb::Int64Metadata(std::int64_t(rep.cappedLoops)));
    if (report) *report = rep;
    return grid;
}

openvdb::FloatGrid::Ptr scalpFromSphere(const Vec3d& center, double radius, const ScalpParams& params)
{
    initializeOpenVdb();
    const std::string where = "scalpFromSphere";
    if (!(radius > 0.0) || !std::isfinite(radius)) throw ValueError(where + ": radius " + formatNumber(radius) + " must be a positive length");
    if (!std::isfinite(center.x()) || !std::isfinite(center.y()) || !std::isfinite(center.z())) throw ValueError(where + ": the centre must be finite");
    BBox box;
    box.expand(Vec3f(center - Vec3d(radius)));
    box.expand(Vec3f(center + Vec3d(radius)));
    const double h = resolveVoxelSize(params, box, where);
    checkBandEstimate(4.0 * M_PI * radius * radius, h, params, where);
    openvdb::FloatGrid::Ptr grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        float(radius), openvdb::Vec3f(float(center.x()), float(center.y()), float(center.z())), float(h), params.halfWidth);
    ScalpParams p = params;
    if (p.source.empty()) p.source = "sphere " + formatNumber(center.x()) + "," + formatNumber(center.y()) + "," + formatNumber(center.z()) + "," + formatNumber(radius);
    stampScalpGrid(*grid, "sphere", p);
    return grid;
}

openvdb::FloatGrid::Ptr scalpFromPoints(const OrientedPoints& input, const ScalpParams& params, bool threaded, openvdb::util::NullInterrupter* interrupter)
{
    initializeOpenVdb();
    const std::string where = "scalpFromPoints(" + (params.source.empty() ? std::string("points") : params.source) + ")";
    const std::size_t n = input.size(), maxConstraints = params.maxConstraints;
    if (n < 5) throw ValueError(where + ": " + std::to_string(n) + " constraint points; the implicit needs at least 5 (4 fix its affine part)");
    if (input.normals.size() != n) throw ValueError(where + ": the points have no normals (nx ny nz); the implicit needs one per point to know inside from outside");
    if (maxConstraints < ScalpParams::kMinConstraints)
        throw ValueError(where + ": maxConstraints " + std::to_string(maxConstraints) + " must be at least " + std::to_string(ScalpParams::kMinConstraints));
    BBox box;
    for (const Vec3f& p : input.positions) box.expand(p);
    const double h = resolveVoxelSize(params, box, where);
    // Band estimate: the surface lies in the points' box, so its area is about that of the box's
    // faces (a sphere in its cube has 0.52 of it).
    const Vec3d e(box.extent());
    const double boxArea = 2.0 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
    checkBandEstimate(std::max(boxArea, double(n) * h * h), h, params, where);

    // Thin to maxConstraints by farthest-point sampling from point 0 (deterministic).
    std::vector<Vec3f> pts, nrm;
    if (n <= maxConstraints) {
        pts = input.positions;
        nrm = input.normals;
    } else {
        std::vector<double> dist(n, std::numeric_limits<double>::max());
        std::size_t pick = 0;
        for (std::size_t k = 0; k < maxConstraints; ++k) {
            pts.push_back(input.positions[pick]);
            nrm.push_back(input.normals[pick]);
            std::size_t best = 0;
            double bestD = -1.0;
            for (std::size_t i = 0; i < n; ++i) {
                const double d = (input.positions[i] - input.positions[pick]).lengthSqr();
                dist[i] = std::min(dist[i], d);
                if (dist[i] > bestD) { bestD = dist[i]; best = i; }
            }
            pick = best;
        }
    }
    if (interrupter) interrupter->start("solving the variational implicit");
    const VariationalImplicit implicit(pts, nrm);
    if (interrupter) interrupter->end();

    // Walk the band from the constraint points, wave by wave (the order does not depend on threads).
    const openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(h);
    const float bandWidth = float(params.halfWidth * h);
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(bandWidth);
    grid->setTransform(xform);
    openvdb::BoolGrid visited(false);
    auto acc = grid->getAccessor();
    auto seen = visited.getAccessor();
    const double pad = 0.1 * implicit.modelSize() + 2.0 * bandWidth;
    const openvdb::CoordBBox limit(xform->worldToIndexNodeCentered(Vec3d(box.min) - Vec3d(pad)),
                                   xform->worldToIndexNodeCentered(Vec3d(box.max) + Vec3d(pad)));
    std::vector<openvdb::Coord> front;
    for (const Vec3f& p : pts) {
        const openvdb::Coord c = xform->worldToIndexNodeCentered(Vec3d(p));
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    const openvdb::Coord q = c.offsetBy(dx, dy, dz);
                    if (!seen.getValue(q)) { seen.setValueOn(q, true); front.push_back(q); }
                }
    }
    const std::uint64_t evalCap = 4 * params.maxVoxels;
    std::uint64_t evaluated = 0;
    std::vector<float> dist;
    ProgressCounter progress(interrupter, "sampling the implicit into the band", estimateBandVoxels(boxArea * 0.6, h, params.halfWidth), "voxels");
    while (!front.empty()) {
        evaluated += front.size();
        if (evaluated > evalCap) {
            throw LimitError(where + ": the implicit's band needs more than " + std::to_string(evalCap) +
                             " voxel evaluations (4 x the cap of " + std::to_string(params.maxVoxels) + "); use a larger voxel size");
        }
        dist.assign(front.size(), 0.f);
        auto evalRange = [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                Vec3d g;
                const double f = implicit.valueAndGradient(xform->indexToWorld(front[i]), g);
                const double gl = g.length();
                dist[i] = gl > 0.0 ? float(f / gl) : (f > 0 ? bandWidth : -bandWidth);
            }
        };
        if (threaded) tbb::parallel_for(tbb::blocked_range<std::size_t>(0, front.size(), 64), evalRange);
        else evalRange(tbb::blocked_range<std::size_t>(0, front.size()));
        if (progress.add(front.size())) throw InterruptedError(where + ": interrupted");
        std::vector<openvdb::Coord> nextFront;
        for (std::size_t i = 0; i < front.size(); ++i) {
            if (!(std::abs(dist[i]) < bandWidth)) continue;
            acc.setValueOn(front[i], dist[i]);
            for (int k = 0; k < 6; ++k) {
                openvdb::Coord q = front[i];
                q[k / 2] += (k % 2) ? 1 : -1;
                if (!limit.isInside(q) || seen.getValue(q)) continue;
                seen.setValueOn(q, true);
                nextFront.push_back(q);
            }
        }
        front.swap(nextFront);
    }
    progress.finish();
    if (grid->activeVoxelCount() == 0 || !hasInside(*grid)) {
        throw FormatError(where + ": the implicit through the " + std::to_string(pts.size()) +
                          " points has no zero crossing near them; are the normals pointing outward?");
    }
    openvdb::tools::signedFloodFill(grid->tree());
    ScalpParams p = params;
    stampScalpGrid(*grid, "points", p);
    grid->insertMeta("vdbhair_constraints", openvdb::Int64Metadata(std::int64_t(pts.size())));
    grid->insertMeta("vdbhair_offset", openvdb::DoubleMetadata(implicit.offset()));
    return grid;
}

openvdb::FloatGrid::Ptr readScalp(const std::string& path, openvdb::util::NullInterrupter* interrupter)
{
    if (fileExtension(path) == ".vdb") {
        openvdb::GridBase::Ptr g = readVdbGrid(path, "surface", "readScalp(" + path + ")");
        openvdb::FloatGrid::Ptr grid = openvdb::GridBase::grid<openvdb::FloatGrid>(g);
        if (!grid || grid->getGridClass() != openvdb::GRID_LEVEL_SET)
            throw TypeError(path + ": grid 'surface' is not a float level set; vdbhair scalp makes one");
        return grid;
    }
    ScalpParams params;
    params.source = path;
    return scalpFromMesh(readTriangleMesh(path), params, nullptr, interrupter);
}

} // namespace vdbhair
