#include "AbcXform.h"

#include <algorithm>
#include <cmath>

namespace vdbhair {
namespace abc {

namespace {

/// Imath's Matrix44::setAxisAngle: rotation by @a degrees about @a axis (row-vector form).
Matrix axisAngle(double x, double y, double z, double degrees)
{
    const double len = std::sqrt(x * x + y * y + z * z);
    if (len > 0) { x /= len; y /= len; z /= len; }
    const double a = degrees * 3.14159265358979323846 / 180.0, c = std::cos(a), s = std::sin(a), t = 1 - c;
    return Matrix{t * x * x + c,     t * x * y + s * z, t * x * z - s * y, 0,
                  t * x * y - s * z, t * y * y + c,     t * y * z + s * x, 0,
                  t * x * z + s * y, t * y * z - s * x, t * z * z + c,     0,
                  0, 0, 0, 1};
}

} // namespace

Matrix multiply(const Matrix& a, const Matrix& b)
{
    Matrix c{};
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k)
            for (int j = 0; j < 4; ++j) c[4 * r + j] += a[4 * r + k] * b[4 * k + j];
    return c;
}

std::string composeXformOps(const std::vector<std::uint8_t>& ops, const std::vector<double>& vals, Matrix& out)
{
    Matrix m = kIdentity;
    std::size_t at = 0;
    for (std::uint8_t op : ops) {
        const unsigned type = op >> 4;
        if (type > 6) return ".ops: operation type " + std::to_string(type) + "; types are 0-6";
        const std::size_t channels = type == 3 ? 16 : type == 2 ? 4 : type >= 4 ? 1 : 3;
        if (at + channels > vals.size()) {
            return "the operations need more than the " + std::to_string(vals.size()) + " values of .vals";
        }
        const double* v = vals.data() + at;
        at += channels;
        Matrix o = kIdentity;
        if (type == 0) { o[0] = v[0]; o[5] = v[1]; o[10] = v[2]; }         // scale
        else if (type == 1) { o[12] = v[0]; o[13] = v[1]; o[14] = v[2]; }  // translate
        else if (type == 2) o = axisAngle(v[0], v[1], v[2], v[3]);          // rotate about an axis
        else if (type == 3) std::copy(v, v + 16, o.begin());               // matrix
        else o = axisAngle(type == 4, type == 5, type == 6, v[0]);          // rotate X, Y, Z
        m = multiply(o, m);
    }
    for (double x : m) {
        if (!std::isfinite(x)) return "a transform value is not finite";
    }
    out = m;
    return {};
}

Vec3f transformPoint(const Matrix& m, const Vec3f& p)
{
    const double x = p.x(), y = p.y(), z = p.z();
    const double w = x * m[3] + y * m[7] + z * m[11] + m[15];
    return Vec3f(float((x * m[0] + y * m[4] + z * m[8] + m[12]) / w), float((x * m[1] + y * m[5] + z * m[9] + m[13]) / w),
                 float((x * m[2] + y * m[6] + z * m[10] + m[14]) / w));
}

} // namespace abc
} // namespace vdbhair
