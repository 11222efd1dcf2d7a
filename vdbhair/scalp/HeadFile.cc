#include "HeadFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/scalp/ScalpSurface.h>

namespace vdbhair {

HeadObstacle readHeadObstacle(const std::string& path, const std::string& where, HeadPolicy policy)
{
    const std::string ext = fileExtension(path);
    if (ext == ".ply" || ext == ".obj") {
        // A triangle mesh: its level set as `vdbhair scalp MESH` makes it (default voxel size).
        const TriangleMesh mesh = readTriangleMesh(path);
        return HeadObstacle::levelSet(scalpFromMesh(mesh, ScalpParams{}), policy);
    }
    if (ext != ".vdb") {
        throw UnsupportedError(where + ": the head must be a triangle mesh (.ply, .obj) or a .vdb holding a level set "
                               "(such as the 'surface' grid of vdbhair scalp)");
    }
    const openvdb::GridPtrVec grids = readVdbGrids(path, where);
    openvdb::FloatGrid::Ptr found;
    for (const openvdb::GridBase::Ptr& g : grids) {
        auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(g);
        if (!f || f->getGridClass() != openvdb::GRID_LEVEL_SET) continue;
        if (f->getName() == "surface") {
            found = f;
            break;
        }
        if (!found) found = f;
    }
    if (!found) throw LookupError(where + ": no float level set grid in the file (a head needs one, e.g. 'surface')");
    return HeadObstacle::levelSet(found, policy);
}

} // namespace vdbhair
