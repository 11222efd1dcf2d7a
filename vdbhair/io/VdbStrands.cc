#include "VdbStrandGrid.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/SegmentWalk.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/MetaKeys.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbPoints.h>

#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointGroup.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tools/PointsToMask.h>

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

namespace vdbhair {

namespace pts = openvdb::points;

namespace {
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

/// The voxels of @a xform that hold a point of @a positions, as openvdb::tools::PointsToMask
/// activates them (worldToIndexCellCentered() of each point); @a box is the points' box.
std::uint64_t occupiedVoxels(const std::vector<Vec3f>& positions, const openvdb::math::Transform& xform, const openvdb::BBoxd& box)
{
    // The index coordinate grows with the world coordinate on each axis (a positive uniform
    // scale, then rounding): the voxels' box is that of the box's corners.
    const openvdb::Coord lo = xform.worldToIndexCellCentered(box.min()), hi = xform.worldToIndexCellCentered(box.max());
    const double dx = double(hi.x()) - lo.x() + 1, dy = double(hi.y()) - lo.y() + 1, dz = double(hi.z()) - lo.z() + 1;
    if (!(dx * dy * dz <= double(std::uint64_t(1) << 30))) {
        openvdb::MaskGrid mask(false);
        mask.setTransform(xform.copy());
        openvdb::tools::PointsToMask<openvdb::MaskGrid> op(mask);
        op.addPoints<pts::PointAttributeVector<openvdb::Vec3f>, openvdb::Vec3f>(pts::PointAttributeVector<openvdb::Vec3f>(positions));
        return mask.activeVoxelCount();
    }
    const std::uint64_t ny = std::uint64_t(dy), nz = std::uint64_t(dz);
    std::vector<std::uint64_t> bits((std::uint64_t(dx) * ny * nz + 63) / 64, 0);
    auto set = [&](const openvdb::Coord& c) {
        const std::uint64_t k = (std::uint64_t(c.x() - lo.x()) * ny + std::uint64_t(c.y() - lo.y())) * nz + std::uint64_t(c.z() - lo.z());
        std::uint64_t& word = bits[k >> 6];
        const std::uint64_t bit = std::uint64_t(1) << (k & 63);
        if (!(__atomic_load_n(&word, __ATOMIC_RELAXED) & bit)) __atomic_fetch_or(&word, bit, __ATOMIC_RELAXED);
    };
    // A uniform scale maps a point to index space as p * (1 / voxel size) (ScaleMap's
    // applyInverseMap(), whose factor is its map of (1, 1, 1)), and Coord::round() is
    // floor(x + 0.5): the same arithmetic inline, instead of a virtual call and three calls to
    // floor() a point, where every coordinate is well inside an int.
    constexpr int kLimit = 1 << 30;
    const bool inlineMap = xform.mapType() == openvdb::math::UniformScaleMap::mapType() && std::abs(lo.x()) < kLimit &&
                         std::abs(lo.y()) < kLimit && std::abs(lo.z()) < kLimit && std::abs(hi.x()) < kLimit &&
                         std::abs(hi.y()) < kLimit && std::abs(hi.z()) < kLimit;
    const openvdb::Vec3d inv = xform.worldToIndex(openvdb::Vec3d(1.0));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (inlineMap) {
                const openvdb::Vec3d p(positions[i]);
                set(voxelOf(openvdb::Vec3d(p.x() * inv.x(), p.y() * inv.y(), p.z() * inv.z())));
            } else {
                set(xform.worldToIndexCellCentered(positions[i]));
            }
        }
    });
    std::uint64_t count = 0;
    for (const std::uint64_t w : bits) count += std::uint64_t(__builtin_popcountll(w));
    return count;
}

/// populateAttribute(@a tree, @a index, @a name, values) for an attribute of type T with
/// OpenVDB's default (null) codec, where point i's value is @a value(i): the same arrays,
/// compacted as it leaves them, but each value stored directly instead of through a write
/// handle's setter (an indirect call a value: half the time of writing a strands grid's strand
/// and vertex attributes went there).
template<typename T, typename ValueOf>
void populateDirect(pts::PointDataTree& tree, const openvdb::tools::PointIndexTree& index, const std::string& name,
                    const ValueOf& value)
{
    const auto first = tree.cbeginLeaf();
    if (!first) return;
    const std::size_t pos = first->attributeSet().find(name);
    if (pos == pts::AttributeSet::INVALID_POS) throw ValueError("populateDirect: no attribute '" + name + "'");
    openvdb::tree::LeafManager<pts::PointDataTree> leaves(tree);
    tbb::parallel_for(leaves.leafRange(), [&](const openvdb::tree::LeafManager<pts::PointDataTree>::LeafRange& range) {
        for (auto leaf = range.begin(); leaf; ++leaf) {
            const openvdb::tools::PointIndexTree::LeafNodeType* indexLeaf = index.probeConstLeaf(leaf->origin());
            if (!indexLeaf) continue;
            auto& array = pts::TypedAttributeArray<T>::cast(leaf->attributeArray(pos));
            array.expand(/*fill=*/false);  // every value is set below
            openvdb::Index n = 0;
            for (const auto i : indexLeaf->indices()) array.setUnsafe(n++, value(std::size_t(i)));
            array.compact();
        }
    });
}

} // namespace

float pointsVoxelSize(const std::vector<Vec3f>& positions, unsigned pointsPerVoxel)
{
    // openvdb::points::computeVoxelSize() (OpenVDB 10, points/PointConversion.h) step for step,
    // with its identity transform and 5 decimals; only the voxels are counted otherwise.
    namespace math = openvdb::math;
    if (pointsPerVoxel == 0) throw ValueError("pointsVoxelSize: points per voxel cannot be zero");
    float voxelSize(0.1f);
    const std::size_t numPoints = positions.size();
    if (numPoints <= 1) return voxelSize;
    std::size_t targetVoxelCount(numPoints / std::size_t(pointsPerVoxel));
    if (targetVoxelCount == 0) targetVoxelCount++;
    auto voxelSizeFromVolume = [](double volume, std::size_t estimatedVoxelCount, float& size) {
        static const double minimumVoxelVolume(3e-15);
        static const double maximumVoxelVolume(std::numeric_limits<float>::max());
        double voxelVolume = volume / static_cast<double>(estimatedVoxelCount);
        bool valid = true;
        if (voxelVolume < minimumVoxelVolume) {
            voxelVolume = minimumVoxelVolume;
            valid = false;
        } else if (voxelVolume > maximumVoxelVolume) {
            voxelVolume = maximumVoxelVolume;
            valid = false;
        }
        size = static_cast<float>(math::Pow(voxelVolume, 1.0 / 3.0));
        return valid;
    };
    const pts::PointAttributeVector<openvdb::Vec3f> wrapper(positions);
    math::Mat4d inverseTransform = math::Mat4d::identity().inverse();
    inverseTransform = math::unit(inverseTransform);
    pts::point_conversion_internal::CalculatePositionBounds<pts::PointAttributeVector<openvdb::Vec3f>, openvdb::Vec3f> bounds(wrapper, inverseTransform);
    tbb::parallel_reduce(tbb::blocked_range<std::size_t>(0, numPoints), bounds);
    const openvdb::BBoxd bbox = bounds.getBoundingBox();
    if (bbox.min() == bbox.max()) return voxelSize;
    double volume = bbox.volume();
    if (math::isApproxZero(volume)) {
        const openvdb::Vec3d extents = bbox.extents().sorted().reversed();
        if (math::isApproxZero(extents[1])) volume = extents[0] * extents[0] * extents[0];
        else volume = extents[0] * extents[1] * extents[1];
    }
    double previousVolume = volume;
    if (!voxelSizeFromVolume(volume, targetVoxelCount, voxelSize)) return voxelSize;
    std::size_t previousVoxelCount(0);
    std::size_t voxelCount(1);
    while (voxelCount > previousVoxelCount) {
        const math::Transform::Ptr xform = math::Transform::createLinearTransform(voxelSize);
        previousVoxelCount = voxelCount;
        voxelCount = std::size_t(occupiedVoxels(positions, *xform, bbox));
        volume = math::Pow3(voxelSize) * static_cast<float>(voxelCount);
        if (volume >= previousVolume) break;
        previousVolume = volume;
        const float previousVoxelSize = voxelSize;
        if (!voxelSizeFromVolume(volume, targetVoxelCount, voxelSize)) {
            voxelSize = previousVoxelSize;
            break;
        }
        if (voxelSize / previousVoxelSize > 0.9f) break;
    }
    // Truncated to 5 decimals for readability (more where that would give 0).
    float truncated = voxelSize;
    for (int i = 5; i < 11; i++) {
        truncated = static_cast<float>(math::Truncate(double(voxelSize), i));
        if (truncated != 0.0f) break;
    }
    return truncated;
}

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
        voxelSize = pointsVoxelSize(strands.positions, std::max(1u, opts.pointsPerVoxel));
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
    std::vector<std::int32_t> strandOf(nV);
    std::vector<short> isRoot(nV, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, strands.numStrands(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            std::fill(strandOf.begin() + std::ptrdiff_t(strands.begin(i)), strandOf.begin() + std::ptrdiff_t(strands.end(i)), std::int32_t(i));
            isRoot[strands.begin(i)] = 1;
        }
    });
    pts::appendAttribute<std::int32_t>(tree, "strand");
    populateDirect<std::int32_t>(tree, index->tree(), "strand", [&](std::size_t v) { return strandOf[v]; });
    pts::appendAttribute<std::int32_t>(tree, "vertex");
    populateDirect<std::int32_t>(tree, index->tree(), "vertex",
                                 [&](std::size_t v) { return std::int32_t(v - strands.begin(std::size_t(strandOf[v]))); });
    pts::appendGroup(tree, "root");
    pts::setGroup(tree, index->tree(), isRoot, "root");

    if (!strands.color.empty()) {
        pts::appendAttribute<openvdb::Vec3f>(tree, "Cd");
        populateDirect<openvdb::Vec3f>(tree, index->tree(), "Cd", [&](std::size_t v) { return strands.color[v]; });
    }
    if (!strands.thickness.empty()) {
        pts::appendAttribute<float>(tree, "width");
        populateDirect<float>(tree, index->tree(), "width", [&](std::size_t v) { return strands.thickness[v]; });
    }
    if (!strands.transparency.empty()) {
        pts::appendAttribute<float>(tree, "Alpha");
        populateDirect<float>(tree, index->tree(), "Alpha", [&](std::size_t v) { return 1.f - strands.transparency[v]; });
    }

    for (const auto& attribute : opts.strandAttributes) {
        const std::string& name = attribute.first;
        const auto& values = attribute.second;  // a plain reference: lambdas may not capture structured bindings (C++17)
        const bool nameOk = !name.empty() && !std::isdigit(static_cast<unsigned char>(name[0])) &&
                            std::all_of(name.begin(), name.end(), [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; });
        if (!nameOk || name == "P" || name == "strand" || name == "vertex" || name == "Cd" || name == "width" || name == "Alpha")
            throw ValueError(where + ": attribute name '" + name + "' must be letters, digits and _ (not starting with a digit) and not one of P, strand, vertex, Cd, width, Alpha");
        if (values.size() != strands.numStrands())
            throw ValueError(where + ": attribute '" + name + "' has " + std::to_string(values.size()) + " values for " +
                             std::to_string(strands.numStrands()) + " strands");
        pts::appendAttribute<std::int32_t>(tree, name);
        populateDirect<std::int32_t>(tree, index->tree(), name, [&](std::size_t v) { return values[std::size_t(strandOf[v])]; });
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

namespace {

using PointLeaf = pts::PointDataTree::LeafNodeType;

/// Where a strands grid keeps its attributes (positions in its descriptor) and which of the
/// optional ones (colour, width, alpha) it has with the type read.
struct StrandAttributes
{
    std::size_t iP = 0, iS = 0, iV = 0, iCd = 0, iW = 0, iA = 0;
    std::string typeS, typeV;  ///< the value types of strand and vertex
    bool hasCd = false, hasW = false, hasA = false;
};

/// Step 1: the attributes of @a desc (the first leaf's layout): P, strand and vertex must be
/// there, strand and vertex of a type that holds whole numbers.
StrandAttributes strandAttributes(const pts::AttributeSet::Descriptor& desc, const pts::PointDataGrid& grid,
                                  const std::string& where)
{
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
    StrandAttributes a;
    a.typeS = desc.valueType(desc.find("strand"));
    a.typeV = desc.valueType(desc.find("vertex"));
    a.iP = desc.find("P");
    a.iS = desc.find("strand");
    a.iV = desc.find("vertex");
    a.iCd = desc.find("Cd");
    a.iW = desc.find("width");
    a.iA = desc.find("Alpha");
    a.hasCd = a.iCd != pts::AttributeSet::INVALID_POS && desc.valueType(a.iCd) == "vec3s";
    a.hasW = a.iW != pts::AttributeSet::INVALID_POS && desc.valueType(a.iW) == "float";
    a.hasA = a.iA != pts::AttributeSet::INVALID_POS && desc.valueType(a.iA) == "float";
    return a;
}

/// Step 2: the strand count the grid's metadata declares (-1 if none), checked to be possible
/// for @a nPoints points before anything is sized by it.
std::int64_t declaredStrandCount(const pts::PointDataGrid& grid, std::uint64_t nPoints, const std::string& where)
{
    std::int64_t declared = -1;
    if (const auto meta = findVdbhairMeta<openvdb::Int64Metadata>(grid, "strand_count")) {
        declared = meta->value();
        if (declared < 0 || std::uint64_t(declared) > nPoints) {
            throw FormatError(where + ": metadata vdbhair_strand_count " + std::to_string(declared) +
                              " is impossible for " + std::to_string(nPoints) + " points");
        }
    }
    return declared;
}

/// What a first pass over the leaves (in parallel) finds about each leaf, before any point is
/// read: OpenVDB's handles index the arrays without bounds checks, so what they will index is
/// checked first (one flipped bit in an offset otherwise reads and writes past the arrays).
struct LeafSurvey
{
    std::vector<const PointLeaf*> leaves;
    std::vector<openvdb::Index32> last;  ///< each leaf's point count (its last offset)
    std::vector<std::uint64_t> visited;  ///< the points of its active voxels (what is gathered)
    std::vector<std::string> leafError;  ///< its first check that fails (layout, offsets)
    std::vector<std::string> arrayError; ///< its first array too short for its points
};

/// The checks of one leaf of @a s (number @a l) against the first leaf's layout @a desc.
void surveyLeaf(LeafSurvey& s, std::size_t l, const pts::AttributeSet::Descriptor& desc, const StrandAttributes& a,
                const std::string& where)
{
    const PointLeaf& leaf = *s.leaves[l];
    if (!(leaf.attributeSet().descriptor() == desc)) {
        s.leafError[l] = where + ": the leaf at voxel " + coordText(leaf.origin()) +
                         " has other attributes than the first leaf; every leaf of a points grid shares one layout";
        return;
    }
    openvdb::Index32 previous = 0;
    std::uint64_t onPoints = 0;
    for (openvdb::Index i = 0; i < PointLeaf::SIZE; ++i) {
        const openvdb::Index32 offset = leaf.getValue(i);
        if (offset < previous) {
            s.leafError[l] = where + ": the leaf at voxel " + coordText(leaf.origin()) + " has point offset " +
                             std::to_string(offset) + " after " + std::to_string(previous) + " (voxel " + std::to_string(i) +
                             "); a leaf's point offsets never decrease";
            return;
        }
        if (leaf.isValueOn(i)) onPoints += offset - previous;
        previous = offset;
    }
    s.last[l] = previous;
    s.visited[l] = onPoints;
    const std::pair<const char*, std::size_t> used[] = {{"P", a.iP}, {"strand", a.iS}, {"vertex", a.iV},
                                                       {"Cd", a.iCd}, {"width", a.iW}, {"Alpha", a.iA}};
    for (const auto& [name, index] : used) {
        if (index == pts::AttributeSet::INVALID_POS) continue;
        const pts::AttributeArray& array = leaf.constAttributeArray(index);
        if (pointArrayLength(array) < previous) {
            s.arrayError[l] = where + ": the leaf at voxel " + coordText(leaf.origin()) + " has " + std::to_string(previous) +
                              " points but its '" + std::string(name) + "' array holds " + std::to_string(pointArrayLength(array)) +
                              "; each array holds one value per point";
            return;
        }
    }
}

/// Step 3: every leaf of @a tree surveyed, in parallel.
LeafSurvey surveyLeaves(const pts::PointDataTree& tree, const pts::AttributeSet::Descriptor& desc, const StrandAttributes& a,
                        const std::string& where)
{
    LeafSurvey s;
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) s.leaves.push_back(leaf.getLeaf());
    const std::size_t nL = s.leaves.size();
    s.last.assign(nL, 0);
    s.visited.assign(nL, 0);
    s.leafError.resize(nL);
    s.arrayError.resize(nL);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nL, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t l = r.begin(); l != r.end(); ++l) surveyLeaf(s, l, desc, a, where);
    });
    return s;
}

/// Which leaves are gathered: those before the first one that fails its checks (@a good of
/// them), their points first; base[l] is leaf l's first point.
struct GatherPlan
{
    std::vector<std::uint64_t> base;
    std::size_t good = 0;
    std::string firstLeafError;  ///< the failing leaf's message ("" when all pass)
};

/// Step 4: the plan, from the survey, leaf by leaf in order (so that the error is the one a pass
/// in order would meet first).
GatherPlan planGather(const LeafSurvey& s, std::uint64_t nPoints, const std::string& where)
{
    const std::size_t nL = s.leaves.size();
    GatherPlan plan;
    plan.base.assign(nL + 1, 0);
    plan.good = nL;
    for (std::size_t l = 0; l < nL; ++l) {
        if (!s.leafError[l].empty()) {
            plan.firstLeafError = s.leafError[l];
        } else if (std::uint64_t(s.last[l]) > nPoints - plan.base[l]) {
            plan.firstLeafError = where + ": the leaf at voxel " + coordText(s.leaves[l]->origin()) + " holds " +
                                  std::to_string(s.last[l]) + " points, more than the " + std::to_string(nPoints) + " the tree counts";
        } else if (!s.arrayError[l].empty()) {
            plan.firstLeafError = s.arrayError[l];
        }
        if (!plan.firstLeafError.empty()) {
            plan.good = l;
            break;
        }
        plan.base[l + 1] = plan.base[l] + s.visited[l];
    }
    return plan;
}

/// Every gathered point's values, in leaf order: world position, strand and vertex index, and
/// the optional attributes the grid has.
struct GridPoints
{
    std::vector<Vec3f> pos, cd;
    std::vector<float> width, alpha;
    std::vector<std::int32_t> sid, vid;
};

/// The points of @a leaf into @a out from point @a k on, each checked to have a whole strand in
/// [0, @a strandLimit) and a whole vertex in [0, @a nPoints). Returns the first error ("" if
/// none) and raises @a maxStrand to the highest strand seen.
std::string gatherLeaf(const PointLeaf& leaf, std::size_t k, const pts::PointDataGrid& grid, const StrandAttributes& a,
                       std::int64_t strandLimit, std::uint64_t nPoints, const std::string& where, GridPoints& out,
                       std::int64_t& maxStrand)
{
    pts::AttributeHandle<openvdb::Vec3f> hP(leaf.constAttributeArray(a.iP));
    const WholeNumberAttribute hS(leaf.constAttributeArray(a.iS), a.typeS), hV(leaf.constAttributeArray(a.iV), a.typeV);
    std::optional<pts::AttributeHandle<openvdb::Vec3f>> hCd;
    std::optional<pts::AttributeHandle<float>> hW, hA;
    if (a.hasCd) hCd.emplace(leaf.constAttributeArray(a.iCd));
    if (a.hasW) hW.emplace(leaf.constAttributeArray(a.iW));
    if (a.hasA) hA.emplace(leaf.constAttributeArray(a.iA));
    for (auto it = leaf.beginIndexOn(); it; ++it, ++k) {
        const openvdb::Vec3d ijk = it.getCoord().asVec3d();
        const openvdb::Vec3d world = grid.transform().indexToWorld(ijk + hP.get(*it));
        out.pos[k] = Vec3f(float(world.x()), float(world.y()), float(world.z()));
        const double sv = hS.get(*it), vv = hV.get(*it);
        const std::pair<const char*, double> checks[] = {{"strand", sv}, {"vertex", vv}};
        for (const auto& [name, value] : checks) {
            if (!std::isfinite(value) || value != std::floor(value)) {
                std::ostringstream v;
                v.precision(9);
                v << value;
                return where + ": a point in voxel " + coordText(it.getCoord()) + " has " + name + " " + v.str() +
                       "; strand and vertex must hold whole numbers";
            }
        }
        out.sid[k] = (sv >= 0.0 && sv < double(strandLimit)) ? std::int32_t(sv) : -1;
        out.vid[k] = (vv >= 0.0 && vv < double(nPoints)) ? std::int32_t(vv) : -1;
        if (a.hasCd) out.cd[k] = hCd->get(*it);
        if (a.hasW) out.width[k] = hW->get(*it);
        if (a.hasA) out.alpha[k] = hA->get(*it);
        if (out.sid[k] < 0 || out.sid[k] >= strandLimit || out.vid[k] < 0 || std::uint64_t(out.vid[k]) >= nPoints) {
            // Whole numbers, possibly beyond any integer type: written as doubles.
            const auto whole = [](double x) { std::ostringstream o; o.precision(17); o << x; return o.str(); };
            return where + ": a point in voxel " + coordText(it.getCoord()) + " has strand " + whole(sv) +
                   " and vertex " + whole(vv) + "; strand must be in [0, " +
                   std::to_string(strandLimit) + ") and vertex in [0, " + std::to_string(nPoints) + ")";
        }
        maxStrand = std::max<std::int64_t>(maxStrand, out.sid[k]);
    }
    return {};
}

/// Step 5: the points of the plan's good leaves, leaves in parallel (the tree already holds
/// them: sizes come from real data). Throws the first error in leaf order; returns the highest
/// strand index in @a maxStrand (-1 for none).
GridPoints gatherPoints(const pts::PointDataGrid& grid, const LeafSurvey& s, const GatherPlan& plan, const StrandAttributes& a,
                        std::uint64_t nPoints, std::int64_t strandLimit, const ReadOptions& opts, const std::string& where,
                        std::int64_t& maxStrand)
{
    GridPoints out;
    out.pos.resize(nPoints);
    out.cd.resize(a.hasCd ? nPoints : 0);
    out.width.resize(a.hasW ? nPoints : 0);
    out.alpha.resize(a.hasA ? nPoints : 0);
    out.sid.resize(nPoints);
    out.vid.resize(nPoints);
    std::vector<std::string> pointError(plan.good);
    std::vector<std::int64_t> leafMaxStrand(plan.good, -1);
    std::atomic<bool> interrupted{false};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, plan.good, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        if (opts.interrupter && opts.interrupter->wasInterrupted()) {
            interrupted = true;
            return;
        }
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
            pointError[l] = gatherLeaf(*s.leaves[l], std::size_t(plan.base[l]), grid, a, strandLimit, nPoints, where, out,
                                       leafMaxStrand[l]);
        }
    });
    if (interrupted) throw InterruptedError(where + ": interrupted while reading");
    for (const std::string& e : pointError)
        if (!e.empty()) throw FormatError(e);
    maxStrand = -1;
    for (std::int64_t m : leafMaxStrand) maxStrand = std::max(maxStrand, m);
    return out;
}

/// Where each strand's vertices go: strand s has count[s] vertices (1 + its highest vertex
/// index), in slots [start[s], start[s+1]); slot[a] is the point in slot a.
struct VertexSlots
{
    std::vector<std::uint32_t> count;
    std::vector<std::uint64_t> start;
    std::vector<std::uint32_t> slot;
};

/// Step 6: the slots of @a nS strands, every vertex index below a strand's count appearing
/// exactly once.
VertexSlots vertexSlots(const GridPoints& points, std::size_t nS, std::uint64_t nPoints, const std::string& where)
{
    VertexSlots v;
    v.count.assign(nS, 0);
    for (std::size_t p = 0; p < nPoints; ++p) {
        v.count[std::size_t(points.sid[p])] = std::max(v.count[std::size_t(points.sid[p])], std::uint32_t(points.vid[p]) + 1);
    }
    v.start.assign(nS + 1, 0);
    for (std::size_t s = 0; s < nS; ++s) v.start[s + 1] = v.start[s] + v.count[s];
    if (v.start[nS] != nPoints) {
        throw FormatError(where + ": the strands' vertex indices leave gaps or repeat: " + std::to_string(v.start[nS]) +
                          " vertex slots for " + std::to_string(nPoints) + " points (each strand needs vertices 0..n-1 exactly once)");
    }
    v.slot.assign(nPoints, std::numeric_limits<std::uint32_t>::max());
    std::vector<char> filled(nPoints, 0);
    for (std::size_t p = 0; p < nPoints; ++p) {
        const std::uint64_t at = v.start[std::size_t(points.sid[p])] + std::uint64_t(points.vid[p]);
        if (filled[at]) throw FormatError(where + ": strand " + std::to_string(points.sid[p]) + " has vertex " + std::to_string(points.vid[p]) + " twice");
        filled[at] = 1;
        v.slot[at] = std::uint32_t(p);
    }
    return v;
}

/// Step 7: the strand set: the strands kept (in order, for the short-strand policy's messages),
/// then their vertices in parallel, with the grid's per-vertex defaults.
StrandSet assembleStrands(const pts::PointDataGrid& grid, const GridPoints& points, const VertexSlots& v, const StrandAttributes& a,
                          const ReadOptions& opts, ReadReport* report, const std::string& where)
{
    StrandSet out;
    if (const auto m = findVdbhairMeta<openvdb::FloatMetadata>(grid, "default_thickness")) out.defaults.thickness = m->value();
    if (const auto m = findVdbhairMeta<openvdb::FloatMetadata>(grid, "default_transparency")) out.defaults.transparency = m->value();
    if (const auto m = findVdbhairMeta<openvdb::Vec3SMetadata>(grid, "default_color")) out.defaults.color = m->value();
    ShortStrandFilter filter(opts, report, where);
    std::vector<std::uint32_t> kept;
    std::uint64_t keptVertices = 0;
    for (std::size_t s = 0; s < v.count.size(); ++s) {
        if (!filter.keep(s, v.count[s], "grid '" + grid.getName() + "'")) continue;
        kept.push_back(std::uint32_t(s));
        keptVertices += v.count[s];
    }
    filter.finish();
    out.reserve(kept.size(), keptVertices);
    for (std::uint32_t s : kept) out.offsets.push_back(out.offsets.back() + v.count[s]);
    out.positions.resize(keptVertices);
    if (a.hasCd) out.color.resize(keptVertices);
    if (a.hasW) out.thickness.resize(keptVertices);
    if (a.hasA) out.transparency.resize(keptVertices);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, kept.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            std::size_t o = out.offsets[i];
            for (std::uint64_t at = v.start[kept[i]]; at < v.start[kept[i] + 1]; ++at, ++o) {
                const std::uint32_t p = v.slot[at];
                out.positions[o] = points.pos[p];
                if (a.hasCd) out.color[o] = points.cd[p];
                if (a.hasW) out.thickness[o] = points.width[p];
                if (a.hasA) out.transparency[o] = 1.f - points.alpha[p];
            }
        }
    });
    return out;
}

} // namespace

StrandSet strandsFromGrid(const openvdb::points::PointDataGrid& grid, const std::string& where,
                          const ReadOptions& opts, ReadReport* report)
{
    const pts::PointDataTree& tree = grid.tree();
    const auto leaf0 = tree.cbeginLeaf();
    const std::uint64_t nPoints = pts::pointCount(tree);
    if (!leaf0 || nPoints == 0) throw FormatError(where + ": grid '" + grid.getName() + "' has no points");
    const pts::AttributeSet::Descriptor& desc = leaf0->attributeSet().descriptor();
    const StrandAttributes attrs = strandAttributes(desc, grid, where);
    const std::int64_t declared = declaredStrandCount(grid, nPoints, where);
    if (nPoints > std::numeric_limits<std::uint32_t>::max())
        throw LimitError(where + ": grid '" + grid.getName() + "' has " + std::to_string(nPoints) +
                         " points, more than the 2^32-1 vertices a strand set holds");

    // Every point gathered, leaves in parallel, after each leaf's offsets and arrays are checked.
    // Errors are those a pass over the leaves in order would meet first: each leaf's checks,
    // then its points, leaf by leaf.
    const LeafSurvey survey = surveyLeaves(tree, desc, attrs, where);
    const GatherPlan plan = planGather(survey, nPoints, where);
    const std::int64_t strandLimit = declared >= 0 ? declared : std::int64_t(nPoints);
    std::int64_t maxStrand = -1;
    const GridPoints points = gatherPoints(grid, survey, plan, attrs, nPoints, strandLimit, opts, where, maxStrand);
    if (!plan.firstLeafError.empty()) throw FormatError(plan.firstLeafError);
    const std::uint64_t k = plan.base[survey.leaves.size()];
    if (k != nPoints) throw FormatError(where + ": counted " + std::to_string(k) + " points, expected " + std::to_string(nPoints));
    const std::size_t nS = std::size_t(declared >= 0 ? declared : maxStrand + 1);

    const VertexSlots slots = vertexSlots(points, nS, nPoints, where);
    return assembleStrands(grid, points, slots, attrs, opts, report, where);
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
    StrandSet strands;
    withinReadBudget(path, where, [&] {  // the expansion too: a uniform array holds any number of points in one value
        const openvdb::GridBase::Ptr base = readVdbGrid(path, gridName, where);
        const auto grid = openvdb::GridBase::grid<pts::PointDataGrid>(base);
        if (!grid) {
            throw TypeError(where + ": grid '" + gridName + "' is a " + base->type() + ", not a PointDataGrid of strands");
        }
        strands = strandsFromGrid(*grid, where, opts, report);
    });
    return strands;
}

} // namespace vdbhair
