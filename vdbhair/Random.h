/// @file Random.h
/// @brief A small, fast, seedable random stream for per-strand randomness.
///
/// Every random choice in vdbhair draws from a stream seeded by (scene seed, guide index, strand
/// index), so results never depend on the thread count or on the order strands are processed
/// (pbrt-v4 seeds each item's RNG by its index). SplitMix64 (Steele, Lea, Flood 2014) is used
/// because seeding is free — std::mt19937 would fill 624 words for every strand.
#pragma once

#include <cmath>
#include <cstdint>

namespace vdbhair {

class Rng
{
public:
    /// @brief A stream for the item identified by @a a, @a b, @a c (e.g. seed, guide, strand).
    explicit Rng(std::uint64_t a, std::uint64_t b = 0, std::uint64_t c = 0)
        : mState(mix(mix(mix(a) ^ (b + 0x9e3779b97f4a7c15ull)) ^ (c + 0xbf58476d1ce4e5b9ull))) {}

    std::uint64_t next()
    {
        std::uint64_t z = (mState += 0x9e3779b97f4a7c15ull);
        return mix(z);
    }
    /// Uniform in [0, 1).
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
    /// Two independent standard normals from one Box–Muller draw.
    void normalPair(double& a, double& b)
    {
        const double u1 = 1.0 - uniform(), u2 = uniform();
        const double r = std::sqrt(-2.0 * std::log(u1)), angle = 2.0 * M_PI * u2;
        a = r * std::cos(angle);
        b = r * std::sin(angle);
    }

private:
    static std::uint64_t mix(std::uint64_t z)
    {
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    std::uint64_t mState;
};

} // namespace vdbhair
