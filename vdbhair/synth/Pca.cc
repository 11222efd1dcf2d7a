#include "Pca.h"

#include <vdbhair/Exceptions.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <string>

namespace vdbhair {

Pca fitPca(const float* rows, std::size_t n, std::size_t dim, int components)
{
    if (n == 0 || dim == 0 || components < 1)
        throw ValueError("fitPca: " + std::to_string(n) + " rows of " + std::to_string(dim) + " values to " +
                         std::to_string(components) + " components: at least one row, one value and one component");
    Pca pca;
    pca.dim = dim;
    pca.components = int(std::min<std::size_t>(std::size_t(components), dim));
    // Mean and covariance, summed in row order in double.
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(Eigen::Index(dim));
    for (std::size_t r = 0; r < n; ++r)
        for (std::size_t i = 0; i < dim; ++i) mean[Eigen::Index(i)] += rows[r * dim + i];
    mean /= double(n);
    Eigen::MatrixXd centred(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(dim));
    for (std::size_t r = 0; r < n; ++r)
        for (std::size_t i = 0; i < dim; ++i) centred(Eigen::Index(r), Eigen::Index(i)) = rows[r * dim + i] - mean[Eigen::Index(i)];
    const Eigen::MatrixXd cov = (centred.transpose() * centred) / double(n);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
    const Eigen::VectorXd values = eig.eigenvalues();  // ascending
    const Eigen::MatrixXd vectors = eig.eigenvectors();
    pca.mean.assign(mean.data(), mean.data() + dim);
    pca.totalVariance = std::max(0.0, values.sum());
    pca.basis.assign(std::size_t(pca.components) * dim, 0.0);
    pca.variance.assign(std::size_t(pca.components), 0.0);
    for (int c = 0; c < pca.components; ++c) {
        const Eigen::Index col = Eigen::Index(dim) - 1 - c;
        Eigen::VectorXd v = vectors.col(col);
        Eigen::Index big = 0;
        v.cwiseAbs().maxCoeff(&big);
        if (v[big] < 0.0) v = -v;
        pca.variance[std::size_t(c)] = std::max(0.0, values[col]);
        std::copy(v.data(), v.data() + dim, pca.basis.begin() + std::ptrdiff_t(std::size_t(c) * dim));
    }
    return pca;
}

void Pca::project(const float* row, float* out) const
{
    for (int c = 0; c < components; ++c) {
        const double* b = basis.data() + std::size_t(c) * dim;
        double s = 0.0;
        for (std::size_t i = 0; i < dim; ++i) s += (row[i] - mean[i]) * b[i];
        out[c] = float(s);
    }
}

void Pca::reconstruct(const float* coords, float* out) const
{
    for (std::size_t i = 0; i < dim; ++i) {
        double s = mean[i];
        for (int c = 0; c < components; ++c) s += double(coords[c]) * basis[std::size_t(c) * dim + i];
        out[i] = float(s);
    }
}

} // namespace vdbhair
