/// @file PointGrid.h
/// @brief A uniform grid over a set of points, built in linear time by a counting sort, for the
/// radius and nearest-point queries of the comparison measures (strands/Compare.h). A k-d tree
/// needs O(N log N) to build, single-threaded; this grid needs three passes over the points,
/// and a query that starts from a good bound (a strand's next vertex) visits a few cells.
#pragma once

#include <vdbhair/Types.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace vdbhair {

class PointGrid
{
public:
    /// @brief Index @a points (copied in cell order) in cells chosen so that there are about as
    /// many cells as points over their bounding box.
    /// @throw ValueError for more than 2^31 points.
    explicit PointGrid(const std::vector<Vec3f>& points, bool threaded = true);

    std::size_t size() const { return mIndex.size(); }
    double cellSize() const { return mCell; }
    /// The grid's box: from origin() over cellSize() times the cell counts (holds every point).
    const Vec3d& origin() const { return mOrigin; }
    Vec3d extent() const { return Vec3d(mDims[0], mDims[1], mDims[2]) * mCell; }

    /// @brief Calls @a visit(index, squared distance) for each point within @a radius of @a p (its
    /// index in the points given), cell by cell, until @a visit returns false.
    /// @return false when @a visit stopped the search.
    template <typename Visit>
    bool forEachWithin(const Vec3d& p, double radius, Visit&& visit) const
    {
        int lo[3], hi[3];
        if (!cellRange(p, radius, lo, hi)) return true;
        const double r2 = radius * radius;
        // Blocks of kBlock^3 cells without a point are skipped whole (a far query crosses many).
        for (int bz = lo[2] / kBlock; bz <= hi[2] / kBlock; ++bz) {
            for (int by = lo[1] / kBlock; by <= hi[1] / kBlock; ++by) {
                for (int bx = lo[0] / kBlock; bx <= hi[0] / kBlock; ++bx) {
                    if (!mBlock[std::size_t(bx) + std::size_t(mBlockDims[0]) * (std::size_t(by) + std::size_t(mBlockDims[1]) * std::size_t(bz))]) continue;
                    const int x0 = std::max(lo[0], bx * kBlock), x1 = std::min(hi[0], bx * kBlock + kBlock - 1);
                    for (int z = std::max(lo[2], bz * kBlock), z1 = std::min(hi[2], bz * kBlock + kBlock - 1); z <= z1; ++z) {
                        for (int y = std::max(lo[1], by * kBlock), y1 = std::min(hi[1], by * kBlock + kBlock - 1); y <= y1; ++y) {
                            // Cells x0..x1 of one row are consecutive in cell order: one run of points.
                            const std::size_t row = std::size_t(mDims[0]) * (std::size_t(y) + std::size_t(mDims[1]) * std::size_t(z));
                            for (std::uint32_t k = mStart[row + std::size_t(x0)], e = mStart[row + std::size_t(x1) + 1]; k < e; ++k) {
                                const Vec3f& q = mPoints[k];
                                const double dx = p.x() - double(q.x()), dy = p.y() - double(q.y()), dz = p.z() - double(q.z());
                                const double d2 = dx * dx + dy * dy + dz * dz;
                                if (d2 <= r2 && !visit(mIndex[k], d2)) return false;
                            }
                        }
                    }
                }
            }
        }
        return true;
    }

    /// @brief The point nearest @a p: its index, and its squared distance in @a d2. On entry @a d2
    /// is an upper bound known to the caller (the squared distance to some point of the set, or
    /// infinity); the smaller it is, the fewer cells are visited. Ties go to the smaller index.
    /// @return the index, or ~0u when the grid is empty.
    std::uint32_t nearest(const Vec3d& p, double& d2) const;

private:
    /// The cells a ball of @a radius around @a p overlaps, clipped to the grid; false when none.
    bool cellRange(const Vec3d& p, double radius, int lo[3], int hi[3]) const
    {
        for (int a = 0; a < 3; ++a) {
            const double l = std::floor((p[a] - radius - mOrigin[a]) / mCell), h = std::floor((p[a] + radius - mOrigin[a]) / mCell);
            if (!(h >= 0.0) || !(l < double(mDims[a]))) return false;
            lo[a] = l < 0.0 ? 0 : int(l);
            hi[a] = h >= double(mDims[a]) ? mDims[a] - 1 : int(h);
        }
        return true;
    }

    static constexpr int kBlock = 8;  ///< cells a block, along each axis

    Vec3d mOrigin{0.0};
    double mCell = 1.0;
    int mDims[3] = {0, 0, 0};
    std::vector<std::uint32_t> mStart;  ///< #cells + 1: the points of cell c are [mStart[c], mStart[c + 1])
    std::vector<Vec3f> mPoints;         ///< the points in cell order
    std::vector<std::uint32_t> mIndex;  ///< each one's index in the points given
    int mBlockDims[3] = {0, 0, 0};
    std::vector<std::uint8_t> mBlock;   ///< per block of kBlock^3 cells: whether one holds a point
};

} // namespace vdbhair
