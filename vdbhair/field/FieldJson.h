/// @file FieldJson.h
/// @brief The reports of field and retrace: what `--json` prints and what Python's report
/// returns, one report whichever front end ran the verb (as RefineJson.h is refine's). The front
/// ends add only what is theirs: the command line its file names and the seconds.
#pragma once

#include <vdbhair/field/DenseArray.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentAngles.h>
#include <vdbhair/field/TangentField.h>

#include <openvdb/openvdb.h>

#include <nlohmann/json.hpp>

#include <optional>
#include <vector>

namespace vdbhair {

/// @brief field's report: strands, voxel size, iterations, levels and space of the estimate
/// (@a fp as it ran, its voxel size resolved), each of @a grids (name, voxel size, active
/// voxels), and in scalp space the sphere and, over a measured scalp, its table (resolution,
/// distance range in radii, rays that missed it).
/// @param grids the voxel grids written (each level's tangent, density and hair length, and any
/// grid fitted to them), in file order
nlohmann::json fieldReport(std::size_t strands, const FieldParams& fp, int levels, const openvdb::GridCPtrVec& grids);

/// @brief The orientation volume's report (orientationVolume()): its shape (D, H, W, 4), the
/// samples with hair (occupancy above 0) and the world box (x0, y0, z0, x1, y1, z1).
nlohmann::json denseReport(const DenseBox& box, const std::vector<float>& volume);

/// @brief retrace's report (retraceStrands()): strands, how many were traced to their full
/// length and why the others stopped, integration steps taken, the mean vertex displacement,
/// the step length and integrator, and with @a angles the mean angle between strand tangents and
/// the field before and after (null where no vertex lay inside the field).
/// @param step the step length used (resolveStep()), world units
nlohmann::json retraceReport(const TraceStats& s, const TraceParams& tp, double step, double displacement,
                             const std::optional<TangentAngles>& angles);

} // namespace vdbhair
