#include "ShepardWeights.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/strands/PointCloud.h>

#include <algorithm>
#include <cmath>

namespace vdbhair {

struct GuideLocator::Tree
{
    PointCloud cloud;
    PointKdTree index;
    explicit Tree(const std::vector<Vec3d>* pts)
        : cloud{pts}, index(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10))
    {
        index.buildIndex();
    }
};

void validateShepardParams(const ShepardParams& params)
{
    if (!(params.power > 0.0) || !std::isfinite(params.power)) {
        throw ValueError("power " + formatNumber(params.power) + ": must be a positive finite exponent (the paper uses 3)");
    }
    if (params.neighbors == 0 || params.neighbors < -1) {
        throw ValueError("neighbors " + std::to_string(params.neighbors) + ": must be at least 1 (or every guide)");
    }
}

GuideLocator::GuideLocator(std::vector<Vec3d> roots) : mRoots(std::move(roots))
{
    if (mRoots.empty()) throw ValueError("no guides: interpolation needs at least one guide root");
    if (mRoots.size() > std::size_t(UINT32_MAX)) throw LimitError("more than 2^32 guides");
    for (std::size_t i = 0; i < mRoots.size(); ++i) {
        const Vec3d& r = mRoots[i];
        if (!std::isfinite(r.x()) || !std::isfinite(r.y()) || !std::isfinite(r.z())) {
            throw ValueError("guide " + std::to_string(i) + ": root is not finite");
        }
    }
    mTree = std::make_unique<Tree>(&mRoots);
}

GuideLocator::~GuideLocator() = default;

void GuideLocator::knn(const Vec3d& x, std::size_t k, std::vector<std::uint32_t>& idx, std::vector<double>& d2) const
{
    k = std::min(k, mRoots.size());
    idx.resize(k);
    d2.resize(k);
    const double q[3] = {x.x(), x.y(), x.z()};
    const std::size_t found = mTree->index.knnSearch(q, k, idx.data(), d2.data());
    idx.resize(found);
    d2.resize(found);
}

std::uint32_t GuideLocator::nearest(const Vec3d& x) const
{
    std::vector<std::uint32_t> idx;
    std::vector<double> d2;
    knn(x, 1, idx, d2);
    return idx.front();
}

void GuideLocator::shepardWeights(const Vec3d& x, const ShepardParams& params, std::vector<GuideWeight>& out) const
{
    out.clear();
    thread_local std::vector<std::uint32_t> idx;
    thread_local std::vector<double> d2;
    if (params.neighbors < 0 || std::size_t(params.neighbors) >= mRoots.size()) {
        idx.resize(mRoots.size());
        d2.resize(mRoots.size());
        for (std::size_t i = 0; i < mRoots.size(); ++i) {
            idx[i] = std::uint32_t(i);
            d2[i] = (x - mRoots[i]).lengthSqr();
        }
    } else {
        knn(x, std::size_t(params.neighbors), idx, d2);
    }
    // A coincident root reproduces its guide exactly.
    for (std::size_t i = 0; i < idx.size(); ++i) {
        if (d2[i] == 0.0) {
            std::uint32_t first = idx[i];
            for (std::size_t j = i; j < idx.size(); ++j) if (d2[j] == 0.0) first = std::min(first, idx[j]);
            out.push_back({first, 1.0});
            return;
        }
    }
    // φ_i = d_i^-p, scaled by d_min^p so the nearest has φ = 1 (no overflow for tiny distances).
    double dmin2 = d2[0];
    for (double v : d2) dmin2 = std::min(dmin2, v);
    const double halfP = 0.5 * params.power;
    double sum = 0.0;
    out.resize(idx.size());
    for (std::size_t i = 0; i < idx.size(); ++i) {
        const double phi = std::pow(dmin2 / d2[i], halfP);
        out[i] = {idx[i], phi};
        sum += phi;
    }
    for (GuideWeight& g : out) g.weight /= sum;
}

void GuideLocator::fadedWeights(const Vec3d& x, int k, std::vector<GuideWeight>& out) const
{
    if (k < 1) throw ValueError("neighbors " + std::to_string(k) + ": must be at least 1");
    out.clear();
    thread_local std::vector<std::uint32_t> idx;
    thread_local std::vector<double> d2;
    const bool extra = mRoots.size() > std::size_t(k);
    knn(x, std::size_t(k) + (extra ? 1 : 0), idx, d2);
    for (std::size_t i = 0; i < idx.size(); ++i) {
        if (d2[i] == 0.0) {
            out.push_back({idx[i], 1.0});
            return;
        }
    }
    const double dmax = std::sqrt(d2.back());
    double sum = 0.0;
    for (std::size_t i = 0; i < idx.size(); ++i) {
        const double d = std::sqrt(d2[i]);
        const double w = extra ? (dmax - d) / d : 1.0 / d;
        if (w > 0.0) {
            out.push_back({idx[i], w});
            sum += w;
        }
    }
    if (out.empty()) {  // every neighbour at the same distance: equal weights over the K nearest
        for (std::size_t i = 0; i < std::min<std::size_t>(idx.size(), std::size_t(k)); ++i) out.push_back({idx[i], 1.0});
        sum = double(out.size());
    }
    for (GuideWeight& g : out) g.weight /= sum;
}

} // namespace vdbhair
