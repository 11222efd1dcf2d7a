/// @file AnalyticHelicoidSampler.h
/// @brief The streamline engine's sampler (field/Streamline.h) for one analytic helicoid
/// (Piuze et al. 2011, Eq. 1 and 2).
#pragma once

#include <vdbhair/field/Streamline.h>
#include <vdbhair/helicoid/Helicoid.h>

namespace vdbhair {

/// @brief The direction E_T of one helicoid (Eq. 1 and 2) at a world point; never Left or
/// Vanished. theta is unwrapped along the trace (Helicoid.h): startDirection() (a step's first
/// stage) unwraps it against the previous step's start and makes that the reference; the later
/// stages, direction(), unwrap against it without moving it. Near the singular axis, where a step
/// turns theta by more than π, this is what decides the branch: tracePHelicoid(), the fit and
/// the issue-19 clearance tests rely on it.
///
/// @a Branchless picks Helicoid::tangentLane() over Helicoid::tangent() (the same polynomials,
/// without the branches that follow the data): the fit's pre-fit (BranchlessHelicoidSampler).
/// @warning Not thread-safe: one per streamline.
template<bool Branchless>
class BasicAnalyticHelicoidSampler
{
public:
    /// @param theta theta at (or near) the trace's first point (0 at a helicoid's own root)
    explicit BasicAnalyticHelicoidSampler(const Helicoid& helicoid, double theta = 0.0) : mH(helicoid), mTheta(theta) {}

    /// A later stage of a step: E_T at @a worldPos, theta against the step's start.
    SampleStatus direction(const Vec3d& worldPos, Vec3d& unitDir)
    {
        double th = mTheta;
        unitDir = eval(worldPos, th);
        return SampleStatus::Ok;
    }

    /// A step's first stage: E_T at @a worldPos, whose theta becomes the reference.
    SampleStatus startDirection(const Vec3d& worldPos, Vec3d& unitDir)
    {
        unitDir = eval(worldPos, mTheta);
        return SampleStatus::Ok;
    }

    /// startDirection() as a value: E_T at a step's start (a trace that keeps the frame there
    /// passes it to StreamlineIntegrator::advanceFrom()).
    Vec3d tangent(const Vec3d& worldPos) { return eval(worldPos, mTheta); }

    /// theta (unwrapped) at the current step's start.
    double theta() const { return mTheta; }
    const Helicoid& helicoid() const { return mH; }

private:
    Vec3d eval(const Vec3d& worldPos, double& theta) const
    {
        if constexpr (Branchless) return mH.tangentLane(worldPos, theta);
        else return mH.tangent(worldPos, theta);
    }

    const Helicoid& mH;
    double mTheta;
};

using AnalyticHelicoidSampler = BasicAnalyticHelicoidSampler<false>;
using BranchlessHelicoidSampler = BasicAnalyticHelicoidSampler<true>;

} // namespace vdbhair
