/// @file HelicoidFieldSampler.h
/// @brief The streamline engine's sampler (field/Streamline.h) for a helicoid field (a helicoid
/// per active voxel, HelicoidField.h).
#pragma once

#include <vdbhair/SegmentWalk.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/HelicoidField.h>

#include <openvdb/tree/ValueAccessor.h>

namespace vdbhair {

/// @brief The direction of a helicoid field at a world point: each active corner of the sampling
/// cell predicts a direction by evaluating its own helicoid (the exact Eq. 1, origin at the voxel
/// centre, theta not unwrapped: the corners lie within a voxel of their origins) at that point;
/// the predictions are blended with the trilinear weights raised to kCornerSharpness and
/// normalized, so that near a voxel's centre its own helicoid decides (each is fitted to the
/// strands around that centre; an even trilinear blend of eight helicoids that disagree in phase
/// averages the curl away). Left where no corner is active, Vanished where the blend is no longer
/// than @a vanishThreshold times the corners' weight.
/// @warning Not thread-safe (it owns accessors): one per thread.
class HelicoidFieldSampler
{
public:
    /// The power of the trilinear corner weights. Measured on the benchmark's helicoid-field
    /// section (issue 19, RK4 for both fields; accuracy over the tangent field's at 1, 2 and 4
    /// times the suggested voxel): power 1 (plain trilinear) Curly_100 1.19 / 1.04 / 1.08x, Fig. 5
    /// 1.12 / 1.25 / 1.42x; power 2: 1.22 / 1.02 / 1.09x and 1.19 / 1.39 / 1.52x; 4: 1.25 / 1.03 /
    /// 1.11x and 1.22 / 1.39 / 1.63x; 8: 1.29 / 1.03 / 1.08x and 1.25 / 1.39 / 1.73x; 30: 1.31 /
    /// 1.07 / 1.06x and 1.23 / 1.47 / 1.67x. docs/helicoids.md, "Helicoid fields in VDB".
    static constexpr int kCornerSharpness = 8;

    HelicoidFieldSampler(const HelicoidFieldGrids& f, double vanishThreshold)
        : mK(f.k->tree()), mA(f.alpha->tree()), mT(f.frameT->tree()), mN(f.frameN->tree()),
          mInv(1.0 / f.k->voxelSize().x()), mH(f.k->voxelSize().x()), mOff(f.k->transform().indexToWorld(Vec3d(0.0))),
          mThreshold(vanishThreshold) {}

    SampleStatus direction(const Vec3d& worldPos, Vec3d& unitDir)
    {
        const Vec3d ip = (worldPos - mOff) * mInv;
        const int bx = floorToInt(ip.x()), by = floorToInt(ip.y()), bz = floorToInt(ip.z());
        const double fx = ip.x() - bx, fy = ip.y() - by, fz = ip.z() - bz;
        Vec3d sum(0.0);
        double active = 0.0;
        for (int i = 0; i < 8; ++i) {
            const int dx = i >> 2, dy = (i >> 1) & 1, dz = i & 1;
            const openvdb::Coord c(bx + dx, by + dy, bz + dz);
            openvdb::Vec3f k;
            if (!mK.probeValue(c, k)) continue;
            const double w1 = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
            if (w1 <= 0.0) continue;
            const double w2 = w1 * w1, w4 = w2 * w2, w = w4 * w4;
            static_assert(kCornerSharpness == 8, "the weight above is w1^8");
            Helicoid hel;
            hel.k = {k.x(), k.y(), k.z(), mA.getValue(c)};
            const Vec3d t(mT.getValue(c)), n(mN.getValue(c));
            if (!(t.lengthSqr() > 0.0)) continue;
            hel.q.t = t;
            hel.q.n = n;
            hel.q.b = t.cross(n);
            hel.p0 = mOff + c.asVec3d() * mH;
            double th = 0.0;
            sum += w * hel.tangent(worldPos, th);
            active += w;
        }
        if (!(active > 0.0)) return SampleStatus::Left;
        const double len = sum.length();
        if (!(len > mThreshold * active)) return SampleStatus::Vanished;
        unitDir = sum / len;
        return SampleStatus::Ok;
    }

private:
    openvdb::tree::ValueAccessor<const openvdb::Vec3STree> mK;
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> mA;
    openvdb::tree::ValueAccessor<const openvdb::Vec3STree> mT, mN;
    double mInv, mH;
    Vec3d mOff;
    double mThreshold;
};

} // namespace vdbhair
