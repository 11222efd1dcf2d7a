/// @file DetailEdges.h
/// @brief The geometry of DetailBlend::Edges (DetailTransfer.h, "Edges"): a strand as its
/// carrier and its own edges in the carrier's frames, and those edges laid along another carrier.
/// Used by DetailTransfer.cc.
#pragma once

#include <vdbhair/Types.h>

#include <vector>

namespace vdbhair {
namespace detail {

/// A polyline's low-passed self (smoothPolyline(), σ in vertices) with its rotation-minimizing
/// frames (started from @a reference) and arc lengths: what detail is laid along.
struct Carrier
{
    std::vector<Vec3f> points;
    std::vector<Frame> frames;
    std::vector<double> arc;
    double length() const { return arc.empty() ? 0.0 : arc.back(); }

    Carrier() = default;
    Carrier(const std::vector<Vec3d>& p, double sigma, const Vec3f& reference);

    /// The frame at arc length @a s (clamped to the carrier), between vertices by normalized
    /// interpolation; as three world axes (t, n, b).
    void frameAt(double s, Vec3d axes[3]) const;
};

/// One strand's detail as edges (DetailBlend::Edges): every edge in the frame of the strand's
/// carrier at the edge's middle; @a advance receives how far along the carrier each edge goes
/// (where the edge is laid along the output's carrier). (Turning each edge so that the edges'
/// local mean points along the carrier was tried: the ponytail onto the default head drifted
/// 0.082 of its length from BASE's wisps with it, 0.076 without.)
std::vector<Vec3d> strandEdges(const std::vector<Vec3d>& strand, double sigma, const Vec3f& reference, std::vector<Vec3f>* carrierPoints,
                               std::vector<double>* advance, std::vector<double>* frameShift);

/// The strand of DetailBlend::Edges: @a d (strandEdges()) scaled by @a lambda, laid from
/// @a root in the frames of @a carrier at the place each edge reaches along it (its running
/// progress along x̂), until the progress reaches @a target: the strand's last edge is cut
/// there, or the strand's loop (strandLoop()) repeats after it, turned by one more twist each time.
std::vector<Vec3d> layEdges(const std::vector<Vec3d>& d, const std::vector<double>& advance, const std::vector<double>& frameShift,
                            double lambda, const Carrier& carrier, const Vec3d& root, double target);

} // namespace detail
} // namespace vdbhair
