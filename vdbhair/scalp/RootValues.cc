#include "RootValues.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Format.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/IdList.h>
#include <vdbhair/io/MeshFile.h>
#include <vdbhair/io/PointFile.h>
#include <vdbhair/scalp/ScalpRegion.h>

#include <openvdb/tools/Interpolation.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace vdbhair {

namespace {

/// @a spec split at its last ':' after a file name ending in @a ext ("a.vdb:mask" -> "a.vdb", "mask").
bool splitAt(const std::string& spec, const std::string& ext, std::string& file, std::string& rest)
{
    const std::size_t at = spec.rfind(ext + ":");
    if (at != std::string::npos && at + ext.size() + 1 <= spec.size()) {
        file = spec.substr(0, at + ext.size());
        rest = spec.substr(at + ext.size() + 1);
        return true;
    }
    if (spec.size() >= ext.size() && spec.compare(spec.size() - ext.size(), ext.size(), ext) == 0) {
        file = spec;
        rest.clear();
        return true;
    }
    return false;
}

} // namespace

std::vector<float> readRootValues(const std::string& spec, const std::vector<Vec3d>& roots, const std::string& option, const std::string& preferred)
{
    const std::size_t R = roots.size();
    std::vector<float> out(R);
    // A number.
    {
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(spec.c_str(), &end);
        if (!spec.empty() && *end == '\0' && errno != ERANGE) {
            if (!std::isfinite(v)) throw ValueError(option + " " + spec + ": must be a finite number");
            std::fill(out.begin(), out.end(), float(v));
            return out;
        }
    }
    std::string file, rest;
    if (splitAt(spec, ".vdb", file, rest)) {
        const openvdb::GridBase::Ptr g = readMaskGrid(file, rest, preferred, option + " (name a grid: " + file + ":GRID)");
        if (const auto f = openvdb::GridBase::grid<openvdb::FloatGrid>(g)) {
            const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*f);
            for (std::size_t i = 0; i < R; ++i) out[i] = sampler.wsSample(roots[i]);
        } else {
            const auto b = openvdb::GridBase::grid<openvdb::BoolGrid>(g);
            const auto acc = b->getConstAccessor();
            for (std::size_t i = 0; i < R; ++i) out[i] = acc.getValue(b->transform().worldToIndexCellCentered(roots[i])) ? 1.f : 0.f;
        }
        for (std::size_t i = 0; i < R; ++i) {
            if (!std::isfinite(out[i])) throw ValueError(file + ": grid '" + g->getName() + "' is not finite at root " + std::to_string(i) + " (" + option + ")");
        }
        return out;
    }
    if (splitAt(spec, ".ply", file, rest) && !rest.empty()) {
        const VertexValueSampler sampler(readTriangleMesh(file), readPlyVertexValues(file, rest), file + ":" + rest);
        for (std::size_t i = 0; i < R; ++i) out[i] = float(sampler.at(roots[i]));
        return out;
    }
    if (fileExtension(spec) == ".ply") {
        throw ValueError(option + " " + spec + ": name the vertex property to read: " + spec + ":PROPERTY (e.g. a painted weight, or red)");
    }
    const std::vector<double> v = readValueList(spec, R, "roots");
    for (std::size_t i = 0; i < R; ++i) out[i] = float(v[i]);
    return out;
}

} // namespace vdbhair
