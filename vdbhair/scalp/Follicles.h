/// @file Follicles.h
/// @brief Follicles (hair roots) spread evenly over a scalp: a particle system constrained to
/// the surface's zero level set (Witkin & Heckbert 1994, as Piuze et al. 2011 use it to place
/// roots), optionally confined to a region.
///
/// Algorithm (each step labelled in Follicles.cc):
/// 1. Area A of the surface (in the region): sum over band voxels of a smoothed delta of the
///    distance, delta(phi) = (1 + cos(pi phi / eps)) / (2 eps), eps = 1.5 voxels, over the voxels
///    within two voxels of a sign change only (a band that never crosses zero, as around an open
///    part of a mesh, has no surface; its area is reported as Follicles::areaWithoutZero).
/// 2. Target: a count N gives the spacing of a hexagonal packing, d = sqrt(2 A / (sqrt(3) N));
///    a nearest-neighbour spacing s gives d = s / 0.90 (relaxed roots sit 10 % closer than the
///    ideal lattice: kRelaxedNearestPerSpacing) and N = 2 A / (sqrt(3) d^2).
/// 3. Contour: with a region, fixed particles on its rim (where the region ends on the surface),
///    about 0.90 d apart along it (contourParticles, SurfaceCells.h). They repel the others and
///    never move, so the region's edge is lined with roots (a hairline) instead of left to
///    whichever free particles reach it. The rim is found at the level set's resolution: where the
///    spacing is below a voxel, contour roots are about a voxel apart and free roots fill between.
/// 4. Initial particles: band voxels drawn with probability delta(phi) (particle i from the
///    random stream (seed, i)), jittered in the voxel and projected onto the zero level set;
///    a draw that lands outside the region is redrawn. A share @c initialFraction of the free
///    count starts (1 by default), with radius sigma_hat / sqrt(initialFraction).
/// 5. Relaxation with adaptive radii (Witkin & Heckbert 1994, §4-5). Particle i has a radius
///    sigma_i and energy E_i = sum_j alpha exp(-r_ij^2 / (2 sigma_i^2)) (cut at 3 sigma_i); it moves
///    by stepScale / (2 alpha) times sigma_i^2 sum_j r_ij (E_ij / sigma_i^2 + E_ji / sigma_j^2)
///    (with equal radii: stepScale sigma^2 grad E), projected onto the tangent plane, capped at
///    sigma_i / 2, then reprojected onto the surface; a move that leaves the region, or whose
///    projection fails (|phi| above 0.01 voxel, or landing more than 2 voxels beyond the aimed
///    step: thin or folded parts of a mesh's band), is halved up to three times, else not taken.
///    Radii follow the paper's feedback toward the desired energy E_hat = 0.8 alpha:
///    dsigma_i/dt = -rho (E_i - E_hat) / (dE_i/dsigma_i + beta / sigma_hat), stepped by
///    @c radiusStep per iteration (at most 10 % of sigma_i). sigma_hat = d / 2: six neighbours at
///    d hold E_hat exactly. Every @c controlInterval iterations (and at equilibrium) particles
///    near equilibrium fission (sigma_i above 1.5 sigma_hat: too sparse) or die (below
///    0.7 sigma_hat, with probability 1 - sigma_i / (0.7 sigma_hat): too crowded), and while the
///    count differs from the target the largest-radius particles split or the smallest die
///    (populationControl); none in the last @c settleIterations. Interactions use radii of
///    at most 1.5 sigma_hat; neighbours within 3 of those come from neighbour lists (plus a skin
///    of d / 2, from a nanoflann k-d tree, rebuilt when 1/20 of the particles have moved more
///    than half the skin, and after births or deaths). All particles move at once from the
///    previous positions (Jacobi), each summing its neighbours in index order, so the result is
///    the same bit for bit for any thread count, and as with a search per iteration.
///    Equilibrium: the largest move is below @c tolerance d and a control step changed nothing,
///    or @c maxIterations.
/// 6. Death: a particle within 0.1 d of an earlier one is removed (coincident particles exert no
///    force on each other; projection onto thin or folded parts of a mesh's band can make them).
/// 7. Frame: the normal is the level set's gradient; the tangent is the reference axis @c up
///    projected onto the tangent plane (x, then z, where up is nearly normal).
///
/// Witkin & Heckbert's constants (their §5, as Piuze et al. 2011 §4.3 use them): alpha = 6,
/// E_hat = 0.8 alpha, rho = 15 (the feedback rate, "phi" in some restatements), beta = 10 (here
/// in units of 1 / sigma_hat, so the feedback does not depend on the model's units), fission
/// above sigma_max = 1.5 sigma_hat, death below delta sigma_hat with delta = 0.7. Their
/// equilibrium test on the velocity is ours on the move (a quarter of sigma_i for fission and
/// death). What is ours: the count rule (the target count is known from the area, so the
/// population is driven to it exactly, the sparsest places first), and the fixed contour.
#pragma once

#include <vdbhair/Parameters.h>
#include <vdbhair/Types.h>

#include <openvdb/openvdb.h>
#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <vector>

namespace vdbhair {

/// Mean nearest-neighbour distance of relaxed roots over the hexagonal spacing d, measured: 0.90
/// on spheres of 1,500 and 5,000 roots and on Bangs_head, woman_head and sintel at 2,000-10,000
/// (0.90-0.92 with a contour). Defects and curvature keep a relaxed set below the ideal lattice.
constexpr double kRelaxedNearestPerSpacing = 0.90;

struct FollicleParams
{
    std::size_t count = 0;   ///< target count (or 0 and a spacing)
    double spacing = 0.0;    ///< target mean nearest-neighbour spacing, world units (when count is 0)
    std::uint64_t seed = 0;
    int maxIterations = 200;
    double tolerance = 2e-3;
    /// Step of the relaxation as a multiple of sigma^2 grad E: the Jacobi update diverges into
    /// oscillation above about 1 (measured: 1.0 never settles, 0.25-0.7 reach CV 0.03-0.04 in 200
    /// iterations on a sphere of 2000 roots).
    double stepScale = 0.5;  ///< equilibrium: largest move below this fraction of the spacing
    Vec3d up{0.0, 1.0, 0.0};  ///< reference direction of the tangent frame
    // Witkin & Heckbert's particle system (see above).
    double alpha = 6.0;            ///< energy scale alpha
    double energyRatio = 0.8;      ///< desired energy E_hat = energyRatio alpha
    double feedback = 15.0;        ///< rho: rate at which radii chase E_hat
    double beta = 10.0;            ///< beta, in units of 1 / sigma_hat: keeps the radius equation finite when alone
    double radiusStep = 0.02;      ///< time step of the radius equation per iteration (stable below about 0.2)
    double fissionRatio = 1.5;     ///< fission above this many sigma_hat
    double deathRatio = 0.7;       ///< death below this many sigma_hat (delta)
    int controlInterval = 10;      ///< iterations between fission/death steps (0: never)
    int settleIterations = 30;     ///< the last iterations relax without births or deaths
    double initialFraction = 1.0;  ///< share of the free count placed at the start (fission makes the rest)
    bool contour = true;           ///< fixed particles on the region's rim (only with a region)
    /// Refuse counts above this (each particle costs about 200 bytes with the k-d tree).
    std::size_t maxCount = std::size_t(20'000'000);
};

struct Follicles
{
    std::vector<Vec3f> positions, normals, tangents;  ///< #N each, world units / unit vectors
    double area = 0.0;           ///< estimated surface area in the region
    /// Area of band (in the region) with no sign change within two voxels: no surface to put a
    /// root on (an open or inside-out part of a mesh), left out of @c area and of the count.
    double areaWithoutZero = 0.0;
    double targetSpacing = 0.0;  ///< d of step 2
    int iterations = 0;          ///< relaxation iterations run
    double lastMove = 0.0;       ///< largest move of the last iteration, in units of d
    std::size_t removed = 0;     ///< particles removed by step 6 (within 0.1 d of another)
    std::size_t contour = 0;     ///< fixed particles on the region's rim: the first @c contour positions
    std::size_t initial = 0;     ///< free particles placed at the start
    std::size_t fissions = 0, deaths = 0;  ///< births and deaths of step 5
    int lastPopulationChange = 0;  ///< the iteration after the last birth or death (0: none)
    double radiusSpread = 0.0;     ///< (largest - smallest) free radius at the end, in units of sigma_hat
};

/// @brief roots's declared parameters (vdbhair/Parameters.h): count or spacing, seed, iterations,
/// step, contour and initial share. The up axis is the front ends' (an axis name, a vector); the
/// particle system's constants are not options.
const ParamTable<FollicleParams>& follicleParameters();

/// @brief The area of a scalp's surface (its zero level set, within a region).
struct ScalpArea
{
    double area = 0.0;             ///< where the band changes sign within two voxels: where roots can grow
    double areaWithoutZero = 0.0;  ///< band that never changes sign (an open or unsigned part of a mesh): no surface
};

/// @brief Measure @a surface's area in @a region (null: everywhere), as sampleFollicles counts it.
ScalpArea measureScalpArea(const openvdb::FloatGrid::ConstPtr& surface, const openvdb::BoolGrid::ConstPtr& region);

/// @brief Spread follicles over @a surface (in @a region when given).
/// @throw ValueError (neither or both of count and spacing, a count of 0), LimitError (over
/// maxCount), LookupError (the region holds no surface), InterruptedError.
Follicles sampleFollicles(const openvdb::FloatGrid::ConstPtr& surface, const openvdb::BoolGrid::ConstPtr& region,
                          const FollicleParams& params, bool threaded = true,
                          openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief Spacing statistics of a set of roots.
struct FollicleStats
{
    std::size_t count = 0;
    double nnMean = 0.0;  ///< mean distance to the nearest other root (world units)
    double nnCV = 0.0;    ///< its coefficient of variation (standard deviation / mean)
    double nnMin = 0.0, nnMax = 0.0;
    double maxSurfaceDistanceVoxels = 0.0;  ///< largest |phi| at a root, in voxels (0 without a surface)
};

/// @brief Nearest-neighbour statistics of @a positions, and their distance to @a surface if given.
FollicleStats measureFollicles(const std::vector<Vec3f>& positions, const openvdb::FloatGrid::ConstPtr& surface = nullptr);

} // namespace vdbhair
