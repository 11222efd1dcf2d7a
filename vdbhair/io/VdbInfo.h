/// @file VdbInfo.h
/// @brief What is in a `.vdb` file, grid by grid — including point attributes and groups, which
/// `vdb_print` does not show. Used by `vdbhair info` (and `inspect`).
#pragma once

#include <vdbhair/Types.h>

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace vdbhair {

/// @brief One metadata entry; vectors and matrices are flattened to numbers.
struct MetaValue
{
    std::string name;
    std::string typeName;  ///< OpenVDB's type name ("string", "int64", "vec3s", ...)
    std::variant<bool, std::int64_t, double, std::string, std::vector<double>> value;
};

struct PointAttributeInfo
{
    std::string name, valueType, codec;
};

struct GridInfo
{
    std::string name;
    std::string type;        ///< e.g. "Tree_vec3s_5_4_3"
    std::string valueType;   ///< e.g. "vec3s", "float", "ptdataidx"
    std::string gridClass;   ///< "unknown", "level set", "fog volume", "staggered"
    std::string vectorType;  ///< "invariant", "covariant", ... ("" for scalar grids)
    Vec3d voxelSize{0.0};    ///< world units per axis
    bool linear = true;      ///< whether the transform is linear (affine)
    std::uint64_t activeVoxels = 0;
    std::uint64_t activeTiles = 0;
    std::uint64_t leafNodes = 0;
    std::uint64_t memoryBytes = 0;
    bool emptyBBox = true;
    Vec3d bboxMin{0.0}, bboxMax{0.0};  ///< world bounds of the active voxels (voxel extents)
    std::vector<MetaValue> metadata;
    // Point grids only
    bool isPoints = false;
    std::uint64_t pointCount = 0;
    std::vector<PointAttributeInfo> attributes;
    std::vector<std::string> groups;
};

/// @brief Describe every grid of @a path, in file order.
/// @throw IoError, FormatError.
/// @param where message prefix; empty: "info(PATH)"
std::vector<GridInfo> describeVdbFile(const std::string& path, const std::string& where = "");

/// @brief A metadata value as text ("0.5", "[1, 2, 3]", "vdbhair 0.1.0"). Text longer than
/// @a maxChars (0: no limit) is cut to its start and "... (N characters)", for listings (a
/// scalp-space field's vdbhair_scalp_distance is about 40,000 characters).
std::string metaValueString(const MetaValue& m, std::size_t maxChars = 0);
/// @brief The text length `info` and `inspect` list metadata values at.
constexpr std::size_t kListedMetaChars = 120;

} // namespace vdbhair
