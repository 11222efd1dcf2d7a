/// @file FastMath.h
/// @brief Inline sin/cos and atan2 for helicoid tracing, which evaluates them at every step.
/// The polynomials are fdlibm's kernels (k_sin.c, k_cos.c) and Cephes' atan (atan.c); with
/// Cody–Waite reduction by π/2 they agree with the C library to about 1e-15 for the angles a
/// trace meets (|x| < 1e5; tested). Inlined and branch-light, they are several times cheaper than
/// the library calls, which dominated tracing.
#pragma once

#include <cmath>

namespace vdbhair {
namespace fastmath {

/// Round to the nearest integer (halves away from zero) for |x| < 2^62, without a library call
/// (std::nearbyint is one unless the target has SSE4.1).
inline long long roundToInt(double x) { return static_cast<long long>(x + (x >= 0.0 ? 0.5 : -0.5)); }

/// @name The polynomial kernels (fdlibm k_sin.c / k_cos.c on |r| <= π/4, z = r²; Cephes atan.c on
/// |a| <= 0.66), shared by the branchy and the branchless forms below.
/// @{
inline double sinKernel(double r, double z)
{
    return r + r * z * (-1.66666666666666324348e-01 + z * (8.33333333332248946124e-03 + z * (-1.98412698298579493134e-04 +
                        z * (2.75573137070700676789e-06 + z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)))));
}
inline double cosKernel(double z)
{
    return 1.0 - 0.5 * z + z * z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03 + z * (2.48015872894767294178e-05 +
                                   z * (-2.75573143513906633035e-07 + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)))));
}
inline double atanKernel(double a)
{
    const double z = a * a;
    const double p = (((-8.750608600031904122785e-01 * z - 1.615753718733365076637e+01) * z - 7.500855792314704667340e+01) * z -
                      1.228866684490136173410e+02) * z - 6.485021904942025371773e+01;
    const double q = ((((z + 2.485846490142306297962e+01) * z + 1.650270098316988542046e+02) * z + 4.328810604912902668951e+02) * z +
                      4.853903996359136964868e+02) * z + 1.945506571482613964425e+02;
    return a + a * z * p / q;
}
/// @}

/// sin and cos of @a x (|x| < 1e5; larger arguments fall back to the library).
inline void sinCos(double x, double& s, double& c)
{
    if (!(std::abs(x) < 1e5)) {
        s = std::sin(x);
        c = std::cos(x);
        return;
    }
    constexpr double invPio2 = 6.36619772367581382433e-01;
    constexpr double pio2a = 1.57079632673412561417e+00, pio2b = 6.07710050650619224932e-11;
    const long long q = roundToInt(x * invPio2);
    const double n = double(q);
    const double r = (x - n * pio2a) - n * pio2b;
    const double z = r * r;
    const double sr = sinKernel(r, z), cr = cosKernel(z);
    switch (int(q & 3)) {
    case 0: s = sr; c = cr; break;
    case 1: s = cr; c = -sr; break;
    case 2: s = -sr; c = -cr; break;
    default: s = -cr; c = sr; break;
    }
}

/// atan of @a x (Cephes: reduction to |x| <= 0.66 and a 4/5 rational approximation).
inline double atan(double x)
{
    const double sign = x < 0.0 ? -1.0 : 1.0;
    double a = std::abs(x), y = 0.0, extra = 0.0;
    constexpr double moreBits = 6.123233995736765886130e-17;
    if (a > 2.41421356237309504880) {
        y = M_PI_2;
        extra = moreBits;
        a = -1.0 / a;
    } else if (a > 0.66) {
        y = M_PI_4;
        extra = 0.5 * moreBits;
        a = (a - 1.0) / (a + 1.0);
    }
    return sign * (y + atanKernel(a) + extra);
}

/// atan2(y, x), the library's quadrant conventions for finite arguments.
inline double atan2(double y, double x)
{
    if (x > 0.0) return fastmath::atan(y / x);
    if (x < 0.0) return (y >= 0.0 ? M_PI : -M_PI) + fastmath::atan(y / x);
    if (y > 0.0) return M_PI_2;
    if (y < 0.0) return -M_PI_2;
    return 0.0;
}

/// @name Branchless forms of the same functions, for loops over independent lanes that the
/// compiler turns into vector code (every branch above becomes a select). Same polynomials and
/// accuracy; arguments as above (|x| < 2^31 · π/2 for sinCosLane).
/// @{

/// x rounded to an integer (halves to even) for |x| < 2^51: the float-add trick, no branch.
inline double roundLane(double x)
{
    constexpr double magic = 6755399441055744.0;  // 1.5 · 2^52
    return (x + magic) - magic;
}

inline void sinCosLane(double x, double& s, double& c)
{
    constexpr double invPio2 = 6.36619772367581382433e-01;
    constexpr double pio2a = 1.57079632673412561417e+00, pio2b = 6.07710050650619224932e-11;
    const double n = roundLane(x * invPio2);
    const double r = (x - n * pio2a) - n * pio2b;
    const double z = r * r;
    const double sr = sinKernel(r, z), cr = cosKernel(z);
    // The quadrant n mod 4 as m = n - 4 round(n / 4) in {-2, -1, 0, 1, 2} (±2 both mean 2:
    // round(n / 4) takes either way at the halves), i.e. quadrants 2, 3, 0, 1, 2.
    const double m = n - 4.0 * roundLane(0.25 * n);
    const bool odd = m * m == 1.0, flip = m < -0.5 || m > 1.5;
    const double s1 = odd ? cr : sr, c1 = odd ? -sr : cr;
    s = flip ? -s1 : s1;
    c = flip ? -c1 : c1;
}

inline double atan2Lane(double y, double x)
{
    constexpr double moreBits = 6.123233995736765886130e-17;
    const double ax = std::abs(x), ay = std::abs(y);
    const bool swap = ay > ax;
    const double hi = swap ? ay : ax, lo = swap ? ax : ay;
    // Every arithmetic result is computed whether it is used or not, then selected: under the
    // default -ftrapping-math an operation under a condition stays a branch (it could trap),
    // which keeps the loop scalar.
    const double t = lo / (hi > 0.0 ? hi : 1.0);  // in [0, 1]; 0 when both are 0
    // Cephes' reduction: above tan(π/8), atan t = π/4 + atan((t - 1) / (t + 1)).
    const bool red = t > 0.41421356237309504880;
    const double reduced = (t - 1.0) / (t + 1.0);
    const double a = red ? reduced : t;
    const double base = red ? M_PI_4 : 0.0, extra = red ? 0.5 * moreBits : 0.0;
    const double r0 = base + atanKernel(a) + extra;  // atan t, in [0, π/4]
    const double r0c = (M_PI_2 - r0) + moreBits;
    const double r1 = swap ? r0c : r0;                     // atan(ay / ax) in [0, π/2]
    const double r1c = (M_PI - r1) + 2.0 * moreBits;
    const double r2 = x < 0.0 ? r1c : r1;                  // the left half-plane
    return y < 0.0 ? -r2 : r2;
}
/// @}

} // namespace fastmath
} // namespace vdbhair
