/// @file FrameAverage.h
/// @brief A weighted average of rotations (helicoid frames) that is well defined: unit quaternions
/// sign-aligned to the heaviest one, summed with their weights and normalized (the "normalized
/// linear" quaternion mean; for rotations within 90° of each other it is within a few degrees of
/// the Karcher mean, and it is exact for a single frame or equal frames). Sign alignment matters:
/// q and -q are the same rotation, and summing them unaligned cancels them out.
/// If the aligned sum vanishes (opposite rotations in equal shares), the heaviest frame is returned.
#pragma once

#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/ShepardWeights.h>

#include <array>

namespace vdbhair {

/// @brief Unit quaternion (w, x, y, z) of the rotation whose columns are @a f.t, f.n, f.b.
std::array<double, 4> frameToQuaternion(const FrameD& f);
/// @brief The frame whose columns are the rotation of unit quaternion @a q.
FrameD quaternionToFrame(const std::array<double, 4>& q);

/// @brief Weighted average of @a frames[w.guide] over @a weights (which sum to 1).
FrameD averageFrames(const std::vector<FrameD>& frames, const std::vector<GuideWeight>& weights);

/// @brief The rotation R with a = b · R in frame columns: bᵀ a (a expressed in b's axes).
FrameD relativeFrame(const FrameD& a, const FrameD& b);
/// @brief b · r: the frame @a r (given in @a b's axes) in world axes.
FrameD composeFrames(const FrameD& b, const FrameD& r);

} // namespace vdbhair
