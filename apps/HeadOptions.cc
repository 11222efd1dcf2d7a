#include "HeadOptions.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/scalp/HeadFile.h>
#include <vdbhair/strands/PointCloud.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace vdbhair::app {

void addHeadOptions(CLI::App* sub, HeadOptions& o, const HeadPolicy& policy, const std::string& fallback)
{
    o.policy = &policy;
    sub->add_option("--head", o.path, "The head strands may not enter: a triangle mesh (.ply, .obj), a .vdb with a level set grid "
                                      "('surface' or the first one), or 'none' (default: " + fallback + ")");
}

HeadObstacle headFromOptions(const HeadOptions& o, const HeadObstacle& fallback)
{
    if (o.path == "none") return HeadObstacle::none();
    if (!o.path.empty()) return readHeadObstacle(o.path, "--head " + o.path, o.headPolicy());
    return fallback;
}

SurfaceDistanceFn headSurfaceDistance(const std::string& path)
{
    const std::string ext = fileExtension(path);
    if (ext == ".ply" || ext == ".obj") {
        // The tree and its points live as long as the function (shared: std::function copies).
        struct Nearest
        {
            std::vector<Vec3d> pts;
            PointCloud cloud{&pts};
            std::unique_ptr<PointKdTree> tree;
        };
        auto n = std::make_shared<Nearest>();
        for (const Vec3f& v : readTriangleMesh(path).vertices) n->pts.emplace_back(v.x(), v.y(), v.z());
        if (n->pts.empty()) throw FormatError("--head " + path + ": the mesh has no vertices");
        n->tree = std::make_unique<PointKdTree>(3, n->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
        n->tree->buildIndex();
        return [n](const Vec3f& p) {
            const double q[3] = {p.x(), p.y(), p.z()};
            std::uint32_t index = 0;
            double d2 = 0.0;
            n->tree->knnSearch(q, 1, &index, &d2);
            return std::sqrt(d2);
        };
    }
    auto head = std::make_shared<HeadObstacle>(readHeadObstacle(path, "--head " + path));
    auto probe = std::make_shared<HeadObstacle::Probe>(*head);  // one thread: readStrands() calls it in order
    // Within the level set's band (its background, read far outside): its depth runs through the
    // whole interior, and a root deep inside is no farther from the scalp for this vote than one
    // at the band's edge, as a point far outside is not.
    const double band = probe->distance(head->center() + Vec3d(1e9, 0.0, 0.0));
    return [head, probe, band](const Vec3f& p) { return std::min(band, std::abs(probe->distance(Vec3d(p.x(), p.y(), p.z())))); };
}

} // namespace vdbhair::app
