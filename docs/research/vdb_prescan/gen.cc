// Writes valid .vdb test files with libopenvdb 10.0.1 covering compression
// settings pyopenvdb cannot choose (zip, none, no active-mask), Int32 grids,
// points grids (paged blosc and unpaged zip/none), instancing, a file without
// grid offsets (io::Stream), and (with "big") a ~100 MB file for timing.
#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <fstream>
#include <random>
#include <string>
#include <cstring>

using namespace openvdb;

static void writeFile(const std::string& path, const GridPtrVec& grids, uint32_t comp)
{
    io::File f(path);
    f.setCompression(comp);
    f.write(grids);
    f.close();
}

static FloatGrid::Ptr randomFloat(const std::string& name, int n, unsigned seed, bool smooth)
{
    auto g = FloatGrid::create(0.f);
    g->setName(name);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    auto acc = g->getAccessor();
    for (int i = 0; i < n; ++i) for (int j = 0; j < n; ++j) for (int k = 0; k < n; ++k) {
        if (!smooth && u(rng) < 0.3f) continue;  // leave holes: inactive voxels
        acc.setValue(Coord(i, j, k), smooth ? float(i + j) * 0.5f : u(rng));
    }
    return g;
}

int main(int argc, char** argv)
{
    initialize();
    const std::string out = "/work/scratch51/files/";
    const bool big = argc > 1 && std::strcmp(argv[1], "big") == 0;
    if (argc > 1 && std::strcmp(argv[1], "bigpoints") == 0) {
        // ~100 MB points file: 5M points, P (null codec), pscale, id, one group; blosc (paged)
        std::vector<Vec3R> pos;
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> u(-50.0, 50.0);
        for (int i = 0; i < 5000000; ++i) pos.emplace_back(u(rng), u(rng) * 0.5, u(rng) * 0.25);
        points::PointAttributeVector<Vec3R> wrapper(pos);
        auto xf = math::Transform::createLinearTransform(0.5);
        auto idx = tools::createPointIndexGrid<tools::PointIndexGrid>(wrapper, *xf);
        auto pg = points::createPointDataGrid<points::NullCodec, points::PointDataGrid>(*idx, wrapper, *xf);
        pg->setName("pts");
        auto& tree = pg->tree();
        points::appendAttribute<float>(tree, "pscale");
        points::appendAttribute<int32_t>(tree, "id");
        points::appendGroup(tree, "odd");
        std::vector<short> member(pos.size());
        std::vector<float> ps(pos.size());
        std::vector<int32_t> ids(pos.size());
        for (size_t i = 0; i < pos.size(); ++i) { member[i] = i % 2; ps[i] = float(i % 1000) * 0.001f; ids[i] = int32_t(i); }
        points::setGroup(tree, idx->tree(), member, "odd");
        points::populateAttribute(tree, idx->tree(), "pscale", points::PointAttributeVector<float>(ps));
        points::populateAttribute(tree, idx->tree(), "id", points::PointAttributeVector<int32_t>(ids));
        writeFile(out + "bigpoints.vdb", {pg}, io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK);
        return 0;
    }
    if (big) {
        // ~100 MB: a large level set (blosc + active mask) and a random vec3 field.
        auto ls = tools::createLevelSetSphere<FloatGrid>(500.f, Vec3f(0), 1.f, 3.f);
        ls->setName("big_ls");
        auto v = Vec3SGrid::create(Vec3s(0));
        v->setName("big_vel");
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(-1.f, 1.f);
        auto acc = v->getAccessor();
        for (int i = 0; i < 160; ++i) for (int j = 0; j < 160; ++j) for (int k = 0; k < 160; ++k)
            acc.setValue(Coord(i, j, k), Vec3s(u(rng), u(rng), u(rng)));
        writeFile(out + "big.vdb", {ls, v}, io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK);
        return 0;
    }

    // Int32 grid, each compression mode.
    auto ig = Int32Grid::create(-1);
    ig->setName("ids");
    {
        auto acc = ig->getAccessor();
        for (int i = 0; i < 30; ++i) for (int j = 0; j < 30; ++j) for (int k = 0; k < 20; ++k)
            if ((i * 7 + j * 3 + k) % 5) acc.setValue(Coord(i - 10, j, k * 3), i * 1000 + j * 10 + k);
        ig->tree().addTile(1, Coord(4096, 0, 0), 42, true);   // lower internal tile
        ig->tree().addTile(2, Coord(-8192, 0, 0), 7, false);  // upper internal tile
        ig->tree().addTile(3, Coord(0, 0, 8192), 9, true);    // root tile
    }
    auto fu = randomFloat("noise", 40, 3, false);          // class unknown: zip applies
    auto fs = randomFloat("ramp", 24, 4, true);
    auto bg = BoolGrid::create(false);
    bg->setName("flags");
    {
        auto acc = bg->getAccessor();
        for (int i = 0; i < 50; ++i) for (int j = 0; j < 50; ++j) acc.setValue(Coord(i, j, (i * j) % 17), (i + j) % 3 == 0);
    }
    auto vg = Vec3SGrid::create(Vec3s(0));
    vg->setName("vec");
    {
        auto acc = vg->getAccessor();
        for (int i = 0; i < 20; ++i) for (int j = 0; j < 20; ++j) for (int k = 0; k < 20; ++k)
            acc.setValue(Coord(i, j, k), Vec3s(float(i), float(j) * 0.1f, float(k * k)));
    }
    auto fh = FloatGrid::create(0.f);
    fh->setName("noise_half");
    fh->setTree(fu->deepCopy()->treePtr());
    fh->setSaveFloatAsHalf(true);
    auto vh = vg->deepCopy();
    vh->setName("vec_half");
    vh->setSaveFloatAsHalf(true);

    const GridPtrVec all{ig, fu, fs, bg, vg, fh, vh};
    writeFile(out + "c_blosc_mask.vdb", all, io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK);
    writeFile(out + "c_zip_mask.vdb", all, io::COMPRESS_ZIP | io::COMPRESS_ACTIVE_MASK);
    writeFile(out + "c_zip.vdb", all, io::COMPRESS_ZIP);
    writeFile(out + "c_blosc.vdb", all, io::COMPRESS_BLOSC);
    writeFile(out + "c_none.vdb", all, io::COMPRESS_NONE);
    writeFile(out + "c_mask.vdb", all, io::COMPRESS_ACTIVE_MASK);

    // Instancing: two grids sharing one tree.
    auto inst = fu->copyGrid();
    inst->setName("noise_instance");
    writeFile(out + "c_instance.vdb", {fu, GridBase::Ptr(std::const_pointer_cast<GridBase>(inst))},
              io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK);

    // A file without grid offsets (io::Stream).
    {
        std::ofstream os(out + "c_stream.vdb", std::ios::binary);
        io::Stream s(os);
        s.setCompression(io::COMPRESS_ZIP | io::COMPRESS_ACTIVE_MASK);
        s.write(all);
    }

    // Points: 20000 points with P (null, fixed16), a float and an int attribute, one group.
    std::vector<Vec3R> pos;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    for (int i = 0; i < 20000; ++i) pos.emplace_back(u(rng), u(rng) * 0.5, u(rng) * 2.0);
    points::PointAttributeVector<Vec3R> wrapper(pos);
    auto xf = math::Transform::createLinearTransform(0.1);
    auto idx = tools::createPointIndexGrid<tools::PointIndexGrid>(wrapper, *xf);
    for (int codec = 0; codec < 2; ++codec) {
        points::PointDataGrid::Ptr pg = codec == 0
            ? points::createPointDataGrid<points::NullCodec, points::PointDataGrid>(*idx, wrapper, *xf)
            : points::createPointDataGrid<points::FixedPointCodec<false>, points::PointDataGrid>(*idx, wrapper, *xf);
        pg->setName("pts");
        auto& tree = pg->tree();
        points::appendAttribute<float>(tree, "pscale");
        points::appendAttribute<int32_t>(tree, "id");
        points::appendAttribute<Vec3f>(tree, "Cd", Vec3f(1, 0.5f, 0));  // stays uniform
        points::appendGroup(tree, "odd");
        std::vector<short> member(pos.size());
        std::vector<float> ps(pos.size());
        std::vector<int32_t> ids(pos.size());
        for (size_t i = 0; i < pos.size(); ++i) { member[i] = i % 2; ps[i] = float(i % 100) * 0.01f; ids[i] = int32_t(i); }
        points::setGroup(tree, idx->tree(), member, "odd");
        points::populateAttribute(tree, idx->tree(), "pscale", points::PointAttributeVector<float>(ps));
        points::populateAttribute(tree, idx->tree(), "id", points::PointAttributeVector<int32_t>(ids));
        const std::string tag = codec == 0 ? "null" : "fx16";
        writeFile(out + "p_" + tag + "_blosc.vdb", {pg}, io::COMPRESS_BLOSC | io::COMPRESS_ACTIVE_MASK);
        writeFile(out + "p_" + tag + "_zip.vdb", {pg}, io::COMPRESS_ZIP | io::COMPRESS_ACTIVE_MASK);
        writeFile(out + "p_" + tag + "_none.vdb", {pg}, io::COMPRESS_NONE);
    }
    return 0;
}
