/// @file FieldTypes.h
/// @brief Parameters and names shared by the field modules (docs/fields.md).
#pragma once

#include <vdbhair/field/ScalpSpace.h>

#include <cstdint>
#include <string>

namespace vdbhair {

/// @brief Where a field's grid lives. World space (the default) is a plain linear transform of
/// voxel size h and handles every hairstyle; scalp space (Wang et al. 2009, §3) is a grid over
/// (u, v, w) of a spherical scalp, for comparison and for hair that stays over the scalp.
enum class FieldSpace { World, Scalp };

const char* fieldSpaceName(FieldSpace space);
/// @throw ValueError unless "world" or "scalp".
FieldSpace fieldSpaceFromName(const std::string& name);

/// @brief Grid names (docs/fields.md): `tangent` / `density` / `hair_length` for one level,
/// `tangent_level_<l>` / `density_level_<l>` / `hair_length_level_<l>` for multi-level fields
/// (level 0 the finest).
std::string tangentGridName(int level, int levels);
std::string densityGridName(int level, int levels);
/// `coherence` / `coherence_level_<l>` and `spread` / `spread_level_<l>` (TangentField.h).
std::string coherenceGridName(int level, int levels);
std::string spreadGridName(int level, int levels);
std::string hairLengthGridName(int level, int levels);

} // namespace vdbhair
