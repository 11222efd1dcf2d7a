/// @file ScalpJson.h
/// @brief The reports of scalp and roots: what `--json` prints and what Python returns, one
/// report whichever front end ran the verb (as SynthJson.h is synth's). The front ends add only
/// what is theirs: the command line its file names and the seconds, Python its arrays.
#pragma once

#include <vdbhair/scalp/Follicles.h>
#include <vdbhair/scalp/ScalpInput.h>

#include <openvdb/openvdb.h>

#include <nlohmann/json.hpp>

#include <string>

namespace vdbhair {

/// How scalp's hair region was painted, as its report says.
struct ScalpRegionSource
{
    enum class Kind { Roots, Vertex, Mask };
    Kind kind = Kind::Roots;
    std::size_t roots = 0;   ///< Roots: the roots given
    double radius = 0.0;     ///< Roots: the band about their projections onto the surface, world units
    std::string name;        ///< Vertex: the PLY vertex property; Mask: the mask grid's name
    double threshold = 0.0;  ///< Vertex, Mask: the value above which the region is
};

/// @brief scalp's report: the kind of source ("sphere" without @a file, else the file's "mesh"
/// or "points"), the level set's voxel size, half width (voxels) and active voxels, the area roots
/// can grow on and the band without a surface (@a areas, measureScalpArea()), the mesh's repairs
/// or the points used (@a file), and with @a region how it was painted (@a source) and its voxels.
nlohmann::json scalpReport(const openvdb::FloatGrid& surface, double halfWidth, const ScalpArea& areas, const ScalpFileReport* file,
                           const openvdb::BoolGrid* region, const ScalpRegionSource& source);

/// @brief roots's report: how many follicles sampleFollicles() placed and how (area, target
/// spacing, iterations, births and deaths), whether a region confined them, and their spacing
/// and distance to the surface (measureFollicles()).
/// @param region whether a region confined the follicles
nlohmann::json rootsReport(const Follicles& f, const FollicleStats& stats, bool region);

} // namespace vdbhair
