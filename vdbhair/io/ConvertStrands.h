/// @file ConvertStrands.h
/// @brief `vdbhair convert`'s processing: what is done to strands between reading and writing
/// them (scaled, their up axis turned onto +Y, resampled) and how they are written (WriteOptions),
/// declared once (convertParameters(), writeParameters()): the command's options, `--help`,
/// Python's `write()` keywords and docs/cli.md's table are made from the declarations.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/Types.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/StrandSet.h>

#include <cstddef>

namespace vdbhair {

/// @brief How strands are written (writeStrands()), declared once: the PLY encoding, the OBJ line
/// style, the VDB position codec and voxel size, and the USD stage's up axis, metersPerUnit and
/// widths. `convert`'s options and Python's `write()` keywords.
const ParamTable<WriteOptions>& writeParameters();

struct ConvertParams
{
    /// Vertices per strand after resampling, equally spaced in arc length (resampleStrands());
    /// 0 keeps them. 1 is refused: a strand needs two.
    std::size_t resample = 0;
    /// Every position and thickness is multiplied by it (scaleStrands()); finite and not 0.
    double scale = 1.0;
    /// The input's up axis, a unit axis turned onto +Y (rotateUpToY()): +Y is vdbhair's and OBJ's
    /// convention, +Z that of Yuksel's cyHair models.
    Vec3d up{0.0, 1.0, 0.0};
    WriteOptions write;

    /// @throw ValueError naming the parameter (resample, scale), its value and the rule.
    void validate() const;
};

/// @brief convert's parameters declared once: resample, scale, up, then writeParameters(). The
/// inputs, the output, the units and the readers' options stay the command's own.
const ParamTable<ConvertParams>& convertParameters();

/// @brief Rotate @a strands so that the axis @a up (a unit axis, possibly negative) becomes +Y,
/// by a quarter or half turn that keeps the frame right-handed; the strands then declare +Y up.
/// Nothing is done for +Y.
void rotateUpToY(StrandSet& strands, const Vec3d& up);

/// @brief What convert does between reading and writing, in this order: scale (ConvertParams::scale),
/// turn the up axis onto +Y (rotateUpToY()), resample (ConvertParams::resample).
/// @throw ValueError for bad @a params (ConvertParams::validate()).
void convertStrands(StrandSet& strands, const ConvertParams& params);

} // namespace vdbhair
