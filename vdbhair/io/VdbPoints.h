/// @file VdbPoints.h
/// @brief Every attribute of every point of an OpenVDB points grid, as columns in the grid's own
/// order (leaf by leaf, voxel by voxel, as Houdini's Convert VDB Points unpacks them): the raw
/// points any tool wrote, for code that rebuilds its own topology (VdbStrands.h reads strands).
#pragma once

#include <openvdb/Grid.h>

#include <cstdint>

#include <string>
#include <vector>

namespace openvdb { OPENVDB_USE_VERSION_NAMESPACE namespace OPENVDB_VERSION_NAME { namespace points { class AttributeArray; } } }

namespace vdbhair {

/// One attribute of every point (or one group's membership).
struct PointColumn
{
    std::string name;          ///< the attribute's name (`P`, `strand`, ...) or a group's
    std::string type;          ///< OpenVDB's value type ("vec3s", "int32", ...), or "group"
    std::size_t components = 1;  ///< 1, or 3 for vectors
    bool integer = false;      ///< whole-number type (or a group: 0 or 1)
    std::vector<double> values;  ///< #points x components, exact for every value of these types
};

/// @brief Columns of @a grid: `P` as world positions (the voxel's index plus the stored offset,
/// through the grid's transform), then every other attribute of a numeric type (int16, int32,
/// int64, float, double, bool, uint8 and their 3-vectors) and every group, in the descriptor's
/// order. Attributes of other types (strings) are listed in @a skipped. (A GridBase, so that code
/// outside the library, such as the Python module, instantiates none of OpenVDB's point templates.)
/// @throw TypeError when @a grid is not a points grid, naming it and what it holds.
std::vector<PointColumn> pointColumns(const openvdb::GridBase& grid, std::vector<std::string>* skipped = nullptr);

/// @brief The points an AttributeHandle on @a array may index: its size, or for an array of
/// varying stride its total size (as the handle counts). A file states both apart from the leaf's
/// point offsets: a leaf whose last offset exceeds this for any array it reads is refused, else a
/// handle reads past the array (OpenVDB checks only with assertions).
std::uint64_t pointArrayLength(const openvdb::points::AttributeArray& array);

/// @brief A voxel as error messages name it: "(x, y, z)".
std::string coordText(const openvdb::Coord& c);

} // namespace vdbhair
