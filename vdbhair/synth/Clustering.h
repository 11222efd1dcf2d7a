/// @file Clustering.h
/// @brief Hierarchical variational hair clustering (Wang et al. 2009, §4): Lloyd iterations of
/// region-growing partitioning (§4.2) and mean centre strands (§4.3), adaptive splitting to an
/// error threshold (§4.4), and the hierarchy of coarser levels with a quarter of the clusters each.
///
/// Neighbourhood: the paper connects strands by a Delaunay triangulation of the roots. vdbhair uses
/// the symmetric k-nearest-neighbour graph of the roots in world space (k = 8): for roots spread
/// over a scalp it joins the same near neighbours a Delaunay triangulation would, it needs no 2D
/// parameterization (roots under the head, where scalp space is singular, are still joined
/// properly), and nanoflann builds it in O(N log N). Strands in a component that no seed reaches
/// (an island of roots) seed a cluster of their own, so every strand is assigned.
///
/// Partitioning (§4.2): each cluster's seed is its member nearest its centre (first iteration: k
/// strands drawn by k-means++ from the random stream (seed, level), see Clustering.cc); seeds' neighbours enter one global priority
/// queue keyed by their L² distance to the seed's centre (ties broken by strand, then cluster
/// index, so the result does not depend on anything but the input); popping an unassigned strand
/// assigns it and pushes its unassigned neighbours with the same label. Clusters are connected.
/// Fitting (§4.3): the centre is the mean of the members' rows; its root is the mean of the
/// members' roots moved onto the scalp.
/// Iterations stop when the energy E = Σ L²(γ, centre) (Eq. 3) falls by less than @c tolerance of
/// itself, or after @c maxIterations.
/// Adaptive clustering (§4.4): after convergence, in every cluster whose farthest member is
/// farther than ε from the centre, that member seeds a new cluster; repeat until no cluster splits,
/// @c maxSplitRounds rounds, or @c maxClusters clusters.
#pragma once

#include <vdbhair/synth/StrandSamples.h>

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <vector>

namespace vdbhair {

struct ClusterParams
{
    static constexpr int kDefaultLevels = 3;  ///< Wang et al. §6: three scales for all but the simplest styles

    int initialClusters = 200;  ///< k0 of §4.4 (Wang et al.)
    /// ε of §4.4: the largest L² distance (radius units², over n_s = 64 vertices) of a strand from
    /// its centre. Table 1 gives 0.1-0.3 for a head of radius 1; 0.2 is its middle (an RMS
    /// distance of 0.056 radius per vertex).
    double threshold = 0.2;
    int neighbours = 8;        ///< k of the root graph
    int maxIterations = 8;     ///< Lloyd iterations per round (Fig. 3: a few reach most of the drop)
    /// Relative energy drop that ends a round: 1 % (Fig. 3: a few iterations reach most of the
    /// drop; measured on straight.hair, rounds at 1e-3 ran 6-8 iterations for the last 2 %)
    double tolerance = 1e-2;
    int maxSplitRounds = 6;    ///< adaptive rounds
    /// At most this share of the strands become clusters at the finest clustered level (wisps of 16
    /// strands on average at least). Long hair rarely meets ε = 0.2 everywhere (straight.hair's
    /// strands are 2.5 radii long: a 5° turn at the root moves the tip by 0.2 radii), so the cap,
    /// not ε, often sets the count; the paper's example had 40,000 strands in 220 clusters.
    double maxClusterFraction = 1.0 / 16.0;
    int levels = kDefaultLevels;  ///< levels of the hierarchy including the strands themselves (2 to 5)
    std::uint64_t seed = 0;

    /// @throw ValueError naming the parameter, its value and the rule.
    void validate(const char* where) const;
};

/// @brief One clustering of a set of samples.
struct Clustering
{
    std::vector<std::uint32_t> label;  ///< #N cluster of each sample
    StrandSamples centers;             ///< #k centre strands (the next coarser level)
    std::vector<double> energy;        ///< E (Eq. 3) after each iteration, radius units²
    std::vector<std::size_t> clusters; ///< the cluster count at each iteration
    double largestDistance = 0.0;      ///< largest L² of a sample from its centre at the end
    std::size_t seededIslands = 0;     ///< clusters seeded in components no seed reached
};

/// @brief Cluster @a samples into @a k clusters (adaptively from @a k when @a adaptive).
/// @throw ValueError for k = 0, or more clusters than samples; InterruptedError.
Clustering clusterSamples(const StrandSamples& samples, const ScalpMap& map, std::size_t k, bool adaptive,
                          const ClusterParams& params, std::uint64_t stream = 0,
                          openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief The full hierarchy: level 0 is @a strands; level l+1 holds the centres of level l.
/// Level 1 comes from adaptive clustering from k0 = min(initialClusters, N / 4); every coarser level
/// has a quarter of the clusters of the level below (at least 1).
struct ClusterHierarchy
{
    std::vector<StrandSamples> levels;   ///< #levels, 0 the finest
    std::vector<Clustering> clusterings; ///< #levels - 1: clusterings[l] partitions levels[l]
};

/// @throw ValueError for fewer strands than the hierarchy needs (4 per cluster at the coarsest
/// level); InterruptedError.
/// @param strands level 0, taken by value (pass an rvalue: 100,000 strands are 77 MB to copy).
ClusterHierarchy buildHierarchy(StrandSamples strands, const ScalpMap& map, const ClusterParams& params,
                                openvdb::util::NullInterrupter* interrupter = nullptr);

/// @brief A graph in compressed rows: the neighbours of point i are indices[offsets[i] ..
/// offsets[i + 1]), sorted (one allocation: the region growing's neighbour loads are its hottest
/// memory accesses).
struct NeighbourGraph
{
    std::vector<std::uint32_t> offsets, indices;
    const std::uint32_t* begin(std::uint32_t i) const { return indices.data() + offsets[i]; }
    const std::uint32_t* end(std::uint32_t i) const { return indices.data() + offsets[i + 1]; }
};

/// @brief The symmetric k-nearest-neighbour graph of @a points. Searched in parallel; the same
/// graph on any thread count.
NeighbourGraph neighbourGraph(const std::vector<Vec3d>& points, int k);

} // namespace vdbhair
