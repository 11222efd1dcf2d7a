/// @file VdbStrands.h
/// @brief Strands as OpenVDB points (`.vdb`): a PointDataGrid named `strands` that Houdini,
/// Blender and every OpenVDB reader open as points.
///
/// One point per vertex with attributes `P`, int32 `strand` (the strand index) and int32
/// `vertex` (the index along the strand, 0 at the root) — OpenVDB reorders points spatially, so
/// topology is explicit — a group `root` holding each strand's first vertex, and when the set has
/// them `Cd` (vec3f colour), `width` (float thickness) and `Alpha` (float, 1 - transparency),
/// named as Houdini names them. Grid class `unknown`; metadata `creator`, `vdbhair_strand_count`
/// (int64), `vdbhair_position_codec`, and the per-vertex defaults (cyHair's header)
/// `vdbhair_default_thickness`, `vdbhair_default_transparency` (floats) and
/// `vdbhair_default_color` (vec3s), so `.hair -> .vdb -> .hair` keeps them. Keys are valid
/// Houdini attribute names (MetaKeys.h); the older `vdbhair:` keys are read too.
///
/// Reading accepts points made elsewhere: `strand` and `vertex` may be int16, int32, int64,
/// float or double (Houdini writes int64 for `i@strand`, float for a bare `@strand`) as long as
/// they hold whole numbers; the first value that is not one is an error naming it. Without
/// `vdbhair_strand_count`, the strand count is one more than the highest `strand`.
///
/// Position precision: with the default `float` codec (OpenVDB's NullCodec) P is stored as a
/// 32-bit float offset from its voxel's centre, so a position round-trips to within about
/// 2^-24 of the voxel size plus float rounding of the world coordinate (bit-exact in most
/// cases, tested within 1e-6 relative to the bounding box). `fixed16` (FixedPointCodec<false>)
/// stores 16 bits per component, which OpenVDB truncates: each component is off by less than
/// voxel size / 65535; `fixed8` by less than voxel size / 255. The voxel size is chosen for about 8 points per voxel
/// (points::computeVoxelSize) unless given.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace vdbhair {

enum class PositionCodec { Float, Fixed16, Fixed8 };

struct VdbPointsOptions
{
    PositionCodec codec = PositionCodec::Float;
    /// World units; 0 chooses it for about @a pointsPerVoxel points per active voxel.
    double voxelSize = 0.0;
    unsigned pointsPerVoxel = 8;
    /// Extra per-strand int32 attributes, written on every point of the strand (for example
    /// `cluster_level_1` from `vdbhair synth`): a name (letters, digits, `_`; not one of the
    /// attributes written anyway) and #S values.
    std::vector<std::pair<std::string, std::vector<std::int32_t>>> strandAttributes;
};

/// @brief Parse "float", "fixed16" or "fixed8". @throw ValueError otherwise.
PositionCodec positionCodecFromName(const std::string& name);
const char* positionCodecName(PositionCodec codec);

/// @brief Write @a strands as the grid `strands` of a new `.vdb` file (atomically).
/// @throw ValueError (empty set, bad voxel size, an extra attribute of the wrong size or name), IoError.
void writeVdbStrands(const std::string& path, const StrandSet& strands, const VdbPointsOptions& opts = {});

/// @brief Read the grid @a gridName (a PointDataGrid with `strand` and `vertex` attributes).
/// @throw IoError, LookupError (no such grid; the message lists the grids in the file),
/// TypeError (not a points grid), FormatError (missing attributes, inconsistent topology).
StrandSet readVdbStrands(const std::string& path, const ReadOptions& opts = {},
                         ReadReport* report = nullptr, const std::string& gridName = "strands");

} // namespace vdbhair
