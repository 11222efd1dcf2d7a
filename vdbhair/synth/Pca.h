/// @file Pca.h
/// @brief Principal component analysis of feature rows (Wang et al. 2009, §5.1: strands as
/// 3 n_s-vectors projected onto their first n_f = 16 principal components).
///
/// The covariance of the centred rows is accumulated in double in row order and diagonalized
/// with Eigen's SelfAdjointEigenSolver; components are sorted by decreasing variance and each is
/// signed so that its largest-magnitude coordinate is positive (a deterministic basis).
#pragma once

#include <cstddef>
#include <vector>

namespace vdbhair {

struct Pca
{
    static constexpr int kDefaultComponents = 16;  ///< n_f, Wang et al. §5.1

    std::size_t dim = 0;
    int components = 0;
    std::vector<double> mean;      ///< #dim
    std::vector<double> basis;     ///< #components × dim, row c is component c (unit)
    std::vector<double> variance;  ///< #components, decreasing
    double totalVariance = 0.0;    ///< of all dim components

    /// Coordinates of @a row (dim floats) on the basis: @a out gets `components` floats.
    void project(const float* row, float* out) const;
    /// The row of @a coords (components floats): mean + Σ coords_c basis_c, into @a out (dim floats).
    void reconstruct(const float* coords, float* out) const;
};

/// @brief PCA of @a n rows of @a dim floats (row-major) to min(@a components, dim) components.
/// @throw ValueError for no rows, dim 0 or components below 1.
Pca fitPca(const float* rows, std::size_t n, std::size_t dim, int components = Pca::kDefaultComponents);

} // namespace vdbhair
