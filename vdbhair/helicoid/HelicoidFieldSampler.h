/// @file HelicoidFieldSampler.h
/// @brief The streamline engine's sampler (field/Streamline.h) for a helicoid field (a helicoid
/// per active voxel, HelicoidField.h).
#pragma once

#include <vdbhair/field/SegmentWalk.h>
#include <vdbhair/field/Streamline.h>
#include <vdbhair/helicoid/Helicoid.h>
#include <vdbhair/helicoid/HelicoidField.h>

#include <openvdb/tree/ValueAccessor.h>

namespace vdbhair {

/// @brief The direction of a helicoid field at a world point: each active corner of the sampling
/// cell predicts a direction by evaluating its own helicoid (the exact Eq. 1, origin at the voxel
/// centre, theta not unwrapped: the corners lie within a voxel of their origins) at that point;
/// the predictions are blended with trilinear weights and normalized. Left where no corner is
/// active, Vanished where the blend is no longer than @a vanishThreshold times the corners' weight.
/// @warning Not thread-safe (it owns accessors): one per thread.
class HelicoidFieldSampler
{
public:
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
            const double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
            if (w <= 0.0) continue;
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
