/// @file HeadObstacle.h
/// @brief The head as an obstacle for retraced strands: a signed distance (world units,
/// negative inside) and its gradient, from a sphere or a narrow-band level set (an OpenVDB
/// FloatGrid of class level set, such as the `surface` grid of a scalp .vdb).
///
/// What a retrace may do near it is the obstacle's HeadPolicy. NoDeeper (what `refine --head` and
/// the fitted-sphere fallback use): a retraced vertex may be inside the head only as deep as the
/// input vertex at the same arc length was, so no vertex enters the head that was outside it, and
/// hair that already crossed the head model (roots embedded in the shared heads' scalps, a rough
/// sphere) is left as it was instead of being pushed out, which would change its length and
/// shape. KeepOutside (`--head-policy outside`, and the analytic tests): no retraced vertex inside.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/Types.h>

#include <openvdb/openvdb.h>

#include <memory>
#include <string>

namespace vdbhair {

enum class HeadPolicy
{
    KeepOutside,  ///< no retraced vertex inside the head
    NoDeeper      ///< no retraced vertex deeper inside than the input was
};

class HeadObstacle
{
public:
    /// @brief Unset: refineStrands() then fits a sphere to the roots.
    HeadObstacle() = default;
    /// @brief Explicitly no obstacle: distance() is +infinity everywhere.
    static HeadObstacle none();

    /// @throw ValueError unless @a radius is positive and finite and @a center finite.
    static HeadObstacle sphere(const Vec3d& center, double radius, HeadPolicy policy = HeadPolicy::KeepOutside);

    /// @brief A narrow-band level set (negative inside). Its distance is extended 21 voxels
    /// further into the interior (OpenVDB's fast sweeping, tools::dilateSdf()), so depths compare
    /// beyond the band; beyond that, and outside the band, the distance is the grid's background
    /// with its sign, and the gradient falls back to the direction from the band's centre of mass.
    /// @throw TypeError unless @a grid is a level set, ValueError if it has no active voxels.
    static HeadObstacle levelSet(openvdb::FloatGrid::ConstPtr grid, HeadPolicy policy = HeadPolicy::KeepOutside);

    /// @brief Whether there is no obstacle (unset or none()).
    bool empty() const { return mKind == Kind::None || mKind == Kind::Disabled; }
    /// @brief Whether it was never set (refineStrands() fits a sphere to the roots then).
    bool unset() const { return mKind == Kind::None; }
    bool isSphere() const { return mKind == Kind::Sphere; }
    HeadPolicy policy() const { return mPolicy; }
    const Vec3d& center() const { return mCenter; }
    double radius() const { return mRadius; }
    /// @brief The level set's voxel size (world units); 0 for a sphere or no head.
    double voxelSize() const { return mGrid ? mGrid->voxelSize()[0] : 0.0; }
    /// @brief Set the words describe() adds on where the head came from ("fitted to the roots").
    void setLabel(const std::string& label) { mLabel = label; }
    /// @brief A short description for reports ("sphere (0, 1.6, 0) r 0.11", "level set 'surface'"),
    /// with what the policy allows unless @a withPolicy is false (callers with a rule of their own).
    std::string describe(bool withPolicy = true) const;

    /// @brief Signed distance and outward unit normal at world points; one per thread.
    class Probe
    {
    public:
        explicit Probe(const HeadObstacle& head);
        /// Signed distance at @a p (world units; +inf without an obstacle).
        double distance(const Vec3d& p);
        /// Outward unit normal at @a p (zero without an obstacle).
        Vec3d normal(const Vec3d& p);
        /// @brief Signed distance at @a p and, in @a direction, the outward unit direction of
        /// its gradient there: on a level set the analytic gradient of the trilinear cell that
        /// gives the distance (one cell's eight values for both; normal()'s central differences
        /// take six more samples). Zero without an obstacle or where the cell is flat.
        double distance(const Vec3d& p, Vec3d& direction);
        /// @brief Move @a p along the normal until its distance is at least @a minDistance (a few
        /// Newton steps on a level set); @return whether it moved.
        bool pushOut(Vec3d& p, double minDistance);

    private:
        const HeadObstacle& mHead;
        std::unique_ptr<openvdb::FloatGrid::ConstAccessor> mAcc;
    };

private:
    enum class Kind { None, Disabled, Sphere, LevelSet };
    Kind mKind = Kind::None;
    HeadPolicy mPolicy = HeadPolicy::KeepOutside;
    std::string mLabel;  ///< where it came from, for describe()

    Vec3d mCenter{0.0};
    double mRadius = 0.0;
    openvdb::FloatGrid::ConstPtr mGrid;
};

/// The policy of a head read from a file or fitted to the roots (refine, comb): NoDeeper.
constexpr HeadPolicy kDefaultHeadPolicy = HeadPolicy::NoDeeper;

/// @throw ValueError unless "no-deeper" or "outside" (headPolicyName()'s names).
HeadPolicy headPolicyFromName(const std::string& name);
const char* headPolicyName(HeadPolicy policy);

/// @brief The head policy of a verb that takes a head (`--head-policy`, `head_policy=`; refine and
/// comb), declared once: the HeadPolicy member of P that @a field returns.
template<typename P, typename F>
Param<P> headPolicyParam(F field)
{
    auto p = makeParam<P>("head-policy", "How strands meet a head given: no-deeper (no vertex enters the head that the input had outside it; "
                                         "hair already inside is left as it was) or outside (every vertex is moved out)", "",
                          named<P>(field, headPolicyName, headPolicyFromName));
    p.choices = {headPolicyName(HeadPolicy::NoDeeper), headPolicyName(HeadPolicy::KeepOutside)};
    return p;
}

} // namespace vdbhair
