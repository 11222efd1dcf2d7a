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
    /// @a hint, if given, is where a walk along the carrier starts (and is left where it ends):
    /// the same result as without it, found in a few steps when @a s moved a little.
    void frameAt(double s, Vec3d axes[3], std::size_t* hint = nullptr) const;
    /// The point at arc length @a s (clamped to the carrier), between vertices linearly.
    Vec3d pointAt(double s, std::size_t* hint = nullptr) const;

private:
    /// The vertex @a j before arc length @a s and the fraction @a u of the way to the next.
    void locate(double s, std::size_t& j, double& u, std::size_t* hint) const;
};

/// The helix that continues a curly strand shorter than its curl's period (layEdges()): from its
/// wisp's turning per length κ and the mean cosine ρ between the wisp's edges and its centre's
/// direction (the helix's pitch: radius (1 − ρ²)/κ, (1 − ρ²)^½/κ of arc per radian), turning as
/// the wisp's edges turn about that direction (@c handed, +1 or −1).
struct Curl
{
    double kappa = 0.0, rho = 1.0, handed = 1.0;
    double period = 0.0;  ///< arc length of one turn of the helix; 0: no helix (strands repeat their loop)
};

/// @brief The curl of a wisp, @a strands about their centre's carrier @a centre (the same vertex
/// count), each smoothed with σ = @a sigma vertices (smoothPolyline()), pooled over the strands by
/// length: a helix when one of them turns at least half a turn (a C or more). A strand shorter than one and a half of its periods holds its curl in
/// its carrier rather than in its edges, so a loop of its edges would repeat only their crimp;
/// it continues as the helix instead (a wisp's short strands as its long ones curl).
Curl wispCurl(const std::vector<std::vector<Vec3d>>& strands, const Carrier& centre, double sigma);

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
/// there, or (@a curl) the strand's helix continues after it, or else the strand's loop
/// (strandLoop()) repeats after it, turned by one more twist each time.
std::vector<Vec3d> layEdges(const std::vector<Vec3d>& d, const std::vector<double>& advance, const std::vector<double>& frameShift,
                            double lambda, const Carrier& carrier, const Vec3d& root, double target, const Curl& curl = Curl{});

} // namespace detail
} // namespace vdbhair
