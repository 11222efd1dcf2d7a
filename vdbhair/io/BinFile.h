/// @file BinFile.h
/// @brief CT2Hair's binary strands (`.bin`): like USC-HairSalon `.data` (i32 strand count; per
/// strand an i32 vertex count) but with 7 f32 per vertex: x, y, z and four values CT2Hair uses
/// internally, which vdbhair skips (as hairutil does). Read only.
#pragma once

#include <vdbhair/io/ReadOptions.h>
#include <vdbhair/strands/StrandSet.h>

#include <string>

namespace vdbhair {

/// @throw IoError, FormatError.
StrandSet readBin(const std::string& path, const ReadOptions& opts = {}, ReadReport* report = nullptr);

} // namespace vdbhair
