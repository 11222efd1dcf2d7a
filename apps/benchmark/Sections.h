/// @file Sections.h
/// @brief The benchmark's sections, each printing its own table (Benchmark.cc runs those
/// --sections names): in-process comparisons with OpenVDB's peers (PeerSections.cc), vdbhair's
/// own operations without a peer (HairSections.cc), and the `vdbhair` command run as processes
/// (ProcessSections.cc).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace vdbhair::bench {

// PeerSections.cc

/// @brief The "field" section: field estimation and streamline tracing against
/// points::rasterizeTrilinear and tools::VelocityIntegrator, on a real hairstyle from @a data (if
/// there), @a strands x @a vertices jittered copies of the bundled ponytail from @a source, and a
/// bundle as large whose field fits in the cache.
/// @param voxelSize the voxel size of the first two (0: vdbhair's suggestion for each)
void benchmarkFields(const std::string& data, const std::string& source, std::size_t strands, std::size_t vertices,
                     double voxelSize, int reps);
/// Follicles on the shared heads: vdbhair's particle system against the quick alternative a user
/// would write, UniformPointScatter in the voxels the zero level set crosses, projected onto it.
/// @param counts the root counts of each head's rows; @param only a part of the head paths (empty: all)
void benchmarkRoots(const std::string& data, const std::vector<std::size_t>& counts, const std::string& only);

// HairSections.cc

/// Helicoid tracing speed: strands per second for a four-piece p-helicoid of 64 steps (one guide
/// and its wisps), and for the bundled default head scene.
void benchmarkHelicoids(const std::string& source, int reps);
/// Interpolation (Piuze et al. 2011, §4.2): the paper's setup, 9 p-helicoid guides of about 4
/// pieces (3 to 5) on a 3 by 3 patch, 64 Euler steps a strand, interpolated at 1,000 and 90,000
/// random roots on the patch (the paper: 0.67 s for 1,000 on one 2.4 GHz core, about a minute for
/// 90,000), against blending the guides' points (Blender's Interpolate Curves) at the same vertex
/// count. Times include growing the strands.
void benchmarkInterpolation(int reps);
/// Hair from guides at production scale (the guides issue, item 7): 1,000 guides of 16 vertices on
/// a head sphere's upper half, hanging down it, in four groups (two partings), and 1,000,000 new
/// roots on the same cap, through `interpolateGuides()` at its defaults with clumps (and with curl),
/// without a head and with the sphere as the head. Peak memory is the process's (getrusage).
void benchmarkGroom(int reps, std::size_t strands);
/// `compare` (issue 54): a head of strands x 100 vertices against the same and against a jittered
/// copy, every measure (HairGS's four thresholds at centimetres, Chamfer, strand pairs, Fréchet,
/// the volume). The target is 100,000 strands against the same under 3 s
/// (--compare-strands 100000).
void benchmarkCompare(int reps, std::size_t strands);
/// What a helicoid field buys over a plain tangent field (issues 4 and 19): curly and wavy
/// strands retraced from their roots through each, at vdbhair's suggested voxel size and coarser,
/// with forward Euler (TraceParams' default) and with RK4 (retrace --helicoid's default,
/// kHelicoidRetraceIntegrator) for both fields, and the mean vertex error against the input (same
/// arc lengths), relative to the mean strand length.
void benchmarkHelicoidFields(const std::string& data, const std::string& source);
/// Fitting p-helicoids to real strands (issue 5's targets: >= 1000 strands/s with a mean error of
/// at most 2 % of the length on straight and wavy hair at 30 vertices).
/// @param limit the most strands per row (an evenly strided subset; 0: all)
void benchmarkFitting(const std::string& data, std::size_t limit, int reps);
/// Example-based synthesis (Wang et al. 2009; the paper: a 100,000-strand hairstyle in under two
/// minutes on a Pentium 4, clustering 50 %, texture optimization 20 %, refinement 20 %): time per
/// stage and peak memory, on real hairstyles and the 100,000-strand jittered set, both layouts.
void benchmarkSynthesis(const std::string& data, const std::string& source, std::size_t strands, std::size_t vertices);

// ProcessSections.cc

/// @brief The end-to-end section: the `vdbhair` command and the stock-OpenVDB peer program
/// (apps/benchmark/Peer.cc, the same operations as the library rows above, with an ifstream
/// reader) as processes on the same files, as a user runs them from the shell: each verb and its
/// peer in turn (A B A B ...), @a runs times after a warm-up, median wall and CPU time, peak
/// resident memory, and the ratio of the peer's wall time to vdbhair's.
/// @param ours the `vdbhair` program (empty: the one built next to this program)
void benchmarkEndToEnd(const std::string& source, std::size_t strands, std::size_t vertices, int runs, std::string ours);
/// @brief The scale section (issue 22, item 7): `vdbhair refine` at its defaults on hairstyles of
/// @a sizes strands x 32 vertices, made by vdbhair itself at benchmark time (the default head
/// scene's 400 guides, each grown into a wisp of size / 400 strands at step 1 by `vdbhair grow`,
/// resampled to 32 vertices by `vdbhair convert`) in a scratch folder removed afterwards: wall
/// and CPU time and peak resident memory from the outside (wait4), against the memory estimate
/// refine checks before it allocates (its --json report).
/// @param ours the `vdbhair` program (empty: the one built next to this program)
void benchmarkScale(const std::string& source, const std::vector<std::size_t>& sizes, std::string ours);

} // namespace vdbhair::bench
