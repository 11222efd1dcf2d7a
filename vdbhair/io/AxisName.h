/// @file AxisName.h
/// @brief The six unit axes by name (x, y, z, -x, -y, -z), as every option and keyword that names
/// an axis takes them (`convert --up z`, `render --facing -y`).
#pragma once

#include <vdbhair/Types.h>

#include <string>
#include <vector>

namespace vdbhair {

/// @brief The axis names x, y, z, -x, -y, -z, in that order (a string parameter's choices).
const std::vector<std::string>& axisNames();

/// @brief The unit axis named @a name, one of axisNames().
/// @param what how the error names the value (an option such as "--up")
/// @throw ValueError "<what> 'w' is not one of x, y, z, -x, -y, -z".
Vec3d axisFromName(const std::string& name, const std::string& what);

/// @brief The name axisFromName() reads as @a axis (x, y, z, -x, -y, -z).
/// @throw ValueError for a vector that is not a unit axis.
std::string axisName(const Vec3d& axis);

} // namespace vdbhair
