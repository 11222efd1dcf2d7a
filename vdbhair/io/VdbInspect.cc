#include "VdbInspect.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/VdbFile.h>

#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

namespace vdbhair {

namespace {

constexpr int kBins = 4096;

/// One pass over the active values as (value as double, voxel count) pairs.
template<typename TreeT, typename Fn>
void forEachActive(const TreeT& tree, Fn&& fn)
{
    for (auto it = tree.cbeginValueOn(); it; ++it) fn(*it, it.getVoxelCount());
}

template<typename T> double scalarOf(const T& v) { return double(v); }

template<typename T> double lengthOf(const openvdb::math::Vec3<T>& v)
{
    return std::sqrt(double(v[0]) * double(v[0]) + double(v[1]) * double(v[1]) + double(v[2]) * double(v[2]));
}

/// Min, max, mean, standard deviation and quantiles of (x, weight) pairs given twice by @a pass.
template<typename Pass>
ValueStats statsOf(Pass&& pass)
{
    ValueStats s;
    double sum = 0.0, lo = std::numeric_limits<double>::max(), hi = -std::numeric_limits<double>::max();
    std::uint64_t n = 0;
    pass([&](double x, std::uint64_t w) {
        if (!std::isfinite(x)) return;
        n += w;
        sum += x * double(w);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
    });
    s.count = n;
    if (n == 0) return s;
    s.min = lo;
    s.max = hi;
    s.mean = sum / double(n);
    double var = 0.0;
    std::vector<std::uint64_t> bins(kBins, 0);
    std::vector<double> binLo(kBins, hi), binHi(kBins, lo);  // the values each bin saw
    const double width = hi > lo ? (hi - lo) / kBins : 1.0;
    pass([&](double x, std::uint64_t w) {
        if (!std::isfinite(x)) return;
        var += (x - s.mean) * (x - s.mean) * double(w);
        const std::size_t b = std::size_t(std::min(kBins - 1, std::max(0, int((x - lo) / width))));
        bins[b] += w;
        binLo[b] = std::min(binLo[b], x);
        binHi[b] = std::max(binHi[b], x);
    });
    s.stddev = std::sqrt(var / double(n));
    auto quantile = [&](double q) {
        if (!(hi > lo)) return lo;
        const double target = q * double(n);
        double seen = 0.0;
        for (int b = 0; b < kBins; ++b) {
            const double c = double(bins[std::size_t(b)]);
            // Within the bin, between the least and the greatest value it saw (exact for
            // discrete values).
            if (c > 0.0 && seen + c >= target) return binLo[std::size_t(b)] + (binHi[std::size_t(b)] - binLo[std::size_t(b)]) * ((target - seen) / c);
            seen += c;
        }
        return hi;
    };
    s.p01 = quantile(0.01);
    s.p50 = quantile(0.5);
    s.p99 = quantile(0.99);
    return s;
}

template<typename GridT>
void scalarStats(const GridT& grid, GridReport& r)
{
    r.isScalar = true;
    std::uint64_t zeros = 0;
    r.values = statsOf([&](auto&& sink) {
        forEachActive(grid.tree(), [&](const auto& v, std::uint64_t w) { sink(scalarOf(v), w); });
    });
    forEachActive(grid.tree(), [&](const auto& v, std::uint64_t w) { if (scalarOf(v) == 0.0) zeros += w; });
    r.zeroShare = r.values.count ? double(zeros) / double(r.values.count) : 0.0;
}

template<typename GridT>
void vectorStats(const GridT& grid, GridReport& r)
{
    r.isVector = true;
    r.values = statsOf([&](auto&& sink) {
        forEachActive(grid.tree(), [&](const auto& v, std::uint64_t w) { sink(lengthOf(v), w); });
    });
    std::uint64_t unit = 0, zero = 0, n = 0;
    openvdb::Vec3d sum(0.0), dirSum(0.0);
    forEachActive(grid.tree(), [&](const auto& v, std::uint64_t w) {
        const double len = lengthOf(v);
        if (!std::isfinite(len)) return;
        n += w;
        const openvdb::Vec3d d{double(v[0]), double(v[1]), double(v[2])};
        sum += d * double(w);
        if (std::abs(len - 1.0) <= 1e-3) unit += w;
        if (len == 0.0) zero += w;
        else dirSum += d * (double(w) / len);
    });
    if (n) {
        r.unitShare = double(unit) / double(n);
        r.zeroShare = double(zero) / double(n);
        const openvdb::Vec3d mean = sum / double(n);
        r.meanVector = Vec3d(mean.x(), mean.y(), mean.z());
        r.coherence = n > zero ? dirSum.length() / double(n - zero) : 0.0;
    }
}

template<typename TreeT>
void treeStats(const TreeT& tree, GridReport& r)
{
    // Active tiles by level; the iterator's depth counts from the root (0), leaf voxels are 3.
    for (auto it = tree.cbeginValueOn(); it; ++it) {
        if (!it.isTileValue()) continue;
        const unsigned depth = it.getDepth();  // 0: root tile (4096³), 1: upper node tile (128³), 2: lower node tile (8³)
        if (depth < 3) ++r.tilesByLevel[depth];
    }
    std::vector<openvdb::Index32> counts = tree.nodeCount();  // leaves first, root last
    r.internalNodes = 0;
    for (std::size_t i = 1; i + 1 < counts.size(); ++i) r.internalNodes += counts[i];
    double sum = 0.0, lo = 1.0, hi = 0.0;
    std::uint64_t leaves = 0, full = 0;
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        const double fill = double(leaf->onVoxelCount()) / double(TreeT::LeafNodeType::SIZE);
        sum += fill;
        lo = std::min(lo, fill);
        hi = std::max(hi, fill);
        ++leaves;
        if (leaf->isValueMaskOn()) ++full;
    }
    if (leaves) {
        r.leafFillMean = sum / double(leaves);
        r.leafFillMin = lo;
        r.leafFillMax = hi;
        r.leafFullShare = double(full) / double(leaves);
    }
}

std::string plural(std::int64_t n, const char* one, const char* many)
{
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

/// The metadata @a name; a `vdbhair_` key is also found under its older `vdbhair:` spelling.
const MetaValue* findMeta(const GridInfo& info, const std::string& name)
{
    for (const MetaValue& m : info.metadata) {
        if (m.name == name) return &m;
    }
    if (name.rfind("vdbhair_", 0) == 0) return findMeta(info, "vdbhair:" + name.substr(8));
    return nullptr;
}

} // namespace

std::string explainGrid(const GridInfo& info)
{
    auto text = [&](const char* key) { const MetaValue* m = findMeta(info, key); return m ? metaValueString(*m) : std::string(); };
    auto integer = [&](const char* key) -> std::int64_t {
        const MetaValue* m = findMeta(info, key);
        if (!m) return -1;
        if (auto i = std::get_if<std::int64_t>(&m->value)) return *i;
        if (auto d = std::get_if<double>(&m->value)) return std::int64_t(*d);
        return -1;
    };
    std::ostringstream os;
    // What the grid holds, by its name (the grid conventions of docs/fields.md and docs/scalps.md).
    static const std::map<std::string, std::string> meaning = {
        {"tangent", "the hair's unit direction, root to tip, per voxel (inactive where no hair passed)"},
        {"density", "the hair density as a fog volume in [0, 1]: hair length per unit volume over vdbhair_density_reference, clamped"},
        {"hair_length", "the hair length that passed through each voxel (summed segment length)"},
        {"hair_direction", "the hair's unit direction, root to tip, per voxel (the tangent grid under a name Blender's Cycles does not reserve)"},
        {"helicoid_k", "the local helicoid curvatures (kT, kN, kB) fitted per voxel"},
        {"helicoid_alpha", "the local helicoid elevation factor alpha fitted per voxel"},
        {"frame_T", "the local helicoid frame's tangent T per voxel"},
        {"frame_N", "the local helicoid frame's normal N per voxel (B = T x N)"},
        {"strands", "hair strands as points: one point per vertex, with strand and vertex indices"},
        {"surface", "the scalp as a narrow-band signed distance field (negative inside the head)"},
        {"region", "where on the scalp hair grows (active voxels of the surface's band)"},
        {"roots", "hair roots (follicles) as points: P on the scalp, the surface normal N and a tangent"},
    };
    std::string base = info.name;
    const std::int64_t level = integer("vdbhair_level");
    // Multi-level fields are named tangent_level_0, density_level_1, ...
    const std::size_t lv = base.rfind("_level_");
    if (lv != std::string::npos && lv > 0) base.resize(lv);
    const auto it = meaning.find(base);
    const std::string creator = text("creator");
    const bool ours = creator.rfind("vdbhair", 0) == 0 || findMeta(info, "vdbhair_strand_count") != nullptr;
    if (it != meaning.end() && ours) os << "Holds " << it->second << ".";
    const std::int64_t strands = integer("vdbhair_strand_count");
    const std::string source = text("vdbhair_source");
    const std::int64_t iterations = integer("vdbhair_iterations");
    const std::string space = text("vdbhair_space");
    const std::string voxel = text("vdbhair_voxel_size");
    if (info.isPoints && strands >= 0) {
        os << (os.tellp() > 0 ? " " : "") << "Written by " << (creator.empty() ? "vdbhair" : creator) << " from "
           << plural(strands, "strand", "strands");
        const std::string codec = text("vdbhair_position_codec");
        if (!codec.empty()) os << ", positions stored with the " << codec << " codec";
        os << ".";
    } else if (iterations >= 0 || !space.empty()) {
        const bool tangent = base == "tangent" || base == "hair_direction", density = base == "density" || base == "hair_length";
        const bool helicoid = base.rfind("helicoid_", 0) == 0 || base.rfind("frame_", 0) == 0;
        os << (os.tellp() > 0 ? " " : "") << (tangent ? "Estimated" : density ? "Accumulated" : helicoid ? "Fitted" : "Made") << " by "
           << (creator.empty() ? "vdbhair" : creator);
        if (helicoid) os << " on the tangent field of";
        else if (density) os << " alongside the tangent field of";
        else os << " from";
        if (strands >= 0) os << " " << plural(strands, "strand", "strands");
        else os << " the strands";
        if (!source.empty()) os << " of " << source;
        if (tangent) {
            os << " (Wang et al. 2009, Eq. 9: the unit tangent of every segment, weighted by its length in each voxel it crosses";
            if (iterations >= 0) os << ", " << plural(iterations, "reweighting iteration", "reweighting iterations");
            os << ")";
        }
        if (!voxel.empty()) os << ", voxel size " << voxel;
        if (space == "world") os << ", in world space";
        else if (space == "scalp") {
            os << ", in scalp space (Wang et al.'s (u, v, height) over a sphere";
            const std::string c = text("vdbhair_scalp_center"), rad = text("vdbhair_scalp_radius");
            if (!c.empty()) os << " centred at " << c;
            if (!rad.empty()) os << " of radius " << rad;
            const std::string res = text("vdbhair_scalp_resolution");
            if (!res.empty() && findMeta(info, "vdbhair_scalp_distance"))
                os << "; the height is measured above a head, its distance from the centre tabulated on " << res << " x " << res
                   << " directions in vdbhair_scalp_distance";
            os << ")";
        }
        os << ".";
        const std::int64_t levels = integer("vdbhair_levels");
        if (levels > 1) {
            os << " Level " << level << " of 0.." << levels - 1 << (level == 0 ? " (the finest" : " (level 0 is the finest")
               << "; each level doubles the voxel size).";
        }
    }
    // Scalps, regions and roots (vdbhair scalp, vdbhair roots).
    const std::string scalpKind = text("vdbhair_scalp_kind"), scalpSource = text("vdbhair_source");
    if (!scalpKind.empty()) {
        os << (os.tellp() > 0 ? " " : "") << "Made by " << (creator.empty() ? "vdbhair" : creator) << " from ";
        if (scalpKind == "mesh") os << "the triangle mesh " << scalpSource << " (openvdb::tools::meshToLevelSet; open boundary loops capped)";
        else if (scalpKind == "points") os << "the oriented points of " << scalpSource << " (Turk & O'Brien's variational implicit)";
        else os << "a " << scalpSource;
        const std::string vs = text("vdbhair_voxel_size"), hw = text("vdbhair_half_width");
        if (!vs.empty()) os << ", voxel size " << vs;
        if (!hw.empty()) os << ", band half width " << hw << " voxels";
        os << ".";
    }
    const std::string regionRadius = text("vdbhair_region_radius");
    if (!regionRadius.empty()) {
        os << (os.tellp() > 0 ? " " : "") << "The surface's band voxels within " << regionRadius << " of the "
           << text("vdbhair_region_roots") << " roots of " << (scalpSource.empty() ? "a hairstyle" : scalpSource) << ", projected onto it.";
    }
    const std::string fit = text("vdbhair_helicoid_fit");
    if (!fit.empty()) os << " Helicoid parameters fitted per voxel: " << fit << ".";
    if (!ours && !creator.empty()) os << (os.tellp() > 0 ? " " : "") << "Written by " << creator << ".";
    return os.str();
}

std::vector<GridReport> inspectVdbFile(const std::string& path)
{
    const std::string where = "inspect(" + path + ")";
    std::vector<GridInfo> infos = describeVdbFile(path, where);
    const openvdb::GridPtrVec grids = readVdbGrids(path, where);
    std::vector<GridReport> out;
    for (std::size_t g = 0; g < grids.size() && g < infos.size(); ++g) {
        GridReport r;
        r.info = std::move(infos[g]);
        const openvdb::GridBase& grid = *grids[g];
        const openvdb::CoordBBox ibox = grid.evalActiveVoxelBoundingBox();
        if (!ibox.empty()) {
            r.emptyIndexBBox = false;
            for (int a = 0; a < 3; ++a) { r.indexMin[std::size_t(a)] = ibox.min()[a]; r.indexMax[std::size_t(a)] = ibox.max()[a]; }
        }
        using namespace openvdb;
        using Scalars = TypeList<FloatGrid, DoubleGrid, Int32Grid, Int64Grid, BoolGrid>;
        using Vectors = TypeList<Vec3SGrid, Vec3DGrid, Vec3IGrid>;
        bool handled = grid.apply<Scalars>([&](const auto& typed) { scalarStats(typed, r); treeStats(typed.tree(), r); });
        if (!handled) handled = grid.apply<Vectors>([&](const auto& typed) { vectorStats(typed, r); treeStats(typed.tree(), r); });
        if (!handled) {
            if (const auto* pg = dynamic_cast<const points::PointDataGrid*>(&grid)) {
                // Points per active voxel.
                r.values = statsOf([&](auto&& sink) {
                    for (auto leaf = pg->tree().cbeginLeaf(); leaf; ++leaf) {
                        for (auto v = leaf->cbeginValueOn(); v; ++v) {
                            const Index n = v.pos();  // voxel values are the running ends of its points
                            sink(double(leaf->getValue(n)) - (n ? double(leaf->getValue(n - 1)) : 0.0), 1);
                        }
                    }
                });
                treeStats(pg->tree(), r);
            } else if (const auto* mg = dynamic_cast<const MaskGrid*>(&grid)) {
                treeStats(mg->tree(), r);
            }
        }
        r.explanation = explainGrid(r.info);
        out.push_back(std::move(r));
    }
    return out;
}

std::vector<GridReport> inspectVdbFile(const std::string& path, const std::string& grid)
{
    std::vector<GridReport> reports = inspectVdbFile(path);
    if (grid.empty()) return reports;
    std::vector<GridReport> kept;
    std::string names;
    for (GridReport& r : reports) {
        names += (names.empty() ? "" : ", ") + r.info.name;
        if (r.info.name == grid) kept.push_back(std::move(r));
    }
    if (kept.empty()) throw LookupError(path + ": no grid named '" + grid + "' (the file has: " + (names.empty() ? "no grids" : names) + ")");
    return kept;
}

} // namespace vdbhair
