#include <vdbhair/io/AxisName.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>

namespace vdbhair {

const std::vector<std::string>& axisNames()
{
    static const std::vector<std::string> names{"x", "y", "z", "-x", "-y", "-z"};
    return names;
}

Vec3d axisFromName(const std::string& name, const std::string& what)
{
    const std::string axis = name.size() == 2 && name[0] == '-' ? name.substr(1) : name;
    const double sign = name.size() == 2 && name[0] == '-' ? -1.0 : 1.0;
    if (axis == "x") return Vec3d(sign, 0.0, 0.0);
    if (axis == "y") return Vec3d(0.0, sign, 0.0);
    if (axis == "z") return Vec3d(0.0, 0.0, sign);
    throw ValueError(what + " '" + name + "' is not one of x, y, z, -x, -y, -z");
}

std::string axisName(const Vec3d& axis)
{
    for (const std::string& name : axisNames()) {
        if (axisFromName(name, "axis") == axis) return name;
    }
    throw ValueError("axis (" + formatNumber(axis.x()) + ", " + formatNumber(axis.y()) + ", " + formatNumber(axis.z()) +
                     ") is not one of x, y, z, -x, -y, -z");
}

} // namespace vdbhair
