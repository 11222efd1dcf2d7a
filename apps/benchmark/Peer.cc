// vdbhair_peer: what a user would write with stock OpenVDB and no vdbhair, the peer of the
// benchmark's end-to-end section (vdbhair_benchmark --sections e2e). It reads and writes
// USC-HairSalon `.data` files with an ifstream loop and uses OpenVDB's own tools, the same
// operations as the benchmark's library rows:
//
//   vdbhair_peer info IN.data                              strand and vertex counts, bounding box, lengths
//   vdbhair_peer field IN.data -o OUT.vdb --voxel-size H   per-vertex tangents splatted with
//                                                          points::rasterizeTrilinear into 'tangent'
//   vdbhair_peer retrace IN.data --field F.vdb -o OUT.data tools::VelocityIntegrator (RK1, step H/2)
//                                                          from each root for the strand's length,
//                                                          a vertex at each input arc length
//   vdbhair_peer refine IN.data -o OUT.data --voxel-size H field, then retrace, in one process
//   vdbhair_peer --help
//
// Deliberately plain: no vdbhair code, no special memory handling, default OpenVDB settings.
#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointRasterizeTrilinear.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tools/VelocityFields.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using openvdb::Vec3f;

struct Strands
{
    std::vector<Vec3f> positions;
    std::vector<std::uint32_t> offsets{0};
    std::size_t size() const { return offsets.size() - 1; }
};

Strands readData(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::int32_t nS = 0;
    in.read(reinterpret_cast<char*>(&nS), 4);
    Strands s;
    for (std::int32_t i = 0; in && i < nS; ++i) {
        std::int32_t nV = 0;
        in.read(reinterpret_cast<char*>(&nV), 4);
        std::vector<Vec3f> v(std::size_t(std::max(nV, 0)));
        in.read(reinterpret_cast<char*>(v.data()), std::streamsize(12 * v.size()));
        if (nV < 2) continue;
        s.positions.insert(s.positions.end(), v.begin(), v.end());
        s.offsets.push_back(std::uint32_t(s.positions.size()));
    }
    if (!in) throw std::runtime_error(path + ": truncated");
    return s;
}

void writeData(const std::string& path, const Strands& s)
{
    std::ofstream out(path, std::ios::binary);
    const std::int32_t nS = std::int32_t(s.size());
    out.write(reinterpret_cast<const char*>(&nS), 4);
    for (std::size_t i = 0; i < s.size(); ++i) {
        const std::int32_t nV = std::int32_t(s.offsets[i + 1] - s.offsets[i]);
        out.write(reinterpret_cast<const char*>(&nV), 4);
        out.write(reinterpret_cast<const char*>(&s.positions[s.offsets[i]]), 12 * nV);
    }
    if (!out) throw std::runtime_error("cannot write " + path);
}

openvdb::Vec3SGrid::Ptr field(const Strands& s, double voxelSize)
{
    namespace pts = openvdb::points;
    std::vector<Vec3f> tangents(s.positions.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        const std::uint32_t b = s.offsets[i], e = s.offsets[i + 1];
        for (std::uint32_t k = b; k < e; ++k) {
            Vec3f t = s.positions[std::min(k + 1, e - 1)] - s.positions[k > b ? k - 1 : b];
            tangents[k] = t.normalize() ? t : Vec3f(0.f);
        }
    }
    const auto xform = openvdb::math::Transform::createLinearTransform(voxelSize);
    const pts::PointAttributeVector<Vec3f> pw(s.positions);
    auto index = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(pw, *xform);
    auto points = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(*index, pw, *xform);
    pts::appendAttribute<Vec3f>(points->tree(), "T");
    pts::populateAttribute(points->tree(), index->tree(), "T", pts::PointAttributeVector<Vec3f>(tangents));
    auto grid = openvdb::Vec3SGrid::create(pts::rasterizeTrilinear<false, Vec3f>(points->tree(), "T"));
    grid->setTransform(xform);
    grid->setName("tangent");
    return grid;
}

Strands retrace(const Strands& s, const openvdb::Vec3SGrid& grid)
{
    const double step = 0.5 * grid.voxelSize()[0];
    Strands out;
    out.positions.resize(s.positions.size());
    out.offsets = s.offsets;
    tbb::enumerable_thread_specific<openvdb::tools::VelocityIntegrator<openvdb::Vec3SGrid>> integrators(grid);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
        auto& integ = integrators.local();
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::uint32_t b = s.offsets[i], e = s.offsets[i + 1];
            openvdb::Vec3d p(s.positions[b]);
            out.positions[b] = s.positions[b];
            double arc = 0.0, traced = 0.0;
            for (std::uint32_t k = b + 1; k < e; ++k) {
                arc += (s.positions[k] - s.positions[k - 1]).length();
                for (; traced + 0.5 * step < arc; traced += step) integ.rungeKutta<1>(step, p);
                out.positions[k] = Vec3f(p);
            }
        }
    });
    return out;
}

void writeGrid(const std::string& path, const openvdb::GridBase::Ptr& grid)
{
    openvdb::io::File(path).write({grid});
}

std::string option(int argc, char** argv, const char* name)
{
    for (int i = 2; i + 1 < argc; ++i) if (std::strcmp(argv[i], name) == 0) return argv[i + 1];
    throw std::runtime_error(std::string("missing ") + name);
}

} // namespace

int main(int argc, char** argv)
{
    const std::string verb = argc > 1 ? argv[1] : "--help";
    if (verb == "--help" || verb == "-h" || argc < 3) {
        std::cout << "usage: vdbhair_peer info|field|retrace|refine IN.data [-o OUT] [--field F.vdb] [--voxel-size H]\n";
        return argc < 3 && verb != "--help" && verb != "-h" ? 1 : 0;
    }
    try {
        openvdb::initialize();
        const Strands s = readData(argv[2]);
        if (verb == "info") {
            Vec3f lo(1e30f), hi(-1e30f);
            double total = 0.0;
            for (const Vec3f& p : s.positions) { lo = openvdb::math::minComponent(lo, p); hi = openvdb::math::maxComponent(hi, p); }
            for (std::size_t i = 0; i < s.size(); ++i) {
                for (std::uint32_t k = s.offsets[i] + 1; k < s.offsets[i + 1]; ++k) total += (s.positions[k] - s.positions[k - 1]).length();
            }
            std::cout << s.size() << " strands, " << s.positions.size() << " vertices, mean length "
                      << total / double(std::max<std::size_t>(1, s.size())) << ", bbox " << lo << " .. " << hi << "\n";
        } else if (verb == "field") {
            writeGrid(option(argc, argv, "-o"), field(s, std::stod(option(argc, argv, "--voxel-size"))));
        } else if (verb == "retrace") {
            openvdb::io::File file(option(argc, argv, "--field"));
            file.open();
            const auto grid = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("tangent"));
            if (!grid) throw std::runtime_error("no vec3s grid 'tangent'");
            writeData(option(argc, argv, "-o"), retrace(s, *grid));
        } else if (verb == "refine") {
            writeData(option(argc, argv, "-o"), retrace(s, *field(s, std::stod(option(argc, argv, "--voxel-size")))));
        } else {
            throw std::runtime_error("unknown verb " + verb);
        }
    } catch (const std::exception& e) {
        std::cerr << "vdbhair_peer " << verb << ": " << e.what() << "\n";
        return 1;
    }
    return 0;
}
