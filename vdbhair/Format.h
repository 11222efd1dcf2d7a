/// @file Format.h
/// @brief Numbers in library messages: "%g" (six significant digits, no trailing zeros), so an
/// error reads "voxel size 0.25", not "0.250000".
#pragma once

#include <cstdio>
#include <string>

namespace vdbhair {

inline std::string formatNumber(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

} // namespace vdbhair
