/// @file StreamlineImpl.h
/// @brief Template bodies of Streamline.h (the integrator and the streamline loop).
#pragma once

// Included at the end of Streamline.h; on its own, it includes Streamline.h first.
#include <vdbhair/field/Streamline.h>

namespace vdbhair {

namespace detail {

/// Whether SamplerT has startDirection() (Streamline.h).
template<typename SamplerT, typename = void>
struct HasStartDirection : std::false_type {};
template<typename SamplerT>
struct HasStartDirection<SamplerT, std::void_t<decltype(std::declval<SamplerT&>().startDirection(
                                       std::declval<const Vec3d&>(), std::declval<Vec3d&>()))>> : std::true_type {};

} // namespace detail

template<typename SamplerT>
inline SampleStatus StreamlineIntegrator<SamplerT>::advance(const Vec3d& p, double h, Vec3d& q)
{
    Vec3d k1;
    SampleStatus s;
    if constexpr (detail::HasStartDirection<SamplerT>::value) s = mSampler.startDirection(p, k1);
    else s = mSampler.direction(p, k1);
    if (s != SampleStatus::Ok) return s;
    return advanceFrom(p, k1, h, q);
}

template<typename SamplerT>
inline SampleStatus StreamlineIntegrator<SamplerT>::advanceFrom(const Vec3d& p, const Vec3d& k1, double h, Vec3d& q)
{
    switch (mIntegrator) {
    case Integrator::Euler: return advanceFrom<Integrator::Euler>(p, k1, h, q);
    case Integrator::RK2: return advanceFrom<Integrator::RK2>(p, k1, h, q);
    case Integrator::RK3: return advanceFrom<Integrator::RK3>(p, k1, h, q);
    case Integrator::RK4: return advanceFrom<Integrator::RK4>(p, k1, h, q);
    }
    return SampleStatus::Left;
}

template<typename SamplerT>
template<Integrator I>
inline SampleStatus StreamlineIntegrator<SamplerT>::advanceFrom(const Vec3d& p, const Vec3d& k1, double h, Vec3d& q)
{
    Vec3d k2, k3, k4;
    SampleStatus s = SampleStatus::Ok;
    if constexpr (I == Integrator::Euler) {
        q = p + h * k1;  // Piuze et al. 2011, Eq. 3: p_{i+1} = p_i + h E_T(p_i)
    } else if constexpr (I == Integrator::RK2) {  // the midpoint rule
        if ((s = mSampler.direction(p + 0.5 * h * k1, k2)) != SampleStatus::Ok) return s;
        if (reversed(k1, k2)) return SampleStatus::Vanished;
        q = p + h * k2;
    } else if constexpr (I == Integrator::RK3) {  // Kutta's third-order rule
        if ((s = mSampler.direction(p + 0.5 * h * k1, k2)) != SampleStatus::Ok) return s;
        if ((s = mSampler.direction(p + h * (2.0 * k2 - k1), k3)) != SampleStatus::Ok) return s;
        if (reversed(k1, k2) || reversed(k1, k3)) return SampleStatus::Vanished;
        q = p + (h / 6.0) * (k1 + 4.0 * k2 + k3);
    } else {
        static_assert(I == Integrator::RK4);
        if ((s = mSampler.direction(p + 0.5 * h * k1, k2)) != SampleStatus::Ok) return s;
        if ((s = mSampler.direction(p + 0.5 * h * k2, k3)) != SampleStatus::Ok) return s;
        if ((s = mSampler.direction(p + h * k3, k4)) != SampleStatus::Ok) return s;
        if (reversed(k1, k2) || reversed(k1, k3) || reversed(k1, k4)) return SampleStatus::Vanished;
        q = p + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    return s;
}

template<typename SamplerT>
StopReason traceStreamline(SamplerT& sampler, const Vec3d& root, double length, const StreamlineRules& rules,
                           std::vector<Vec3d>& points)
{
    StreamlineIntegrator<SamplerT> integrator(sampler, rules.integrator, rules.reversal);
    const double step = rules.step;
    const std::size_t needed = stepCount(length, step);
    const std::size_t limit = rules.maxSteps ? std::min(needed, rules.maxSteps) : needed;
    points.assign(1, root);
    Vec3d p = root, last(0.0);
    double outside = 0.0;  // travelled past the field in a row
    for (std::size_t k = 0; k < limit; ++k) {
        const double h = k + 1 == needed ? length - double(needed - 1) * step : step;
        Vec3d q;
        const SampleStatus s = integrator.advance(p, h, q);
        if (s == SampleStatus::Ok) {
            last = (q - p) / h;
            outside = 0.0;
        } else if (continuesPastField(s, k, outside, h, rules.marginLength)) {
            q = p + h * last;  // past the active region, within the margin: straight on
            outside += h;
        } else {
            return stopReasonOf(s);
        }
        p = q;
        points.push_back(p);
    }
    return limit == needed ? StopReason::FullLength : StopReason::MaxSteps;
}

} // namespace vdbhair
