/// @file ScalpMap.h
/// @brief Wang et al.'s scalp space (2009, §3) on a real scalp: Eq. 1-2 with the distance
/// d(x̂, ŷ, ẑ) from the centre to the scalp measured on a level set, and the local frame at every
/// (u, v).
///
/// The parameterization's sphere (centre, radius, up) comes from ScalpSpace.h (by default the sphere
/// fitted to the roots). Without a surface the scalp *is* that sphere (d ≡ 1, the paper's
/// assumption). With a surface (a `surface` level set), d(u, v) is measured once along the ray from
/// the centre in the direction of (u, v) with OpenVDB's LevelSetRayIntersector, in units of the
/// radius, and tabulated on a resolution × resolution grid of (u, v) ∈ (0, π)² (bilinear between
/// nodes); directions whose ray misses the surface take the sphere (d = 1), and are counted. So
///   w = |p'| - d(u, v)   (units of the radius; 0 on the scalp, positive above it).
/// The inverse (Eq. 2): p' = (w + d(u, v)) (h cot u, h - 1, h cot v), h = 2 / (cot²u + cot²v + 1).
///
/// A scalp-space tangent field (`field --space scalp --scalp HEAD`) carries its map in its grids'
/// metadata so that any reader rebuilds it exactly: `vdbhair_scalp_distance`, the table of d at
/// kFieldResolution² nodes as text (FieldMapping.h), from which the map is restored with the
/// table constructor below.
///
/// Local frame (§3): R is the shortest rotation taking +y onto the scalp's unit outward normal at
/// (u, v) (the sphere's radial direction, or the level set's normalized gradient, tabulated with d);
/// the frame is n = R y (normal), t = R x (tangent), b = R z (binormal), in world space. Points in
/// the hair volume use the frame of the scalp point with the same (u, v).
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/field/ScalpSpace.h>
#include <vdbhair/strands/StrandSet.h>

#include <openvdb/openvdb.h>

#include <memory>
#include <vector>

namespace vdbhair {

/// @brief An orthonormal frame in world space: t (tangent, R x), n (normal, R y), b (binormal, R z).
struct ScalpFrame
{
    Vec3d t{1.0, 0.0, 0.0}, n{0.0, 1.0, 0.0}, b{0.0, 0.0, 1.0};

    /// World direction of local coordinates (x along t, y along n, z along b).
    Vec3d toWorld(const Vec3d& local) const { return t * local.x() + n * local.y() + b * local.z(); }
    /// Local coordinates of a world direction.
    Vec3d toLocal(const Vec3d& world) const { return Vec3d(t.dot(world), n.dot(world), b.dot(world)); }
};

class ScalpMap
{
public:
    static constexpr int kDefaultResolution = 256;  ///< table nodes per (u, v) axis: 0.7° apart
    /// Table nodes per axis of the map a scalp-space field carries (2.8° apart: 0.5 units on a
    /// head of radius 10; d is bilinear between nodes, and the field only needs the map to be the
    /// same wherever it is rebuilt, which the stored table guarantees).
    static constexpr int kFieldResolution = 64;
    static constexpr int kMinResolution = 8;
    static constexpr int kMaxResolution = 4096;

    /// @brief The paper's scalp: the sphere itself (d ≡ 1).
    explicit ScalpMap(const ScalpSphere& sphere);

    /// @brief A real scalp: d(u, v) and normals tabulated from the level set @a surface.
    /// @throw TypeError if @a surface is not a level set; ValueError if the sphere's centre is not
    /// inside it (rays from outside cross the scalp twice) or @a resolution is below 8.
    ScalpMap(const ScalpSphere& sphere, const openvdb::FloatGrid& surface, int resolution = kDefaultResolution);

    /// @brief A real scalp restored from its table: @a distances holds d at resolution² nodes (row
    /// v, column u, as distances() returns them). Normals come from the tabulated surface by
    /// central differences (within about a degree of the level set's on a smooth head); misses()
    /// is 0.
    /// @throw ValueError if @a resolution is outside [kMinResolution, kMaxResolution], the table
    /// has another size, or a distance is not a positive finite number.
    ScalpMap(const ScalpSphere& sphere, std::vector<float> distances, int resolution);

    /// (u, v, w) of a world point (Eq. 1; w in units of the radius).
    Vec3d toScalp(const Vec3d& worldPos) const;
    /// World point of (u, v, w) (Eq. 2).
    Vec3d toWorld(const Vec3d& uvw) const;
    /// The world point on the scalp with the (u, v) of @a worldPos (w set to 0).
    Vec3d projectToScalp(const Vec3d& worldPos) const { Vec3d s = toScalp(worldPos); s.z() = 0.0; return toWorld(s); }
    /// The local frame at (u, v).
    ScalpFrame frame(double u, double v) const;
    /// d(u, v) in units of the radius (1 on the sphere).
    double scalpDistance(double u, double v) const;

    const ScalpSphere& sphere() const { return mSphere; }
    double radius() const { return mSphere.radius; }
    bool hasSurface() const { return !mD.empty(); }
    int resolution() const { return mResolution; }
    /// d at the table's nodes (row v, column u; empty for the sphere).
    const std::vector<float>& distances() const { return mD; }
    /// Table directions whose ray missed the surface (they use the sphere).
    std::size_t misses() const { return mMisses; }

private:
    Vec3d unitDirection(double u, double v) const;  ///< in the sphere's frame (y up), unit
    void lookup(double u, double v, double& d, Vec3d& normal) const;
    void axesFromUp();

    ScalpSphere mSphere;
    Vec3d mRight{1.0, 0.0, 0.0}, mUp{0.0, 1.0, 0.0}, mForward{0.0, 0.0, 1.0};  ///< world axes of the sphere's x, y, z
    int mResolution = 0;
    std::vector<float> mD;        ///< #res² d(u, v), row v, column u
    std::vector<Vec3f> mNormal;   ///< #res² unit normals in world space
    std::size_t mMisses = 0;
};

/// @brief The scalp map of hair with these roots (Wang et al. §3): the sphere fitted to @a roots
/// (fitScalpSphere()), up @a up or, when @a up is zero, the roots' mean direction from its centre
/// (cyHair files are z-up, USC's y-up); measured on the level set @a surface when given.
/// @param upUsed if given, receives the up axis used
/// @throw ValueError as fitScalpSphere() and the ScalpMap constructors (a centre not inside the surface).
std::shared_ptr<ScalpMap> scalpMapOfPoints(const std::vector<Vec3f>& roots, const Vec3d& up, openvdb::FloatGrid::ConstPtr surface,
                                           Vec3d* upUsed = nullptr, int resolution = ScalpMap::kDefaultResolution);
/// @brief The same for a hairstyle's roots.
std::shared_ptr<ScalpMap> hairScalpMap(const StrandSet& strands, const Vec3d& up, openvdb::FloatGrid::ConstPtr surface,
                                       Vec3d* upUsed = nullptr, int resolution = ScalpMap::kDefaultResolution);

/// @brief @a strands moved from the scalp @a from onto the scalp @a to through scalp space (Wang
/// et al. §3: the parameterization is the same for every head): each root keeps its (u, v) and
/// its height w above the scalp, and every vertex its offset from the root in the root's local
/// frame, in units of the head's radius. Hair made on one head so grows on another of any size or
/// shape with the same (u, v) layout; the strand count, vertex counts and order are kept.
/// Scalp space ties (u, v) to the world's axes (the shortest rotation taking +y to each sphere's
/// up): heads that face different ways need @a turn, radians about the up axis, turning the layout
/// (and every strand with it) on @a to. With @a from and @a to the same map, @a turn is the
/// rigid rotation of the hairstyle about the up axis through the centre (tested).
/// @warning Far from the root the other head's shape may differ: strands are not kept out of it.
StrandSet moveToScalp(const StrandSet& strands, const ScalpMap& from, const ScalpMap& to, double turn = 0.0, bool threaded = true);

} // namespace vdbhair
