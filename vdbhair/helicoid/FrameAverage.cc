#include "FrameAverage.h"

#include <cmath>

namespace vdbhair {

std::array<double, 4> frameToQuaternion(const FrameD& f)
{
    // Shepperd's method on the matrix with columns t, n, b (m[row][col]).
    const double m00 = f.t.x(), m10 = f.t.y(), m20 = f.t.z();
    const double m01 = f.n.x(), m11 = f.n.y(), m21 = f.n.z();
    const double m02 = f.b.x(), m12 = f.b.y(), m22 = f.b.z();
    const double tr = m00 + m11 + m22;
    std::array<double, 4> q;
    if (tr > 0.0) {
        const double s = 2.0 * std::sqrt(tr + 1.0);
        q = {0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s};
    } else if (m00 > m11 && m00 > m22) {
        const double s = 2.0 * std::sqrt(1.0 + m00 - m11 - m22);
        q = {(m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s};
    } else if (m11 > m22) {
        const double s = 2.0 * std::sqrt(1.0 + m11 - m00 - m22);
        q = {(m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s};
    } else {
        const double s = 2.0 * std::sqrt(1.0 + m22 - m00 - m11);
        q = {(m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s};
    }
    const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& c : q) c /= len;
    return q;
}

FrameD quaternionToFrame(const std::array<double, 4>& q)
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    FrameD f;
    f.t = Vec3d(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y));
    f.n = Vec3d(2.0 * (x * y - w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + w * x));
    f.b = f.t.cross(f.n);
    return f;
}

FrameD averageFrames(const std::vector<FrameD>& frames, const std::vector<GuideWeight>& weights)
{
    std::size_t heaviest = 0;
    for (std::size_t i = 1; i < weights.size(); ++i) {
        if (weights[i].weight > weights[heaviest].weight) heaviest = i;
    }
    const FrameD& h = frames[weights[heaviest].guide];
    if (weights.size() == 1) return h;
    const std::array<double, 4> qh = frameToQuaternion(h);
    std::array<double, 4> sum{0.0, 0.0, 0.0, 0.0};
    for (const GuideWeight& gw : weights) {
        const std::array<double, 4> q = frameToQuaternion(frames[gw.guide]);
        const double dot = q[0] * qh[0] + q[1] * qh[1] + q[2] * qh[2] + q[3] * qh[3];
        const double s = dot < 0.0 ? -gw.weight : gw.weight;
        for (int c = 0; c < 4; ++c) sum[std::size_t(c)] += s * q[std::size_t(c)];
    }
    const double len = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2] + sum[3] * sum[3]);
    if (!(len > 1e-9)) return h;
    for (double& c : sum) c /= len;
    return quaternionToFrame(sum);
}

FrameD relativeFrame(const FrameD& a, const FrameD& b)
{
    FrameD r;
    r.t = Vec3d(b.t.dot(a.t), b.n.dot(a.t), b.b.dot(a.t));
    r.n = Vec3d(b.t.dot(a.n), b.n.dot(a.n), b.b.dot(a.n));
    r.b = r.t.cross(r.n);
    return r;
}

FrameD composeFrames(const FrameD& b, const FrameD& r)
{
    FrameD f;
    f.t = r.t.x() * b.t + r.t.y() * b.n + r.t.z() * b.b;
    f.n = r.n.x() * b.t + r.n.y() * b.n + r.n.z() * b.b;
    f.b = f.t.cross(f.n);
    return f;
}

} // namespace vdbhair
