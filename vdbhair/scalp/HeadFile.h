/// @file HeadFile.h
/// @brief The head as an obstacle (field/HeadObstacle.h), read from a file: a triangle mesh made
/// into a level set as `vdbhair scalp` makes it, or a level set grid in a .vdb.
#pragma once

#include <vdbhair/field/HeadObstacle.h>

#include <string>

namespace vdbhair {

/// @brief The head in a file: a triangle mesh (.ply, .obj: its level set as `vdbhair scalp`
/// makes it, open boundaries capped) or a .vdb's level set grid (the one named `surface`, else
/// the first level set in the file).
/// @param where prefix for messages, e.g. "head scalp.vdb"
/// @throw IoError, FormatError (unreadable file), LookupError (no level set in it),
/// UnsupportedError (neither a mesh nor a .vdb).
HeadObstacle readHeadObstacle(const std::string& path, const std::string& where,
                              HeadPolicy policy = kDefaultHeadPolicy);

} // namespace vdbhair
