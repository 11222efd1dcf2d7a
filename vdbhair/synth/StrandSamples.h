/// @file StrandSamples.h
/// @brief Strands as feature vectors (Wang et al. 2009, §4.1): every strand resampled to n_s
/// vertices equally spaced in arc length (Table 1: n_s = 64) and expressed in the local frame of
/// its root (ScalpMap.h), relative to the root and in units of the head radius, so that strands
/// compare by the L² distance Σ_l |γ_a(l) − γ_b(l)|² whatever their place on the scalp and the
/// size of the head (the paper's thresholds are for a head of radius 1).
#pragma once

#include <vdbhair/strands/StrandSet.h>
#include <vdbhair/field/ScalpMap.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vdbhair {

struct StrandSamples
{
    static constexpr int kDefaultVertices = 64;  ///< n_s, Wang et al. Table 1
    /// What counts as detail along a strand (transfer's smoothing of the coarsest strands,
    /// combing's strand directions): σ = 1/8 of its vertices, eight of 64, which removes waves
    /// shorter than about half the strand and keeps its overall bend. Measured on transfer
    /// (turning per head radius, DETAILS' own in brackets): harolongo onto straight.hair 3.78
    /// (3.83) at 1/8 against 3.40 at 1/16 and 3.87 at 1/4, BASE's wisps kept within 0.022 of their
    /// length (0.014, 0.030); straight.hair onto harolongo 1.13 (0.61) against 1.44.
    static constexpr double kDetailSmoothing = 1.0 / 8.0;

    int vertices = kDefaultVertices;
    /// #N × 3 n_s: vertex l of strand s, coordinate c, at `local[(s * n_s + l) * 3 + c]`; the
    /// root-relative position in the root's frame (x along t, y along n, z along b), radius units.
    std::vector<float> local;
    std::vector<Vec3d> roots;        ///< #N world roots
    std::vector<Vec3d> scalp;        ///< #N scalp coordinates (u, v, w) of the roots
    std::vector<ScalpFrame> frames;  ///< #N root frames
    std::vector<float> lengths;      ///< #N arc lengths, world units

    std::size_t count() const { return roots.size(); }
    std::size_t dim() const { return std::size_t(3) * std::size_t(vertices); }
    const float* row(std::size_t s) const { return local.data() + s * dim(); }
    float* row(std::size_t s) { return local.data() + s * dim(); }
    /// Append one sample (its row copied from @a localRow).
    void push(const float* localRow, const Vec3d& root, const Vec3d& scalpCoord, const ScalpFrame& frame, float length);
};

/// @brief Resample and express every strand of @a strands in its root frame on @a map.
/// @param vertices n_s, at least 2
/// @param order null, or the strand each sample takes (sample i is strand (*order)[i]: a
/// permutation or any selection of strand indices, each less than the strand count)
/// @throw ValueError for fewer than 2 vertices, or a strand of fewer than two vertices (named).
StrandSamples sampleStrands(const StrandSet& strands, const ScalpMap& map, int vertices = StrandSamples::kDefaultVertices,
                            bool threaded = true, const std::vector<std::uint32_t>* order = nullptr);

/// @brief The L² distance of Wang et al. §4.1 between two sample rows of @a dim floats.
double sampleDistance2(const float* a, const float* b, std::size_t dim);

/// @brief World positions of a sample row: root + radius · frame · local, n_s points into @a out.
void sampleToWorld(const float* localRow, int vertices, const Vec3d& root, const ScalpFrame& frame, double radius,
                   Vec3f* out);

/// @brief All samples as world strands of n_s vertices each.
StrandSet samplesToStrands(const StrandSamples& samples, double radius, bool threaded = true);

} // namespace vdbhair
