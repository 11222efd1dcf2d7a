#include "VdbStrandGrid.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/MetaKeys.h>
#include <vdbhair/io/VdbFile.h>

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointGroup.h>
#include <openvdb/tools/PointIndexGrid.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

namespace vdbhair {

namespace pts = openvdb::points;

namespace {
std::string toString(const openvdb::Coord& c)
{
    return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) + ")";
}
/// A topology attribute (`strand`, `vertex`) of any integer or floating type, read as a whole
/// number: Houdini writes int64 for `i@strand` set in VEX and float for a bare `@strand`.
class WholeNumberAttribute
{
public:
    WholeNumberAttribute(const pts::AttributeArray& array, const std::string& type)
    {
        if (type == "int16") m16.emplace(array);
        else if (type == "int32") m32.emplace(array);
        else if (type == "int64") m64.emplace(array);
        else if (type == "float") mF.emplace(array);
        else if (type == "double") mD.emplace(array);
    }
    static bool supports(const std::string& type)
    {
        return type == "int16" || type == "int32" || type == "int64" || type == "float" || type == "double";
    }
    /// The value at point @a i, as a double (exact for every integer an index can be).
    double get(openvdb::Index i) const
    {
        if (m32) return double(m32->get(i));
        if (m64) return double(m64->get(i));
        if (mF) return double(mF->get(i));
        if (mD) return mD->get(i);
        return double(m16->get(i));
    }

private:
    std::optional<pts::AttributeHandle<std::int16_t>> m16;
    std::optional<pts::AttributeHandle<std::int32_t>> m32;
    std::optional<pts::AttributeHandle<std::int64_t>> m64;
    std::optional<pts::AttributeHandle<float>> mF;
    std::optional<pts::AttributeHandle<double>> mD;
};

} // namespace

PositionCodec positionCodecFromName(const std::string& name)
{
    if (name == "float") return PositionCodec::Float;
    if (name == "fixed16") return PositionCodec::Fixed16;
    if (name == "fixed8") return PositionCodec::Fixed8;
    throw ValueError("position codec '" + name + "' is not one of float, fixed16, fixed8");
}

const char* positionCodecName(PositionCodec codec)
{
    switch (codec) {
    case PositionCodec::Fixed16: return "fixed16";
    case PositionCodec::Fixed8: return "fixed8";
    default: return "float";
    }
}

openvdb::points::PointDataGrid::Ptr createStrandGrid(const StrandSet& strands, const VdbPointsOptions& opts,
                                                     const std::string& where)
{
    initializeOpenVdb();
    if (strands.empty()) throw ValueError(where + ": the hairstyle has no strands; there is nothing to write");
    if (strands.numVertices() > std::size_t(std::numeric_limits<std::int32_t>::max())) {
        throw ValueError(where + ": " + std::to_string(strands.numVertices()) + " vertices exceed the int32 attributes");
    }
    const pts::PointAttributeVector<openvdb::Vec3f> positions(strands.positions);
    double voxelSize = opts.voxelSize;
    if (voxelSize == 0.0) {
        voxelSize = pts::computeVoxelSize(positions, std::max(1u, opts.pointsPerVoxel));
        voxelSize = std::max(voxelSize, 2e-5);  // OpenVDB's smallest (its transforms refuse less)
    }
    if (!(voxelSize >= 2e-5) || !std::isfinite(voxelSize)) {
        throw ValueError(where + ": voxel size " + std::to_string(voxelSize) +
                         " must be a finite length of at least 2e-5 (OpenVDB's smallest)");
    }
    const openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(voxelSize);
    const openvdb::tools::PointIndexGrid::Ptr index =
        openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positions, *xform);

    pts::PointDataGrid::Ptr grid;
    switch (opts.codec) {
    case PositionCodec::Fixed16:
        grid = pts::createPointDataGrid<pts::FixedPointCodec<false>, pts::PointDataGrid>(*index, positions, *xform);
        break;
    case PositionCodec::Fixed8:
        grid = pts::createPointDataGrid<pts::FixedPointCodec<true>, pts::PointDataGrid>(*index, positions, *xform);
        break;
    default:
        grid = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, positions, *xform);
    }
    pts::PointDataTree& tree = grid->tree();

    // Topology: strand and vertex index of every point, and the root group.
    const std::size_t nV = strands.numVertices();
    std::vector<std::int32_t> strandOf(nV), vertexOf(nV);
    std::vector<short> isRoot(nV, 0);
    for (std::size_t i = 0; i < strands.numStrands(); ++i) {
        for (std::size_t v = strands.begin(i); v < strands.end(i); ++v) {
            strandOf[v] = std::int32_t(i);
            vertexOf[v] = std::int32_t(v - strands.begin(i));
        }
        isRoot[strands.begin(i)] = 1;
    }
    pts::appendAttribute<std::int32_t>(tree, "strand");
    pts::populateAttribute(tree, index->tree(), "strand", pts::PointAttributeVector<std::int32_t>(strandOf));
    pts::appendAttribute<std::int32_t>(tree, "vertex");
    pts::populateAttribute(tree, index->tree(), "vertex", pts::PointAttributeVector<std::int32_t>(vertexOf));
    pts::appendGroup(tree, "root");
    pts::setGroup(tree, index->tree(), isRoot, "root");

    if (!strands.color.empty()) {
        pts::appendAttribute<openvdb::Vec3f>(tree, "Cd");
        pts::populateAttribute(tree, index->tree(), "Cd", pts::PointAttributeVector<openvdb::Vec3f>(strands.color));
    }
    if (!strands.thickness.empty()) {
        pts::appendAttribute<float>(tree, "width");
        pts::populateAttribute(tree, index->tree(), "width", pts::PointAttributeVector<float>(strands.thickness));
    }
    if (!strands.transparency.empty()) {
        std::vector<float> alpha(nV);
        for (std::size_t v = 0; v < nV; ++v) alpha[v] = 1.f - strands.transparency[v];
        pts::appendAttribute<float>(tree, "Alpha");
        pts::populateAttribute(tree, index->tree(), "Alpha", pts::PointAttributeVector<float>(alpha));
    }

    for (const auto& [name, values] : opts.strandAttributes) {
        const bool nameOk = !name.empty() && !std::isdigit(static_cast<unsigned char>(name[0])) &&
                            std::all_of(name.begin(), name.end(), [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; });
        if (!nameOk || name == "P" || name == "strand" || name == "vertex" || name == "Cd" || name == "width" || name == "Alpha")
            throw ValueError(where + ": attribute name '" + name + "' must be letters, digits and _ (not starting with a digit) and not one of P, strand, vertex, Cd, width, Alpha");
        if (values.size() != strands.numStrands())
            throw ValueError(where + ": attribute '" + name + "' has " + std::to_string(values.size()) + " values for " +
                             std::to_string(strands.numStrands()) + " strands");
        std::vector<std::int32_t> perVertex(nV);
        for (std::size_t v = 0; v < nV; ++v) perVertex[v] = values[std::size_t(strandOf[v])];
        pts::appendAttribute<std::int32_t>(tree, name);
        pts::populateAttribute(tree, index->tree(), name, pts::PointAttributeVector<std::int32_t>(perVertex));
    }

    grid->setName("strands");
    grid->setGridClass(openvdb::GRID_UNKNOWN);
    grid->insertMeta("creator", openvdb::StringMetadata(creatorString()));
    // The per-vertex defaults (cyHair's header), so that .hair -> .vdb -> .hair loses nothing.
    grid->insertMeta(metaKey("default_thickness"), openvdb::FloatMetadata(strands.defaults.thickness));
    grid->insertMeta(metaKey("default_transparency"), openvdb::FloatMetadata(strands.defaults.transparency));
    grid->insertMeta(metaKey("default_color"), openvdb::Vec3SMetadata(strands.defaults.color));
    grid->insertMeta("vdbhair_strand_count", openvdb::Int64Metadata(std::int64_t(strands.numStrands())));
    grid->insertMeta("vdbhair_position_codec", openvdb::StringMetadata(positionCodecName(opts.codec)));
    return grid;
}

StrandSet strandsFromGrid(const openvdb::points::PointDataGrid& grid, const std::string& where,
                          const ReadOptions& opts, ReadReport* report)
{
    const pts::PointDataTree& tree = grid.tree();
    const auto leaf0 = tree.cbeginLeaf();
    const std::uint64_t nPoints = pts::pointCount(tree);
    if (!leaf0 || nPoints == 0) throw FormatError(where + ": grid '" + grid.getName() + "' has no points");
    const pts::AttributeSet::Descriptor& desc = leaf0->attributeSet().descriptor();
    for (const char* name : {"P", "strand", "vertex"}) {
        if (desc.find(name) == pts::AttributeSet::INVALID_POS) {
            throw FormatError(where + ": grid '" + grid.getName() + "' has no '" + name +
                              "' attribute; a vdbhair strands grid has P, strand and vertex");
        }
    }
    auto checkType = [&](const char* name) {
        const std::string got = desc.valueType(desc.find(name));
        if (!WholeNumberAttribute::supports(got)) {
            throw FormatError(where + ": attribute '" + std::string(name) + "' has type " + got +
                              "; strand and vertex must be integers (int16, int32, int64) or floats (float, double) holding whole numbers");
        }
    };
    checkType("strand");
    checkType("vertex");
    const std::string typeS = desc.valueType(desc.find("strand")), typeV = desc.valueType(desc.find("vertex"));
    const std::size_t iP = desc.find("P"), iS = desc.find("strand"), iV = desc.find("vertex");
    const std::size_t iCd = desc.find("Cd"), iW = desc.find("width"), iA = desc.find("Alpha");
    const bool hasCd = iCd != pts::AttributeSet::INVALID_POS && desc.valueType(iCd) == "vec3s";
    const bool hasW = iW != pts::AttributeSet::INVALID_POS && desc.valueType(iW) == "float";
    const bool hasA = iA != pts::AttributeSet::INVALID_POS && desc.valueType(iA) == "float";

    // The declared strand count must be possible before anything is sized by it.
    std::int64_t declared = -1;
    if (const auto meta = findVdbhairMeta<openvdb::Int64Metadata>(grid, "strand_count")) {
        declared = meta->value();
        if (declared < 0 || std::uint64_t(declared) > nPoints) {
            throw FormatError(where + ": metadata vdbhair_strand_count " + std::to_string(declared) +
                              " is impossible for " + std::to_string(nPoints) + " points");
        }
    }

    if (nPoints > std::numeric_limits<std::uint32_t>::max())
        throw LimitError(where + ": grid '" + grid.getName() + "' has " + std::to_string(nPoints) +
                         " points, more than the 2^32-1 vertices a strand set holds");
    // Gather every point (the tree already holds them: sizes come from real data), leaves in
    // parallel. A leaf's offsets and arrays come from the file as they are: OpenVDB's handles index
    // the arrays without bounds checks, so what they will index is checked first (one flipped bit
    // in an offset otherwise reads and writes past the arrays). Errors are those a pass over the
    // leaves in order would meet first: each leaf's checks, then its points, leaf by leaf.
    std::vector<const pts::PointDataTree::LeafNodeType*> leaves;
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) leaves.push_back(leaf.getLeaf());
    const std::size_t nL = leaves.size();
    std::vector<openvdb::Index32> last(nL, 0);    // each leaf's point count (its last offset)
    std::vector<std::uint64_t> visited(nL, 0);    // the points of its active voxels (what is gathered)
    std::vector<std::string> leafError(nL);       // its first check that fails (layout, offsets)
    std::vector<std::string> arrayError(nL);      // its first array too short for its points
    const std::pair<const char*, std::size_t> used[] = {{"P", iP}, {"strand", iS}, {"vertex", iV},
                                                       {"Cd", iCd}, {"width", iW}, {"Alpha", iA}};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nL, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const auto& leaf = *leaves[l];
            if (!(leaf.attributeSet().descriptor() == desc)) {
                leafError[l] = where + ": the leaf at voxel " + toString(leaf.origin()) +
                               " has other attributes than the first leaf; every leaf of a points grid shares one layout";
                continue;
            }
            openvdb::Index32 previous = 0;
            std::uint64_t onPoints = 0;
            for (openvdb::Index i = 0; i < pts::PointDataTree::LeafNodeType::SIZE; ++i) {
                const openvdb::Index32 offset = leaf.getValue(i);
                if (offset < previous) {
                    leafError[l] = where + ": the leaf at voxel " + toString(leaf.origin()) + " has point offset " +
                                   std::to_string(offset) + " after " + std::to_string(previous) + " (voxel " + std::to_string(i) +
                                   "); a leaf's point offsets never decrease";
                    break;
                }
                if (leaf.isValueOn(i)) onPoints += offset - previous;
                previous = offset;
            }
            if (!leafError[l].empty()) continue;
            last[l] = previous;
            visited[l] = onPoints;
            for (const auto& [name, index] : used) {
                if (index == pts::AttributeSet::INVALID_POS) continue;
                const pts::AttributeArray& array = leaf.constAttributeArray(index);
                if (!array.isUniform() && array.size() < previous) {
                    arrayError[l] = where + ": the leaf at voxel " + toString(leaf.origin()) + " has " + std::to_string(previous) +
                                    " points but its '" + std::string(name) + "' array holds " + std::to_string(array.size()) +
                                    "; each array holds one value per point";
                    break;
                }
            }
        }
    });
    // The leaves before the first one that fails its checks are gathered; their points come first.
    std::vector<std::uint64_t> base(nL + 1, 0);
    std::size_t good = nL;
    std::string firstLeafError;
    for (std::size_t l = 0; l < nL; ++l) {
        if (!leafError[l].empty()) {
            firstLeafError = leafError[l];
        } else if (std::uint64_t(last[l]) > nPoints - base[l]) {
            firstLeafError = where + ": the leaf at voxel " + toString(leaves[l]->origin()) + " holds " + std::to_string(last[l]) +
                             " points, more than the " + std::to_string(nPoints) + " the tree counts";
        } else if (!arrayError[l].empty()) {
            firstLeafError = arrayError[l];
        }
        if (!firstLeafError.empty()) {
            good = l;
            break;
        }
        base[l + 1] = base[l] + visited[l];
    }
    std::vector<Vec3f> pos(nPoints), cd(hasCd ? nPoints : 0);
    std::vector<float> width(hasW ? nPoints : 0), alpha(hasA ? nPoints : 0);
    std::vector<std::int32_t> sid(nPoints), vid(nPoints);
    std::vector<std::string> pointError(good);
    std::vector<std::int64_t> leafMaxStrand(good, -1);
    const std::int64_t strandLimit = declared >= 0 ? declared : std::int64_t(nPoints);
    std::atomic<bool> interrupted{false};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, good, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        if (opts.interrupter && opts.interrupter->wasInterrupted()) {
            interrupted = true;
            return;
        }
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            const auto& leaf = *leaves[l];
            pts::AttributeHandle<openvdb::Vec3f> hP(leaf.constAttributeArray(iP));
            const WholeNumberAttribute hS(leaf.constAttributeArray(iS), typeS), hV(leaf.constAttributeArray(iV), typeV);
            std::optional<pts::AttributeHandle<openvdb::Vec3f>> hCd;
            std::optional<pts::AttributeHandle<float>> hW, hA;
            if (hasCd) hCd.emplace(leaf.constAttributeArray(iCd));
            if (hasW) hW.emplace(leaf.constAttributeArray(iW));
            if (hasA) hA.emplace(leaf.constAttributeArray(iA));
            std::size_t k = std::size_t(base[l]);
            for (auto it = leaf.beginIndexOn(); it; ++it, ++k) {
                const openvdb::Vec3d ijk = it.getCoord().asVec3d();
                const openvdb::Vec3d world = grid.transform().indexToWorld(ijk + hP.get(*it));
                pos[k] = Vec3f(float(world.x()), float(world.y()), float(world.z()));
                const double sv = hS.get(*it), vv = hV.get(*it);
                const std::pair<const char*, double> checks[] = {{"strand", sv}, {"vertex", vv}};
                for (const auto& [name, value] : checks) {
                    if (!std::isfinite(value) || value != std::floor(value)) {
                        std::ostringstream v;
                        v.precision(9);
                        v << value;
                        pointError[l] = where + ": a point in voxel " + toString(it.getCoord()) + " has " + name + " " + v.str() +
                                        "; strand and vertex must hold whole numbers";
                        break;
                    }
                }
                if (!pointError[l].empty()) break;
                sid[k] = (sv >= 0.0 && sv < double(strandLimit)) ? std::int32_t(sv) : -1;
                vid[k] = (vv >= 0.0 && vv < double(nPoints)) ? std::int32_t(vv) : -1;
                if (hasCd) cd[k] = hCd->get(*it);
                if (hasW) width[k] = hW->get(*it);
                if (hasA) alpha[k] = hA->get(*it);
                if (sid[k] < 0 || sid[k] >= strandLimit || vid[k] < 0 || std::uint64_t(vid[k]) >= nPoints) {
                    pointError[l] = where + ": a point in voxel " + toString(it.getCoord()) + " has strand " + std::to_string(std::int64_t(sv)) +
                                    " and vertex " + std::to_string(std::int64_t(vv)) + "; strand must be in [0, " +
                                    std::to_string(strandLimit) + ") and vertex in [0, " + std::to_string(nPoints) + ")";
                    break;
                }
                leafMaxStrand[l] = std::max<std::int64_t>(leafMaxStrand[l], sid[k]);
            }
        }
    });
    if (interrupted) throw InterruptedError(where + ": interrupted while reading");
    for (const std::string& e : pointError)
        if (!e.empty()) throw FormatError(e);
    if (!firstLeafError.empty()) throw FormatError(firstLeafError);
    const std::uint64_t k = base[nL];
    if (k != nPoints) throw FormatError(where + ": counted " + std::to_string(k) + " points, expected " + std::to_string(nPoints));
    std::int64_t maxStrand = -1;
    for (std::int64_t m : leafMaxStrand) maxStrand = std::max(maxStrand, m);
    const std::size_t nS = std::size_t(declared >= 0 ? declared : maxStrand + 1);

    // Vertices per strand = 1 + highest vertex index; every index below must appear exactly once.
    std::vector<std::uint32_t> count(nS, 0);
    for (std::size_t p = 0; p < nPoints; ++p) count[std::size_t(sid[p])] = std::max(count[std::size_t(sid[p])], std::uint32_t(vid[p]) + 1);
    std::vector<std::uint64_t> start(nS + 1, 0);
    for (std::size_t s = 0; s < nS; ++s) start[s + 1] = start[s] + count[s];
    if (start[nS] != nPoints) {
        throw FormatError(where + ": the strands' vertex indices leave gaps or repeat: " + std::to_string(start[nS]) +
                          " vertex slots for " + std::to_string(nPoints) + " points (each strand needs vertices 0..n-1 exactly once)");
    }
    std::vector<std::uint32_t> slot(nPoints, std::numeric_limits<std::uint32_t>::max());
    std::vector<char> filled(nPoints, 0);
    for (std::size_t p = 0; p < nPoints; ++p) {
        const std::uint64_t at = start[std::size_t(sid[p])] + std::uint64_t(vid[p]);
        if (filled[at]) throw FormatError(where + ": strand " + std::to_string(sid[p]) + " has vertex " + std::to_string(vid[p]) + " twice");
        filled[at] = 1;
        slot[at] = std::uint32_t(p);
    }

    // The strands kept (in order, for the short-strand policy's messages), then their vertices in parallel.
    StrandSet out;
    if (const auto m = findVdbhairMeta<openvdb::FloatMetadata>(grid, "default_thickness")) out.defaults.thickness = m->value();
    if (const auto m = findVdbhairMeta<openvdb::FloatMetadata>(grid, "default_transparency")) out.defaults.transparency = m->value();
    if (const auto m = findVdbhairMeta<openvdb::Vec3SMetadata>(grid, "default_color")) out.defaults.color = m->value();
    ShortStrandFilter filter(opts, report, where);
    std::vector<std::uint32_t> kept;
    std::uint64_t keptVertices = 0;
    for (std::size_t s = 0; s < nS; ++s) {
        if (!filter.keep(s, count[s], "grid '" + grid.getName() + "'")) continue;
        kept.push_back(std::uint32_t(s));
        keptVertices += count[s];
    }
    filter.finish();
    out.reserve(kept.size(), keptVertices);
    for (std::uint32_t s : kept) out.offsets.push_back(out.offsets.back() + count[s]);
    out.positions.resize(keptVertices);
    if (hasCd) out.color.resize(keptVertices);
    if (hasW) out.thickness.resize(keptVertices);
    if (hasA) out.transparency.resize(keptVertices);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, kept.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            std::size_t o = out.offsets[i];
            for (std::uint64_t a = start[kept[i]]; a < start[kept[i] + 1]; ++a, ++o) {
                const std::uint32_t p = slot[a];
                out.positions[o] = pos[p];
                if (hasCd) out.color[o] = cd[p];
                if (hasW) out.thickness[o] = width[p];
                if (hasA) out.transparency[o] = 1.f - alpha[p];
            }
        }
    });
    return out;
}

void writeVdbStrands(const std::string& path, const StrandSet& strands, const VdbPointsOptions& opts)
{
    const std::string where = "writeVdbStrands(" + path + ")";
    const pts::PointDataGrid::Ptr grid = createStrandGrid(strands, opts, where);
    writeVdbGrids(path, {grid}, where);
}

StrandSet readVdbStrands(const std::string& path, const ReadOptions& opts, ReadReport* report,
                         const std::string& gridName)
{
    const std::string where = "readVdbStrands(" + path + ")";
    const openvdb::GridBase::Ptr base = readVdbGrid(path, gridName, where);
    const auto grid = openvdb::GridBase::grid<pts::PointDataGrid>(base);
    if (!grid) {
        throw TypeError(where + ": grid '" + gridName + "' is a " + base->type() + ", not a PointDataGrid of strands");
    }
    return strandsFromGrid(*grid, where, opts, report);
}

} // namespace vdbhair
