#include "Xform.h"

#include <algorithm>
#include <cmath>

namespace vdbhair {
namespace xform {

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

Matrix multiply(const Matrix& a, const Matrix& b)
{
    Matrix c{};
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k)
            for (int j = 0; j < 4; ++j) c[4 * r + j] += a[4 * r + k] * b[4 * k + j];
    return c;
}

bool invert(const Matrix& m, Matrix& out)
{
    // Gauss-Jordan elimination with partial pivoting on [m | I].
    double a[4][8];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 8; ++c) a[r][c] = c < 4 ? m[4 * r + c] : (c - 4 == r ? 1.0 : 0.0);
    for (int c = 0; c < 4; ++c) {
        int pivot = c;
        for (int r = c + 1; r < 4; ++r) if (std::abs(a[r][c]) > std::abs(a[pivot][c])) pivot = r;
        if (!(std::abs(a[pivot][c]) > 1e-300)) return false;
        if (pivot != c) for (int k = 0; k < 8; ++k) std::swap(a[c][k], a[pivot][k]);
        const double inv = 1.0 / a[c][c];
        for (int k = 0; k < 8; ++k) a[c][k] *= inv;
        for (int r = 0; r < 4; ++r) {
            if (r == c || a[r][c] == 0.0) continue;
            const double f = a[r][c];
            for (int k = 0; k < 8; ++k) a[r][k] -= f * a[c][k];
        }
    }
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out[4 * r + c] = a[r][c + 4];
    return true;
}

double lengthScale(const Matrix& m)
{
    const double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) + m[2] * (m[4] * m[9] - m[5] * m[8]);
    return std::cbrt(std::abs(det));
}

std::string composeAbcOps(const std::vector<std::uint8_t>& ops, const std::vector<double>& vals, Matrix& out)
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

std::string usdOp(const std::string& type, const std::vector<double>& v, Matrix& out)
{
    auto need = [&](std::size_t n) {
        return v.size() == n ? std::string() : type + " needs " + std::to_string(n) + " number(s), got " + std::to_string(v.size());
    };
    Matrix o = kIdentity;
    if (type == "translate" || type == "scale") {
        if (std::string e = need(3); !e.empty()) return e;
        if (type == "translate") { o[12] = v[0]; o[13] = v[1]; o[14] = v[2]; }
        else { o[0] = v[0]; o[5] = v[1]; o[10] = v[2]; }
    } else if (type == "rotateX" || type == "rotateY" || type == "rotateZ") {
        if (std::string e = need(1); !e.empty()) return e;
        o = axisAngle(type[6] == 'X', type[6] == 'Y', type[6] == 'Z', v[0]);
    } else if (type.size() == 9 && type.compare(0, 6, "rotate") == 0) {
        // rotateXYZ ... rotateZYX: (angle about X, about Y, about Z), the first letter applied first.
        const std::string order = type.substr(6);
        std::string sorted = order;
        std::sort(sorted.begin(), sorted.end());
        if (sorted != "XYZ") return "unknown xformOp type '" + type + "'";
        if (std::string e = need(3); !e.empty()) return e;
        for (char axis : order) {
            const int i = axis - 'X';
            o = multiply(o, axisAngle(i == 0, i == 1, i == 2, v[std::size_t(i)]));
        }
    } else if (type == "orient") {
        if (std::string e = need(4); !e.empty()) return e;
        const double w = v[0], len = std::sqrt(v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
        if (len > 0.0) o = axisAngle(v[1], v[2], v[3], 2.0 * std::atan2(len, w) * 180.0 / 3.14159265358979323846);
    } else if (type == "transform") {
        if (std::string e = need(16); !e.empty()) return e;
        std::copy(v.begin(), v.end(), o.begin());
    } else {
        return "unknown xformOp type '" + type + "' (translate, scale, rotateX, rotateXYZ, orient, transform, ...)";
    }
    for (double x : o) {
        if (!std::isfinite(x)) return type + " has a value that is not finite";
    }
    out = o;
    return {};
}

Vec3f transformPoint(const Matrix& m, const Vec3f& p)
{
    const double x = p.x(), y = p.y(), z = p.z();
    const double w = x * m[3] + y * m[7] + z * m[11] + m[15];
    return Vec3f(float((x * m[0] + y * m[4] + z * m[8] + m[12]) / w), float((x * m[1] + y * m[5] + z * m[9] + m[13]) / w),
                 float((x * m[2] + y * m[6] + z * m[10] + m[14]) / w));
}

} // namespace xform
} // namespace vdbhair
