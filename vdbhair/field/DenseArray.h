/// @file DenseArray.h
/// @brief Grids as dense float32 arrays, the form learning code loads: an exact copy of an index
/// box (Python's `Grid.to_dense`) and the orientation volume of a tangent field resampled over a
/// world box (`vdbhair field --dense`, Python's `TangentField.orientation_volume`).
///
/// Layout, for both: C order with x varying fastest, so a volume of W x H x D samples (along x, y,
/// z) is an array of shape (D, H, W) for scalar grids and (D, H, W, C) with C channels per
/// sample: `array[k][j][i][c]` is sample (i, j, k). This is NumPy's default order and what
/// orientation-volume networks read (NeuralHDHair: 96 x 128 x 128 x 3; Zhang et al.'s
/// HairNet-style volumes alike).
#pragma once

#include <openvdb/openvdb.h>

#include <array>
#include <cstddef>
#include <vector>

namespace vdbhair {

/// @brief A box in world space sampled at W x H x D points: sample (i, j, k) sits at the centre of
/// cell (i, j, k) when the box is cut into W x H x D equal cells, at
/// `worldMin + ((i, j, k) + 0.5) * (worldMax - worldMin) / (W, H, D)`.
struct DenseBox
{
    openvdb::Vec3d worldMin{0.0}, worldMax{1.0};
    openvdb::Coord size{1};  ///< samples along x, y, z (W, H, D); each at least 1
};

/// @brief The default samples of an orientation volume, (D, H, W) along z, y, x: NeuralHDHair's
/// 96 x 128 x 128 (`field --dense-size`, Python's TangentField.orientation_volume(shape=)).
inline constexpr std::array<int, 3> kDefaultDenseShape{96, 128, 128};

/// @brief The number of samples of @a box (W * H * D).
std::size_t denseSampleCount(const DenseBox& box);

/// @brief Copy @a grid's values over the inclusive index box @a indexBox into @a out, exactly
/// (OpenVDB's tools::copyToDense). Inactive voxels give the background.
/// @param out #D*H*W*3 floats for a Vec3SGrid, #D*H*W for a FloatGrid, W = indexBox.dim().x()
/// and so on; every one is written.
/// @throw ValueError if @a indexBox is empty.
void copyToDenseArray(const openvdb::Vec3SGrid& grid, const openvdb::CoordBBox& indexBox, float* out, bool threaded = true);
void copyToDenseArray(const openvdb::FloatGrid& grid, const openvdb::CoordBBox& indexBox, float* out, bool threaded = true);

/// @brief The orientation volume of a tangent field over @a box: 4 channels per sample,
/// (tx, ty, tz, occupancy).
///
/// Occupancy is the trilinear interpolation of the field's active mask (1 at voxels hair passed
/// through, 0 elsewhere): 1 inside the hair volume, 0 outside it, in between within a voxel of its
/// boundary. The direction is the trilinear interpolation of the active voxels' tangents,
/// normalized: a unit vector (root to tip) wherever occupancy is above 0 and the interpolated
/// tangents do not cancel, zero otherwise. Sample positions are mapped to index space through the
/// grid's transform, so any linear transform (world-space fields) works.
/// @param tangent unit directions, inactive where no hair passed (TangentField::tangent)
/// @return #D*H*W*4 floats in the layout above.
/// @throw ValueError if a size is below 1, a box extent is not positive, or a coordinate is not finite.
std::vector<float> orientationVolume(const openvdb::Vec3SGrid& tangent, const DenseBox& box, bool threaded = true);

} // namespace vdbhair
