#include "DetailTransfer.h"

#include <vdbhair/Memory.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/scalp/PointCloud.h>
#include <vdbhair/strands/Frames.h>

#include <vdbhair/Parallel.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace vdbhair {

DetailBlend detailBlendFromName(const std::string& name)
{
    if (name == "root-frame") return DetailBlend::RootFrame;
    if (name == "paper") return DetailBlend::Paper;
    throw ValueError("detail blend '" + name + "' is not one of root-frame, paper");
}

const char* detailBlendName(DetailBlend blend) { return blend == DetailBlend::Paper ? "paper" : "root-frame"; }

DetailScale detailScaleFromName(const std::string& name)
{
    if (name == "index") return DetailScale::Index;
    if (name == "arc-length") return DetailScale::ArcLength;
    throw ValueError("detail scale '" + name + "' is not one of index, arc-length");
}

const char* detailScaleName(DetailScale scale) { return scale == DetailScale::ArcLength ? "arc-length" : "index"; }

ScalpFrame alignedFrame(const float* row, int vertices, const ScalpFrame& f)
{
    // v_g in root-frame coordinates (root at 0), projected onto the tangent plane (x, z).
    double x = 0.0, z = 0.0;
    for (int l = 1; l < vertices; ++l) {
        x += row[3 * l];
        z += row[3 * l + 2];
    }
    const double len = std::hypot(x, z);
    if (len < 1e-12) return f;
    const double c = x / len, s = z / len;
    ScalpFrame a;
    a.n = f.n;
    a.t = f.t * c + f.b * s;
    a.b = a.t.cross(a.n);
    return a;
}

namespace {

/// Row @a row of a sample re-expressed in @a to (from its root frame @a from).
void reexpress(const float* row, int vertices, const ScalpFrame& from, const ScalpFrame& to, float* out)
{
    for (int l = 0; l < vertices; ++l) {
        const Vec3d w = from.toWorld(Vec3d(row[3 * l], row[3 * l + 1], row[3 * l + 2]));
        const Vec3d q = to.toLocal(w);
        out[3 * l] = float(q.x());
        out[3 * l + 1] = float(q.y());
        out[3 * l + 2] = float(q.z());
    }
}

/// Row @a row of @a from vertices at @a to vertices, linearly between vertices at the same fraction
/// of the vertices (the samples are even in arc length); a copy when the counts agree.
void resampleRow(const float* row, int from, int to, float* out)
{
    if (from == to) {
        std::copy(row, row + 3 * from, out);
        return;
    }
    for (int k = 0; k < to; ++k) {
        const double x = double(k) * double(from - 1) / double(to - 1);
        const int j = std::min(int(x), from - 1);
        const double t = x - double(j);
        for (int c = 0; c < 3; ++c)
            out[3 * k + c] = j + 1 < from && t > 0.0 ? float(row[3 * j + c] * (1.0 - t) + row[3 * (j + 1) + c] * t) : row[3 * j + c];
    }
}

std::vector<Vec3f> worldOf(const StrandSamples& s, std::size_t i, double radius)
{
    std::vector<Vec3f> p(std::size_t(s.vertices));
    sampleToWorld(s.row(i), s.vertices, s.roots[i], s.frames[i], radius, p.data());
    return p;
}

} // namespace

StrandSamples transferDetail(const TransferSource& source, const StrandSamples& outCenters,
                             const std::vector<Vec3d>& roots, const ScalpMap& map, int components,
                             std::vector<std::uint32_t>* outLabel, TransferStats* stats, DetailBlend blend, bool threaded,
                             openvdb::util::NullInterrupter* interrupter, const std::vector<std::uint32_t>* givenLabel,
                             DetailScale scale, int outVertices)
{
    if (!source.strands || !source.centers || !source.label || source.strands->count() == 0 ||
        source.centers->count() == 0 || source.label->size() != source.strands->count())
        throw ValueError("transferDetail: the input level is incomplete or empty");
    if (outCenters.count() == 0) throw ValueError("transferDetail: no coarser output strands to transfer onto");
    const StrandSamples& inS = *source.strands;
    const StrandSamples& inC = *source.centers;
    const int ns = inS.vertices, nc = outCenters.vertices, no = outVertices > 0 ? outVertices : nc;
    if (inC.vertices != ns)
        throw ValueError("transferDetail: the input levels have different vertex counts per strand");
    if (ns < 2 || nc < 2 || no < 2) throw ValueError("transferDetail: strands need at least 2 vertices");
    const std::size_t dim = inS.dim(), nIn = inC.count(), nOut = outCenters.count(), n = roots.size();
    const double radius = map.radius();
    const auto forEach = [&](std::size_t count, auto&& fn) { forEachIndex(count, threaded, fn, 64); };

    // 1. Output clusters: each new root joins the nearest coarser output root (or its given centre).
    std::vector<std::uint32_t> label(n, 0);
    if (givenLabel) {
        if (givenLabel->size() != n)
            throw ValueError("transferDetail: " + std::to_string(givenLabel->size()) + " given centres for " + std::to_string(n) + " roots");
        for (std::uint32_t c : *givenLabel)
            if (c >= nOut) throw ValueError("transferDetail: given centre " + std::to_string(c) + " of " + std::to_string(nOut));
        label = *givenLabel;
    } else {
        PointCloud cloud{&outCenters.roots};
        PointKdTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
        tree.buildIndex();
        forEach(n, [&](std::size_t i) {
            std::uint32_t idx;
            double d2;
            const double q[3] = {roots[i].x(), roots[i].y(), roots[i].z()};
            tree.knnSearch(q, 1, &idx, &d2);
            label[i] = idx;
        });
    }
    // 2. Aligned frames of every centre and their rows in them.
    std::vector<ScalpFrame> inAligned(nIn), outAligned(nOut);
    std::vector<float> rows((nIn + nOut) * dim);
    forEach(nIn, [&](std::size_t c) {
        inAligned[c] = alignedFrame(inC.row(c), ns, inC.frames[c]);
        reexpress(inC.row(c), ns, inC.frames[c], inAligned[c], rows.data() + c * dim);
    });
    forEach(nOut, [&](std::size_t c) {
        // Compared at the input's n_s vertices (the same row when the counts agree).
        std::vector<float> row(dim);
        resampleRow(outCenters.row(c), nc, ns, row.data());
        outAligned[c] = alignedFrame(row.data(), ns, outCenters.frames[c]);
        reexpress(row.data(), ns, outCenters.frames[c], outAligned[c], rows.data() + (nIn + c) * dim);
    });
    // 3. Matching clusters through PCA features of both sets of centres.
    const Pca pca = fitPca(rows.data(), nIn + nOut, dim, components);
    const int nf = pca.components;
    std::vector<float> feat((nIn + nOut) * std::size_t(nf));
    forEach(nIn + nOut, [&](std::size_t r) { pca.project(rows.data() + r * dim, feat.data() + r * std::size_t(nf)); });
    std::vector<std::uint32_t> match(nOut, 0);
    forEach(nOut, [&](std::size_t c) {
        const float* f = feat.data() + (nIn + c) * std::size_t(nf);
        double best = std::numeric_limits<double>::max();
        for (std::size_t j = 0; j < nIn; ++j) {
            const double d = sampleDistance2(f, feat.data() + j * std::size_t(nf), std::size_t(nf));
            if (d < best) {
                best = d;
                match[c] = std::uint32_t(j);
            }
        }
    });
    if (interrupter && interrupter->wasInterrupted()) throw InterruptedError("detail transfer interrupted");
    // Members of each input cluster.
    std::vector<std::vector<std::uint32_t>> members(nIn);
    for (std::uint32_t s = 0; s < inS.count(); ++s) members[(*source.label)[s]].push_back(s);
    // World geometry and rotation-minimizing frames of the centres used, computed once each.
    std::vector<std::vector<Vec3f>> outWorld(nOut), inWorld(nIn);
    std::vector<std::vector<Frame>> outRmf(nOut), inRmf(nIn);
    std::vector<std::uint8_t> inUsed(nIn, 0), outUsed(nOut, 0);
    for (std::uint32_t l : label) outUsed[l] = 1;
    for (std::size_t c = 0; c < nOut; ++c)
        if (outUsed[c]) inUsed[match[c]] = 1;
    // (The output centres at the output's vertex count.)
    const auto prepare = [&](const StrandSamples& s, std::size_t i, const ScalpFrame& aligned, int vertices,
                             std::vector<Vec3f>& world, std::vector<Frame>& rmf) {
        std::vector<float> row(std::size_t(3 * vertices));
        resampleRow(s.row(i), s.vertices, vertices, row.data());
        world.resize(std::size_t(vertices));
        sampleToWorld(row.data(), vertices, s.roots[i], s.frames[i], radius, world.data());
        rmf.resize(std::size_t(vertices));
        parallelTransportFrames(world.data(), world.size(), Vec3f(aligned.t), rmf.data());
    };
    forEach(nIn, [&](std::size_t c) { if (inUsed[c]) prepare(inC, c, inAligned[c], ns, inWorld[c], inRmf[c]); });
    forEach(nOut, [&](std::size_t c) { if (outUsed[c]) prepare(outCenters, c, outAligned[c], no, outWorld[c], outRmf[c]); });

    // 4-5. Every new strand.
    StrandSamples out;
    out.vertices = no;
    reserveHugePages(out.local, n * out.dim());  // fresh pages 2 MiB at a time (Memory.h)
    out.local.assign(n * out.dim(), 0.0f);
    out.roots = roots;
    out.scalp.resize(n);
    out.frames.resize(n);
    out.lengths.resize(n);
    forEach(n, [&](std::size_t i) {
        const std::uint32_t oc = label[i], ic = match[oc];
        const ScalpFrame& mo = outAligned[oc];
        const ScalpFrame& mi = inAligned[ic];
        // 4. The input member whose root offset (aligned frame) is nearest to ours.
        const Vec3d offOut = mo.toLocal(roots[i] - outCenters.roots[oc]);
        std::uint32_t pick = 0;
        double best = std::numeric_limits<double>::max();
        for (std::uint32_t m : members[ic]) {
            const double d = (mi.toLocal(inS.roots[m] - inC.roots[ic]) - offOut).lengthSqr();
            if (d < best) {
                best = d;
                pick = m;
            }
        }
        const std::vector<Vec3f> gin = worldOf(inS, pick, radius);
        const std::vector<Vec3f>& cin = inWorld[ic];
        const std::vector<Vec3f>& cout = outWorld[oc];
        const std::vector<Frame>& fin = inRmf[ic];
        const std::vector<Frame>& fout = outRmf[oc];
        // 5. Eq. 5-8.
        const auto inFrame = [&](const Frame& f, const Vec3d& w) { return Vec3d(f.t.dot(Vec3f(w)), f.n.dot(Vec3f(w)), f.b.dot(Vec3f(w))); };
        const auto outOf = [&](const Frame& f, const Vec3d& d) { return Vec3d(f.t) * d.x() + Vec3d(f.n) * d.y() + Vec3d(f.b) * d.z(); };
        const Vec3d rootIn = Vec3d(gin[0]) - Vec3d(cin[0]);
        const Vec3d betaShift = roots[i] - Vec3d(cout[0]) - outOf(fout[0], inFrame(fin[0], rootIn));
        const Vec3d sc = map.toScalp(roots[i]);
        const ScalpFrame rf = map.frame(sc.x(), sc.y());
        // Eq. 5-6 per vertex of the input pair.
        std::vector<Vec3d> dA(static_cast<std::size_t>(ns)), dB(static_cast<std::size_t>(ns));
        for (int l = 0; l < ns; ++l) {
            const Vec3d dIn = Vec3d(gin[std::size_t(l)]) - Vec3d(cin[std::size_t(l)]);
            dA[std::size_t(l)] = mi.toLocal(dIn - rootIn);                          // Eq. 5
            dB[std::size_t(l)] = inFrame(fin[std::size_t(l)], dIn);                 // Eq. 6
        }
        // Where each output vertex reads the input's displacement: a fractional input vertex.
        std::vector<double> at(static_cast<std::size_t>(no));
        if (scale == DetailScale::ArcLength) {
            // At the output centre's arc length along the input centre, mirrored back and forth
            // beyond the input centre's end (DetailTransfer.h).
            const auto arcs = [&](const std::vector<Vec3f>& c) {
                std::vector<double> a(c.size(), 0.0);
                for (std::size_t k = 1; k < c.size(); ++k) a[k] = a[k - 1] + (Vec3d(c[k]) - Vec3d(c[k - 1])).length();
                return a;
            };
            const std::vector<double> ai = arcs(cin), ao = arcs(cout);
            const double Li = ai.back();
            for (std::size_t k = 0; k < at.size(); ++k) {
                double a = ao[k];
                if (Li > 0.0) {
                    a = std::fmod(a, 2.0 * Li);
                    if (a > Li) a = 2.0 * Li - a;
                }
                const std::size_t j = std::size_t(std::upper_bound(ai.begin(), ai.end(), a) - ai.begin());
                if (j == 0) at[k] = 0.0;
                else if (j >= ai.size()) at[k] = double(ns - 1);
                else at[k] = double(j - 1) + (ai[j] > ai[j - 1] ? (a - ai[j - 1]) / (ai[j] - ai[j - 1]) : 0.0);
            }
        } else {
            // Vertex by vertex (the same fraction of the vertices).
            for (std::size_t k = 0; k < at.size(); ++k) at[k] = double(k) * double(ns - 1) / double(no - 1);
        }
        const auto read = [&](const std::vector<Vec3d>& d) {
            std::vector<Vec3d> r(at.size());
            for (std::size_t k = 0; k < at.size(); ++k) {
                const std::size_t j = std::min(std::size_t(at[k]), std::size_t(ns - 1));
                const double t = at[k] - double(j);
                r[k] = j + 1 < std::size_t(ns) && t > 0.0 ? d[j] * (1.0 - t) + d[j + 1] * t : d[j];
            }
            return r;
        };
        dA = read(dA);
        dB = read(dB);
        float* row = out.row(i);
        double len = 0.0;
        Vec3d prev = roots[i];
        for (int l = 0; l < no; ++l) {
            const Vec3d& dAlpha = dA[std::size_t(l)];
            const Vec3d& dBeta = dB[std::size_t(l)];
            const Vec3d a = roots[i] + (Vec3d(cout[std::size_t(l)]) - Vec3d(cout[0])) + mo.toWorld(dAlpha);  // Eq. 8
            const Vec3d b = Vec3d(cout[std::size_t(l)]) + outOf(fout[std::size_t(l)], dBeta) + betaShift;
            const double s = blend == DetailBlend::RootFrame ? 0.0 : double(l) / double(no - 1);
            const Vec3d p = l == 0 ? roots[i] : a * (1.0 - s) + b * s;             // Eq. 7
            const Vec3d q = rf.toLocal((p - roots[i]) / radius);
            row[3 * l] = float(q.x());
            row[3 * l + 1] = float(q.y());
            row[3 * l + 2] = float(q.z());
            len += (p - prev).length();
            prev = p;
        }
        out.scalp[i] = sc;
        out.frames[i] = rf;
        out.lengths[i] = float(len);
    });
    if (outLabel) *outLabel = label;
    if (stats) {
        stats->clusters = 0;
        for (std::uint8_t u : outUsed) stats->clusters += u;
        stats->distinctSources = 0;
        for (std::uint8_t u : inUsed) stats->distinctSources += u;
    }
    return out;
}

} // namespace vdbhair
