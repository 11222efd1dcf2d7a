#include "VdbFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/FileUtil.h>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <filesystem>
#include <mutex>

namespace vdbhair {

void initializeOpenVdb()
{
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

namespace {

/// Open @a path, turning OpenVDB's errors into ours.
void openFile(openvdb::io::File& file, const std::string& path, const std::string& where)
{
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw IoError(where + ": cannot open for reading: No such file or directory");
    if (std::filesystem::is_directory(path, ec)) throw IoError(where + ": is a directory, not a file");
    try {
        file.open(/*delayLoad=*/false);
    } catch (const openvdb::Exception& e) {
        throw FormatError(where + ": not a readable VDB file (" + std::string(e.what()) + ")");
    }
}

std::string listNames(const std::vector<std::string>& names)
{
    if (names.empty()) return "the file has no grids";
    std::string s = "the file has ";
    for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", '" : "'") + names[i] + "'";
    return s;
}

} // namespace

openvdb::GridPtrVec readVdbGrids(const std::string& path, const std::string& where)
{
    initializeOpenVdb();
    openvdb::io::File file(path);
    openFile(file, path, where);
    try {
        openvdb::GridPtrVecPtr grids = file.getGrids();
        file.close();
        return grids ? *grids : openvdb::GridPtrVec{};
    } catch (const openvdb::Exception& e) {
        throw FormatError(where + ": cannot read the grids (" + std::string(e.what()) + ")");
    }
}

std::vector<std::string> vdbGridNames(const std::string& path, const std::string& where)
{
    initializeOpenVdb();
    openvdb::io::File file(path);
    openFile(file, path, where);
    std::vector<std::string> names;
    for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
    file.close();
    return names;
}

openvdb::GridBase::Ptr readVdbGrid(const std::string& path, const std::string& name,
                                   const std::string& where)
{
    initializeOpenVdb();
    openvdb::io::File file(path);
    openFile(file, path, where);
    std::vector<std::string> names;
    for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
    if (!file.hasGrid(name)) {
        file.close();
        throw LookupError(where + ": no grid named '" + name + "'; " + listNames(names));
    }
    try {
        openvdb::GridBase::Ptr grid = file.readGrid(name);
        file.close();
        return grid;
    } catch (const openvdb::Exception& e) {
        throw FormatError(where + ": cannot read grid '" + name + "' (" + std::string(e.what()) + ")");
    }
}

void writeVdbGrids(const std::string& path, const openvdb::GridCPtrVec& grids, const std::string& where)
{
    initializeOpenVdb();
    AtomicOutput out(path);
    try {
        openvdb::io::File file(out.tempPath());
        file.write(grids);
        file.close();
    } catch (const openvdb::Exception& e) {
        throw IoError(where + ": cannot write (" + std::string(e.what()) + ")");
    }
    out.commit();
}

} // namespace vdbhair
