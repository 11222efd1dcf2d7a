/// @file ShepardWeights.h
/// @brief Interpolation weights of new roots over guide roots: Shepard's inverse distance
/// weighting (Piuze et al. 2011, §4.1) and the faded K-nearest weights of Blender's Interpolate
/// Curves node (the point-blending baseline), over one nanoflann k-d tree of the guide roots
/// (strands/PointCloud.h).
///
/// Shepard: w_i = φ_i / Σ φ_j with φ_i = |x̃ - x_i|^-p over every guide, or over the K nearest by
/// root. p = 3 is the paper's choice for all its examples: larger p gives clumps around each guide,
/// smaller p smooths the style out. A root that coincides with a guide's root (distance exactly 0)
/// gets weight 1 on that guide alone (the first such guide by index), so it reproduces it exactly.
///
/// Faded (Blender 3.5's Interpolate Curves, the behaviour Houdini's Hair Generate shares): the K+1
/// nearest guides, w_i ∝ (d_max - d_i) / d_i with d_max the distance of the farthest of them, so
/// the farthest has weight zero and a guide enters or leaves the neighbourhood without a jump
/// ("popping"); with K or fewer guides in all, plain 1/d over them.
///
/// Sums are taken in a fixed order (by distance, ties by guide index as nanoflann returns them
/// for one tree), so results do not depend on the thread count.
#pragma once

#include <vdbhair/Types.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace vdbhair {

/// @brief Shepard's weights (Piuze et al. §4.1). The command's --power and --neighbors bind here.
struct ShepardParams
{
    double power = 3.0;  ///< p > 0 (the paper's α; 3 in all its examples)
    int neighbors = -1;  ///< the K nearest guides by root, K >= 1; -1: every guide (the paper)
};

/// @brief One guide's share of a new root.
struct GuideWeight
{
    std::uint32_t guide = 0;
    double weight = 0.0;
};

/// @brief The guide roots, and the weights of new roots over them. Thread-safe after construction.
class GuideLocator
{
public:
    /// @param roots #G world positions of the guide roots (copied), G >= 1
    /// @throw ValueError for no roots or a non-finite one.
    explicit GuideLocator(std::vector<Vec3d> roots);
    ~GuideLocator();
    GuideLocator(const GuideLocator&) = delete;
    GuideLocator& operator=(const GuideLocator&) = delete;

    std::size_t size() const { return mRoots.size(); }
    const std::vector<Vec3d>& roots() const { return mRoots; }

    /// @brief Shepard weights at @a x (they sum to 1), heaviest first is not implied.
    /// @param[out] out replaced; one entry per guide used (all, or the K nearest)
    void shepardWeights(const Vec3d& x, const ShepardParams& params, std::vector<GuideWeight>& out) const;

    /// @brief Blender's faded weights over the K nearest (see above); they sum to 1.
    void fadedWeights(const Vec3d& x, int k, std::vector<GuideWeight>& out) const;

    /// @brief The index of the guide whose root is nearest @a x.
    std::uint32_t nearest(const Vec3d& x) const;

private:
    /// The @a k nearest guides to @a x, nearest first: indices and squared distances.
    void knn(const Vec3d& x, std::size_t k, std::vector<std::uint32_t>& idx, std::vector<double>& d2) const;

    std::vector<Vec3d> mRoots;
    struct Tree;
    std::unique_ptr<Tree> mTree;
};

/// @brief Check @a params: power positive and finite, neighbors -1 or at least 1.
/// @throw ValueError naming the value and the rule.
void validateShepardParams(const ShepardParams& params);

} // namespace vdbhair
