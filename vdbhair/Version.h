/// @file Version.h
/// @brief The toolkit's version, written into every file vdbhair creates (`creator` metadata).
#pragma once

#define VDBHAIR_VERSION_STRING "0.1.0"

namespace vdbhair {
/// @return "vdbhair 0.1.0", the value of the `creator` metadata of every grid written.
inline const char* creatorString() { return "vdbhair " VDBHAIR_VERSION_STRING; }
} // namespace vdbhair
