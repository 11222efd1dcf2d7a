/// @file Helicoid.h
/// @brief The generalized helicoid of Piuze, Kry & Siddiqi 2011 (§3): a parameter vector
/// k = (kT, kN, kB, alpha) with a frame Q and an origin p0 describes an orientation field around
/// p0; hair strands are its streamlines (Eq. 3), p-helicoids chain pieces (§3.4).
///
/// At a world point x, in the local coordinates y = Qᵀ (x - p0) (Q's columns are the world
/// directions of the local x, y, z axes: E_T, E_N, E_B at the origin),
///   theta = atan2(kT y1 + kN y2, 1 + kN y1 - kT y2) + kB y3,    phi = alpha · theta    (Eq. 1)
/// and the frame is (Eq. 2, mapped to world space by Q)
///   E_T = (cos phi cos theta, cos phi sin theta, sin phi),  E_N = (-sin theta, cos theta, 0),
///   E_B = (-sin phi cos theta, -sin phi sin theta, cos phi).
/// theta is **unwrapped along a trace**: atan2 jumps by 2π when a streamline circles the axis,
/// and the multiple of 2π that keeps theta closest to its previous value is added (the paper's
/// "counting the 2π cycles theta completes"), so phi stays continuous through full turns.
///
/// Analytic cases (tested): k = 0 traces a straight line; k = (kT, 0, 0, 0) traces the circle of
/// radius 1/kT about p0 + E_N/kT in the E_T–E_N plane; k = (0, kN, 0, 0) gives straight
/// streamlines fanning out from p0 - E_T/kN.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/helicoid/FastMath.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace vdbhair {

/// @brief k = (kT, kN, kB, alpha): curvatures in 1 / world units, alpha dimensionless.
struct HelicoidParams
{
    double kT = 0.0, kN = 0.0, kB = 0.0, alpha = 0.0;
};

/// @brief An orthonormal right-handed frame in double precision: Q = [t n b].
struct FrameD
{
    Vec3d t{1.0, 0.0, 0.0}, n{0.0, 1.0, 0.0}, b{0.0, 0.0, 1.0};

    /// @brief The frame with tangent @a t and the part of @a n orthogonal to it.
    /// @throw ValueError if @a t is zero or @a n is parallel to it.
    static FrameD fromTangentNormal(const Vec3d& t, const Vec3d& n);
    /// @brief This frame rolled by @a angle (radians) about t: n' = cos·n + sin·b.
    FrameD rolled(double angle) const;
    /// @brief This frame rotated by π about n (t and b flip; the kT sign symmetry of §4.1).
    FrameD flippedAboutNormal() const { return FrameD{-t, n, -b}; }
};

/// @brief One generalized helicoid: parameters, frame and origin.
struct Helicoid
{
    HelicoidParams k;
    FrameD q;
    Vec3d p0{0.0};

    /// @brief theta at @a world, unwrapped to the value closest to @a thetaRef.
    double theta(const Vec3d& world, double thetaRef) const;

    /// @brief The world frame (E_T, E_N, E_B) for a given (unwrapped) theta.
    FrameD frameFromTheta(double theta) const;

    /// @brief Unit tangent E_T at @a world; updates @a thetaRef to the unwrapped theta there.
    Vec3d tangent(const Vec3d& world, double& thetaRef) const;
    /// @brief tangent() through the branchless forms of FastMath.h (the same polynomials; theta
    /// unwrapped to even at exact halves): for the fit's pre-fit, whose traces call it millions
    /// of times and whose branches would follow the data.
    Vec3d tangentLane(const Vec3d& world, double& thetaRef) const;

    /// @brief Distance (world units) from @a world to the helicoid's singular axis, where both
    /// arguments of Eq. 1's atan2, kT y1 + kN y2 and 1 + kN y1 - kT y2, vanish: the line through
    /// p0 + Q (-kN, kT, 0) / (kT² + kN²) along E_B. theta turns about it like the polar angle
    /// about a vortex, so its gradient is 1/r at distance r; streamlines with kN < 0 spiral onto
    /// it in finite arc length. Infinite when kT = kN = 0.
    double axisDistance(const Vec3d& world) const;
};

/// @brief How close, in tracing steps, a trace may come to a helicoid's singular axis and still
/// be a streamline: at r = 2 steps a step turns theta by about half a radian, and RK4 traces at
/// h and h/16 agree to 3e-5 of their length (40 seeded pieces with kN < 0, tested to 1e-4);
/// nearer the axis the trace depends on the step (issue 19: traces that passed within one step
/// of it changed by up to 100 % of their length at a finer step). Measured for fitting: 2 steps
/// fit as closely as 1 and 4 at 30 vertices and better than 4 at the stored resolutions
/// (docs/fitting.md). At a piece's root the axis is 1/sqrt(kT² + kN²) away, at least 4 steps by
/// the fit's bounds on k.
constexpr double kAxisClearanceSteps = 2.0;

// theta() and tangent() are inline: tracing calls them four times per RK4 step, and fitting
// traces thousands of times per strand.
inline double Helicoid::theta(const Vec3d& world, double thetaRef) const
{
    const Vec3d d = world - p0;
    const double y1 = d.dot(q.t), y2 = d.dot(q.n), y3 = d.dot(q.b);
    double th = fastmath::atan2(k.kT * y1 + k.kN * y2, 1.0 + k.kN * y1 - k.kT * y2) + k.kB * y3;
    // Unwrap: the multiple of 2π that brings theta closest to its previous value.
    constexpr double twoPi = 2.0 * M_PI;
    th += twoPi * double(fastmath::roundToInt((thetaRef - th) * (1.0 / twoPi)));
    return th;
}

inline double Helicoid::axisDistance(const Vec3d& world) const
{
    const double k2 = k.kT * k.kT + k.kN * k.kN;
    if (!(k2 > 0.0)) return std::numeric_limits<double>::infinity();
    const Vec3d d = world - p0;
    const double y1 = d.dot(q.t), y2 = d.dot(q.n);
    const double u = k.kT * y1 + k.kN * y2, v = 1.0 + k.kN * y1 - k.kT * y2;
    return std::sqrt((u * u + v * v) / k2);
}

inline Vec3d Helicoid::tangent(const Vec3d& world, double& thetaRef) const
{
    thetaRef = theta(world, thetaRef);
    const double phi = k.alpha * thetaRef;
    double ct, st, cp = 1.0, sp = 0.0;
    fastmath::sinCos(thetaRef, st, ct);
    if (phi != 0.0) fastmath::sinCos(phi, sp, cp);
    return (cp * ct) * q.t + (cp * st) * q.n + sp * q.b;
}

/// @brief Eq. 1 in a lane: theta at local coordinates (y1, y2, y3) of a helicoid with curvatures
/// (kT, kN, kB), unwrapped against @a t (which receives it), and the sines and cosines of theta and
/// of phi = alpha theta that Eq. 2's frame is made of. Branchless (FastMath.h), for the lane
/// kernels (Helicoid.cc) and tangentLane().
inline void laneAngles(double y1, double y2, double y3, double kT, double kN, double kB, double alpha, double& t,
                       double& st, double& ct, double& sp, double& cp)
{
    constexpr double twoPi = 2.0 * M_PI, invTwoPi = 1.0 / (2.0 * M_PI);
    double a = fastmath::atan2Lane(kT * y1 + kN * y2, 1.0 + kN * y1 - kT * y2) + kB * y3;
    a += twoPi * fastmath::roundLane((t - a) * invTwoPi);
    t = a;
    fastmath::sinCosLane(a, st, ct);
    fastmath::sinCosLane(alpha * a, sp, cp);
}

inline Vec3d Helicoid::tangentLane(const Vec3d& world, double& thetaRef) const
{
    const Vec3d d = world - p0;
    double st, ct, sp, cp;
    laneAngles(d.dot(q.t), d.dot(q.n), d.dot(q.b), k.kT, k.kN, k.kB, k.alpha, thetaRef, st, ct, sp, cp);
    return (cp * ct) * q.t + (cp * st) * q.n + sp * q.b;
}

/// @brief Integrators for helicoid streamlines: forward Euler is Eq. 3, the paper's choice;
/// RK4 (with theta unwrapped at every stage) is for when the streamline must be exact. Both are
/// the streamline engine's (field/Streamline.h) over an AnalyticHelicoidSampler
/// (AnalyticHelicoidSampler.h); toIntegrator() maps them.
enum class HelicoidIntegrator { Euler, RK4 };

inline Integrator toIntegrator(HelicoidIntegrator integrator)
{
    return integrator == HelicoidIntegrator::Euler ? Integrator::Euler : Integrator::RK4;
}

/// @brief One piece of a p-helicoid: parameters, length (world units) and a roll about E_T applied
/// to the frame it starts with.
struct HelicoidPiece
{
    HelicoidParams k;
    double length = 0.0;
    double roll = 0.0;
};

/// @brief The traced points of a p-helicoid, with the frame of Eq. 2 at each point and the arc
/// length of each point from the root.
struct HelicoidTrace
{
    std::vector<Vec3d> points;
    std::vector<FrameD> frames;
    std::vector<double> arc;
    std::vector<Helicoid> pieces;    ///< each piece's helicoid (its p0 and Q)
    std::vector<std::size_t> joints; ///< index of each piece's first point
};

/// @brief Trace a p-helicoid from @a root with @a frame (Eq. 3, piece by piece, §3.4): piece i+1
/// starts at the end of piece i with the frame of Eq. 2 there (then rolled by its roll), so
/// tangents — and whole frames — are continuous at the joints.
/// @param field optional: trace through these pieces' helicoids (their p0 and Q) instead of
/// building them from @a root and @a frame; wisps use the guide's field this way.
void tracePHelicoid(const Vec3d& root, const FrameD& frame, const std::vector<HelicoidPiece>& pieces,
                    double step, HelicoidIntegrator integrator, HelicoidTrace& out,
                    const std::vector<Helicoid>* field = nullptr);

/// @brief The least distance of @a trace's points from the singular axis of the piece each lies
/// on (Helicoid::axisDistance), divided by @a step: below kAxisClearanceSteps the trace is not a
/// converged streamline.
double traceClearance(const HelicoidTrace& trace, double step);

/// @brief tracePHelicoid() for @a count strands from @a roots at once, all with the same pieces
/// (and the same @a field when given), traced in lockstep a few at a time for speed. Steps go
/// through the streamline engine (StreamlineIntegrator over an AnalyticHelicoidSampler), except
/// forward Euler through a shared @a field (wisps), which has its own SIMD fast path (the same
/// steps, eight strands per vector loop; tests hold it to tracePHelicoid()).
void tracePHelicoids(const Vec3d* roots, std::size_t count, const FrameD& frame, const std::vector<HelicoidPiece>& pieces,
                     double step, HelicoidIntegrator integrator, HelicoidTrace* outs, const std::vector<Helicoid>* field = nullptr);

/// @brief One p-helicoid to trace: root, frame, pieces and step (tracePHelicoidPoints()).
struct PHelicoidRequest
{
    Vec3d root{0.0};
    FrameD frame;
    const std::vector<HelicoidPiece>* pieces = nullptr;
    double step = 0.0;
};

/// @brief The points only of @a count p-helicoids, each with its own root, frame, pieces and step,
/// traced with forward Euler (Eq. 3) or RK4 eight at a time in a lane kernel, each lane on its
/// own strand's helicoids (interpolated hair: growScene()'s hot path). Strand i's points go to
/// @a out[i], which holds 1 + Σ stepCount(length, step) points. The same steps as
/// tracePHelicoid() (the branchless forms of the same polynomials; tests hold them together).
void tracePHelicoidPoints(const PHelicoidRequest* strands, std::size_t count, HelicoidIntegrator integrator, Vec3f* const* out);

} // namespace vdbhair
