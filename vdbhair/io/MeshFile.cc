#include "MeshFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

namespace vdbhair {

TriangleMesh readTriangleMesh(const std::string& path)
{
    const std::string ext = fileExtension(path);
    if (ext == ".ply") return readPlyMesh(path);
    if (ext == ".obj") return readObjMesh(path);
    throw UnsupportedError(path + ": unknown mesh extension '" + ext + "' (meshes are .ply or .obj)");
}

BBox meshBBox(const TriangleMesh& mesh)
{
    BBox box;
    for (const Vec3f& v : mesh.vertices) box.expand(v);
    return box;
}

} // namespace vdbhair
