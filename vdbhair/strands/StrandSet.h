/// @file StrandSet.h
/// @brief A hairstyle as flat arrays: every strand is a polyline from root to tip.
#pragma once

#include <vdbhair/Types.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace vdbhair {

/// @brief Per-vertex attribute defaults, used where a per-vertex array is absent
/// (the cyHair header's defaults).
struct StrandDefaults
{
    float thickness = 1.f;      ///< world units
    float transparency = 0.f;   ///< 0 = opaque
    Vec3f color{0.5f, 0.5f, 0.5f};  ///< linear RGB in [0,1]
};

/// @brief A set of strands in structure-of-arrays layout (docs/formats.md).
///
/// Strand i is the vertex range `[offsets[i], offsets[i+1])` of `positions`, root first.
/// Optional arrays are empty when absent, otherwise they have one entry per vertex
/// (`thickness`, `transparency`, `color`) or per strand (`rootUV`, `strandId`).
/// Readers guarantee: finite positions, at least two vertices per strand, every present
/// optional array of the right size (validate() checks it).
struct StrandSet
{
    std::vector<Vec3f> positions;           ///< #V world positions
    std::vector<std::uint32_t> offsets{0};  ///< #S+1 prefix sums into positions

    std::vector<float> thickness;     ///< #V or empty
    std::vector<float> transparency;  ///< #V or empty
    std::vector<Vec3f> color;         ///< #V or empty, linear RGB in [0,1]
    std::vector<Vec2f> rootUV;        ///< #S or empty
    std::vector<std::int32_t> strandId;  ///< #S or empty (ids of an upstream source)
    StrandDefaults defaults;
    /// The unit the source file declared (USD's `metersPerUnit`), 0 when it declared none: carried
    /// so that a writer with a unit (USD) keeps it; nothing is scaled by it except convertUnits().
    double metersPerUnit = 0.0;
    /// The up axis the source declared or the data was turned to: 'Y', 'Z', or 0 when unknown
    /// (USD's `upAxis`; `convert --up` makes it 'Y'); OBJ's header comment says it.
    char upAxis = 0;

    std::size_t numStrands() const { return offsets.empty() ? 0 : offsets.size() - 1; }
    std::size_t numVertices() const { return positions.size(); }
    bool empty() const { return numStrands() == 0; }

    std::size_t begin(std::size_t strand) const { return offsets[strand]; }
    std::size_t end(std::size_t strand) const { return offsets[strand + 1]; }
    std::size_t size(std::size_t strand) const { return offsets[strand + 1] - offsets[strand]; }
    const Vec3f* data(std::size_t strand) const { return positions.data() + offsets[strand]; }
    Vec3f* data(std::size_t strand) { return positions.data() + offsets[strand]; }
    const Vec3f& root(std::size_t strand) const { return positions[offsets[strand]]; }
    const Vec3f& tip(std::size_t strand) const { return positions[offsets[strand + 1] - 1]; }

    /// @brief Append a strand of @a count positions (attributes of the new vertices take the
    /// defaults where the set has per-vertex arrays).
    /// @throw ValueError if the vertex count would overflow 32-bit offsets.
    void addStrand(const Vec3f* points, std::size_t count);
    void addStrand(const std::vector<Vec3f>& points) { addStrand(points.data(), points.size()); }

    /// @brief Remove every strand and attribute (defaults stay).
    void clear();

    /// @brief Reserve storage for @a strands strands and @a vertices vertices.
    void reserve(std::size_t strands, std::size_t vertices);

    /// @brief Check the invariants above.
    /// @param where prefix for the message, e.g. "readHair(a.hair)"
    /// @throw FormatError naming the first broken rule.
    void validate(const std::string& where) const;

    /// @brief Append all strands of @a other (attribute arrays are filled with defaults
    /// where only one side has them).
    void append(const StrandSet& other);
    /// @brief As above; into an empty set, @a other's storage is taken instead of copied (the
    /// same result: reading one file into a set no longer copies it).
    void append(StrandSet&& other);

    /// Per-vertex attribute values with defaults applied.
    float thicknessAt(std::size_t v) const { return thickness.empty() ? defaults.thickness : thickness[v]; }
    float transparencyAt(std::size_t v) const { return transparency.empty() ? defaults.transparency : transparency[v]; }
    Vec3f colorAt(std::size_t v) const { return color.empty() ? defaults.color : color[v]; }
};

/// @brief Axis-aligned bounding box of every vertex.
BBox computeBBox(const StrandSet& strands);

/// @brief Keep only the strands with `keep[i] != 0`, with their attributes.
/// @param keep #S flags
StrandSet selectStrands(const StrandSet& strands, const std::vector<char>& keep);

/// @brief Scale every position by @a factor about the origin (thickness scales too).
void scaleStrands(StrandSet& strands, float factor);

/// @brief A unit's length in metres from its name: "mm", "cm", "dm", "m", "in", or a positive
/// number of metres ("0.01"). Throws ValueError naming @a what (e.g. "--units") and the choices.
double metersPerUnitFromName(const std::string& text, const std::string& what);

/// @brief Express @a strands in the unit of @a metersPerUnit: positions and thickness scaled by
/// their declared unit over it (StrandSet::metersPerUnit), which becomes @a metersPerUnit.
/// Throws ValueError when the strands declare no unit (give it first: set metersPerUnit).
void convertUnits(StrandSet& strands, double metersPerUnit);

} // namespace vdbhair
