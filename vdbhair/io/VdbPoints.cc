#include "VdbPoints.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Memory.h>

#include <openvdb/points/AttributeArray.h>
#include <openvdb/points/AttributeGroup.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <cstdint>

namespace vdbhair {

namespace {

namespace pts = openvdb::points;

/// Copy attribute @a index of every leaf into @a col (T scalar or a 3-vector of it).
template<typename T>
void copyColumn(const std::vector<const pts::PointDataTree::LeafNodeType*>& leaves, std::size_t index, PointColumn& col)
{
    std::size_t k = 0;
    for (const auto* leaf : leaves) {
        pts::AttributeHandle<T> h(leaf->constAttributeArray(index));
        for (auto it = leaf->beginIndexOn(); it; ++it, ++k) {
            const T v = h.get(*it);
            if constexpr (openvdb::VecTraits<T>::IsVec) {
                for (int c = 0; c < 3; ++c) col.values[3 * k + std::size_t(c)] = double(v[c]);
            } else {
                col.values[k] = double(v);
            }
        }
    }
}

/// The copy for OpenVDB's type name @a type, or null when it is not a numeric type read here.
using CopyFn = void (*)(const std::vector<const pts::PointDataTree::LeafNodeType*>&, std::size_t, PointColumn&);
CopyFn copierFor(const std::string& type, std::size_t& components, bool& integer)
{
    struct Entry { const char* name; CopyFn fn; std::size_t components; bool integer; };
    static const Entry kTypes[] = {
        {"int16", &copyColumn<std::int16_t>, 1, true},   {"int32", &copyColumn<std::int32_t>, 1, true},
        {"int64", &copyColumn<std::int64_t>, 1, true},   {"bool", &copyColumn<bool>, 1, true},
        {"uint8", &copyColumn<std::uint8_t>, 1, true},   {"float", &copyColumn<float>, 1, false},
        {"double", &copyColumn<double>, 1, false},       {"vec3s", &copyColumn<openvdb::Vec3f>, 3, false},
        {"vec3d", &copyColumn<openvdb::Vec3d>, 3, false}, {"vec3i", &copyColumn<openvdb::Vec3i>, 3, true},
    };
    for (const Entry& e : kTypes) {
        if (type == e.name) {
            components = e.components;
            integer = e.integer;
            return e.fn;
        }
    }
    return nullptr;
}

/// The name of array @a index of @a desc (an attribute's, or the groups' array).
std::string arrayName(const pts::AttributeSet::Descriptor& desc, std::size_t index)
{
    for (const auto& [name, i] : desc.map())
        if (i == index) return name;
    return "#" + std::to_string(index);
}

/// @throw FormatError naming @a grid when a leaf would make a handle read outside its arrays:
/// a layout other than the first leaf's, point offsets that decrease, or an array shorter than
/// the leaf's points (the rules strandsFromGrid() reads strands by, VdbStrands.cc).
void checkLeaves(const pts::PointDataGrid& grid, const std::vector<const pts::PointDataTree::LeafNodeType*>& leaves)
{
    const pts::AttributeSet::Descriptor& desc = leaves.front()->attributeSet().descriptor();
    for (const auto* leaf : leaves) {
        const std::string where = "grid '" + grid.getName() + "': the leaf at voxel " + coordText(leaf->origin());
        if (!(leaf->attributeSet().descriptor() == desc))
            throw FormatError(where + " has other attributes than the first leaf; every leaf of a points grid shares one layout");
        openvdb::Index32 previous = 0;
        for (openvdb::Index i = 0; i < pts::PointDataTree::LeafNodeType::SIZE; ++i) {
            const openvdb::Index32 offset = leaf->getValue(i);
            if (offset < previous)
                throw FormatError(where + " has point offset " + std::to_string(offset) + " after " + std::to_string(previous) +
                                  "; a leaf's point offsets never decrease");
            previous = offset;
        }
        for (std::size_t a = 0; a < leaf->attributeSet().size(); ++a) {
            const std::uint64_t length = pointArrayLength(*leaf->attributeSet().getConst(a));
            if (length < previous)
                throw FormatError(where + " has " + std::to_string(previous) + " points but its '" + arrayName(desc, a) + "' array holds " +
                                  std::to_string(length) + "; each array holds one value per point");
        }
    }
}

} // namespace

std::string coordText(const openvdb::Coord& c)
{
    return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) + ")";
}

std::uint64_t pointArrayLength(const openvdb::points::AttributeArray& array)
{
    return array.hasConstantStride() ? std::uint64_t(array.size()) : std::uint64_t(array.dataSize());
}

std::vector<PointColumn> pointColumns(const openvdb::GridBase& base, std::vector<std::string>* skipped)
{
    const auto* points = dynamic_cast<const pts::PointDataGrid*>(&base);
    if (!points) throw TypeError("grid '" + base.getName() + "' holds " + base.valueType() + " voxels, not points");
    const pts::PointDataGrid& grid = *points;
    std::vector<const pts::PointDataTree::LeafNodeType*> leaves;
    for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) leaves.push_back(&*leaf);
    std::vector<PointColumn> out;
    if (leaves.empty()) return out;
    checkLeaves(grid, leaves);
    const std::size_t n = std::size_t(pts::pointCount(grid.tree()));
    const pts::AttributeSet::Descriptor& desc = leaves.front()->attributeSet().descriptor();
    // Uniform arrays hold any number of points in one value: the columns may need far more memory
    // than the grid. At most 3 components of 8 bytes per attribute or group.
    const std::uint64_t columns = desc.size() + desc.groupMap().size();
    checkMemory("grid '" + grid.getName() + "'", std::uint64_t(n) * columns * 24,
                std::to_string(n) + " points x " + std::to_string(columns) + " columns of up to 3 doubles",
                "read the strands instead (vdbhair.read) or fewer points");
    const std::size_t iP = desc.find("P");
    if (iP != pts::AttributeSet::INVALID_POS) {
        PointColumn p{"P", desc.valueType(iP), 3, false, std::vector<double>(3 * n)};
        std::size_t k = 0;
        for (const auto* leaf : leaves) {
            pts::AttributeHandle<openvdb::Vec3f> h(leaf->constAttributeArray(iP));
            for (auto it = leaf->beginIndexOn(); it; ++it, ++k) {
                const openvdb::Vec3d world = grid.transform().indexToWorld(it.getCoord().asVec3d() + h.get(*it));
                for (int c = 0; c < 3; ++c) p.values[3 * k + std::size_t(c)] = world[c];
            }
        }
        out.push_back(std::move(p));
    }
    // The other attributes in the descriptor's order (the group arrays hold the groups below).
    std::vector<std::pair<std::size_t, std::string>> byPosition;
    for (const auto& [name, index] : desc.map()) byPosition.emplace_back(index, name);
    std::sort(byPosition.begin(), byPosition.end());
    for (const auto& [index, name] : byPosition) {
        if (index == iP || desc.type(index) == pts::GroupAttributeArray::attributeType()) continue;
        PointColumn col{name, desc.valueType(index), 1, false, {}};
        const CopyFn copy = copierFor(col.type, col.components, col.integer);
        if (!copy) {
            if (skipped) skipped->push_back(name + " (" + col.type + ")");
            continue;
        }
        col.values.resize(n * col.components);
        copy(leaves, index, col);
        out.push_back(std::move(col));
    }
    for (const auto& [group, offset] : desc.groupMap()) {
        (void)offset;
        PointColumn col{group, "group", 1, true, std::vector<double>(n)};
        std::size_t k = 0;
        for (const auto* leaf : leaves) {
            const pts::GroupHandle h = leaf->groupHandle(group);
            for (auto it = leaf->beginIndexOn(); it; ++it, ++k) col.values[k] = h.get(*it) ? 1.0 : 0.0;
        }
        out.push_back(std::move(col));
    }
    return out;
}

} // namespace vdbhair
