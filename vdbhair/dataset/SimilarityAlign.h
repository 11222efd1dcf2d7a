/// @file SimilarityAlign.h
/// @brief Similarity transforms (scale, rotation, translation) fitted to point pairs (Umeyama 1991)
/// and to two point sets without pairs by trimmed iterative closest points, and a groom's head
/// mesh aligned to a common head: what `vdbhair prepare --align-to` fits.
///
/// What is fitted to what: the groom's own head mesh (`--head`) onto the common head mesh
/// (`--align-to`), never the strands themselves. When both meshes have the same vertex count and
/// the same triangles (two copies of one head model, moved), vertex i corresponds to vertex i and
/// the transform is Umeyama's closed form on those pairs. Otherwise the vertices are matched
/// without pairs by trimmed ICP (Chetverikov et al. 2002): each iteration pairs every (sampled)
/// vertex of each mesh with the nearest point on the other's surface (a k-d tree of vertices, then
/// the triangles around the nearest four), drops the worst (1 - overlap) share of the pairs in
/// each direction (necks and shoulders cut at different heights), and takes a Gauss-Newton step
/// of the similarity that moves each point onto the plane of its match (point-to-plane ICP, Chen
/// & Medioni 1992, with a scale): matched point to point, ICP converges only linearly, and stalls
/// one vertex off on two samplings of one surface. Matching both ways keeps the scale from collapsing
/// onto a patch of the target, which one-way matching with a free scale rewards. Hairstyles come
/// in any up axis and facing, so ICP starts from the 24 rotations that map axes to axes (each
/// with the scale of the two sets' RMS radii and their centroids matched), run on a subsample, and
/// the best start is refined on up to `maxSamples` points of each set.
#pragma once

#include <vdbhair/Types.h>
#include <vdbhair/io/MeshFile.h>

#include <openvdb/math/Mat3.h>

#include <cstddef>
#include <vector>

namespace vdbhair {

/// @brief x -> scale * rotation * x + translation (rotation proper: det +1; scale > 0).
struct Similarity
{
    double scale = 1.0;
    openvdb::math::Mat3d rotation = openvdb::math::Mat3d::identity();  ///< rotation(i, j): row i, column j
    Vec3d translation{0.0};

    Vec3d apply(const Vec3d& p) const;
    /// @brief The inverse transform (x = s R y + t  =>  y = (1/s) R^T x - (1/s) R^T t).
    Similarity inverse() const;
};

/// @brief The similarity that maps @a from[i] closest to @a to[i] in the least-squares sense
/// (Umeyama 1991, Eq. 40-42; Eigen::umeyama), over the pairs with @a weights[i] != 0 when
/// @a weights is given.
/// @throw ValueError if the sizes differ, there are fewer than 3 pairs, or every point of @a from
/// is the same point (no scale or rotation is determined).
Similarity fitSimilarity(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to);

struct AlignParams
{
    /// Share of the pairs of each direction kept at every ICP iteration (the nearest ones): heads
    /// cut at the neck at different heights overlap in most, not all, of their surface.
    double overlap = 0.85;
    int iterations = 100;          ///< ICP iterations of the refinement, at most
    int startIterations = 25;      ///< ICP iterations of each of the 24 starts
    std::size_t startSamples = 1500;  ///< points of each set (evenly by index) used for the starts
    std::size_t maxSamples = 20000;   ///< points of each set (evenly by index) used for the refinement
    /// Stop when the RMS of the kept pairs changes by less than this share of it in an iteration
    /// (point-to-plane steps converge in a few iterations; below this the change is rounding).
    double tolerance = 1e-5;
    /// When both are non-zero, only the starts that turn @a sourceUp to within 90 degrees of
    /// @a targetUp are tried, and a result that turns it to within 30 degrees wins over any that
    /// does not: a head's rounded top fits the other head upside down or on its side nearly as
    /// well as upright, so ICP needs to be told which way is up (prepareStrands() takes the
    /// source's up from its head's centroid to its roots').
    Vec3d sourceUp{0.0}, targetUp{0.0};

    /// @throw ValueError naming the field, the value and the rule.
    void validate() const;
};

enum class AlignMethod
{
    Correspondence,  ///< same vertex count and triangles: Umeyama on vertex i -> vertex i
    Icp              ///< trimmed ICP from the 24 axis rotations
};

struct AlignResult
{
    Similarity transform;
    AlignMethod method = AlignMethod::Icp;
    /// RMS and largest distance (target units) from the moved source points to their nearest
    /// target point: over the kept share (`overlap`) of the pairs, and over all of them.
    double rms = 0.0, max = 0.0, rmsAll = 0.0;
    std::size_t pairs = 0;   ///< source points measured (all of them, or the refinement's samples)
    int iterations = 0;      ///< of the refinement (0 for correspondence)
    int start = -1;          ///< which of the 24 starts won (-1 for correspondence)
};

/// @brief The similarity that moves the points @a from onto the points @a to, without pairs
/// (trimmed ICP, both ways, from the 24 axis rotations, or those of them that keep up up; see above). Deterministic and independent
/// of the thread count.
/// @throw ValueError for fewer than 3 points in either set, non-finite points, or bad params.
AlignResult alignPointSets(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to, const AlignParams& params = {},
                           bool threaded = true);

/// @brief The similarity that moves the mesh @a from onto the mesh @a to: Umeyama on vertex pairs
/// when both have the same vertex count and triangles, else alignPointSets() of @a from's vertices
/// onto @a to's vertices and triangle centroids. The residuals are measured on every vertex of
/// @a from against that target.
/// @throw ValueError as alignPointSets().
AlignResult alignMeshes(const TriangleMesh& from, const TriangleMesh& to, const AlignParams& params = {},
                        bool threaded = true);

const char* alignMethodName(AlignMethod method);

} // namespace vdbhair
