// The field estimate's parameters, declared once (TangentField.h): field's, and refine's where
// they are the same.
#include <vdbhair/field/TangentField.h>

namespace vdbhair {

const ParamTable<FieldParams>& fieldParameters()
{
    using P = FieldParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto voxel = makeParam<P>("voxel-size", "Voxel size (of the finest level)", "world units", member<P>([](P& p) -> double& { return p.voxelSize; }));
        voxel.min = 0.0;
        voxel.zeroMeans = "3 x the median root spacing, within 1/64..1/4 of the head radius";
        t.push_back(voxel);
        auto iterations = makeParam<P>("iterations", "Reweighting iterations of Eq. 9", "", member<P>([](P& p) -> int& { return p.iterations; }));
        iterations.min = 1;
        t.push_back(iterations);
        auto maxVoxels = makeParam<P>("max-voxels", "Refuse voxel sizes whose voxel visits could exceed this", "",
                                      member<P>([](P& p) -> std::uint64_t& { return p.maxVoxels; }));
        maxVoxels.min = 1;
        t.push_back(maxVoxels);
        auto maxMemory = makeParam<P>("max-memory", "Refuse work whose memory estimate exceeds this (suffixes k, M, G on the command line: 16G)",
                                      "bytes", member<P>([](P& p) -> std::uint64_t& { return p.maxMemory; }));
        maxMemory.zeroMeans = "the memory available (MemAvailable)";
        t.push_back(maxMemory);
        auto density = makeParam<P>("density-reference", "Hair length per unit volume that the grid 'density' maps to 1", "world units^-2",
                                    member<P>([](P& p) -> double& { return p.densityReference; }));
        density.min = 0.0;
        density.zeroMeans = "the 95th percentile of the hairstyle's";
        t.push_back(density);
        auto space = makeParam<P>("space", "The grids' space (world: any hairstyle; scalp: Wang et al.'s (u, v, w) over the scalp)", "",
                                  named<P>([](P& p) -> FieldSpace& { return p.space; }, fieldSpaceName, fieldSpaceFromName));
        space.choices = {fieldSpaceName(FieldSpace::World), fieldSpaceName(FieldSpace::Scalp)};
        t.push_back(space);
        t.push_back(makeAxisParam<P>("up", "The scalp's up axis in scalp space", [](P& p) -> Vec3d& { return p.scalp.up; }));
        return t;
    }();
    return table;
}

const ParamTable<FieldLevelsParams>& fieldLevelsParameters()
{
    using P = FieldLevelsParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t = nestedParams<P>(fieldParameters(), [](P& p) -> FieldParams& { return p.field; });
        auto levels = makeParam<P>("levels", "Levels: level l has voxel size h x 2^l", "", member<P>([](P& p) -> int& { return p.levels; }));
        levels.min = 1;
        levels.max = FieldParams::kMaxLevels;
        levels.pythonNone = true;  // None: one field, not a list of one
        t.insert(t.begin() + 1, levels);
        return t;
    }();
    return table;
}

} // namespace vdbhair
