#include "VdbInfo.h"

#include <vdbhair/io/VdbFile.h>

#include <openvdb/openvdb.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <sstream>

namespace vdbhair {

namespace {

MetaValue toMetaValue(const std::string& name, const openvdb::Metadata& meta)
{
    MetaValue m;
    m.name = name;
    m.typeName = meta.typeName();
    using namespace openvdb;
    auto vec = [](auto v, int n) {
        std::vector<double> out;
        for (int i = 0; i < n; ++i) out.push_back(double(v[i]));
        return out;
    };
    if (auto b = dynamic_cast<const BoolMetadata*>(&meta)) m.value = b->value();
    else if (auto i32 = dynamic_cast<const Int32Metadata*>(&meta)) m.value = std::int64_t(i32->value());
    else if (auto i64 = dynamic_cast<const Int64Metadata*>(&meta)) m.value = i64->value();
    else if (auto f = dynamic_cast<const FloatMetadata*>(&meta)) m.value = double(f->value());
    else if (auto d = dynamic_cast<const DoubleMetadata*>(&meta)) m.value = d->value();
    else if (auto s = dynamic_cast<const StringMetadata*>(&meta)) m.value = s->value();
    else if (auto v2i = dynamic_cast<const Vec2IMetadata*>(&meta)) m.value = vec(v2i->value(), 2);
    else if (auto v2s = dynamic_cast<const Vec2SMetadata*>(&meta)) m.value = vec(v2s->value(), 2);
    else if (auto v2d = dynamic_cast<const Vec2DMetadata*>(&meta)) m.value = vec(v2d->value(), 2);
    else if (auto v3i = dynamic_cast<const Vec3IMetadata*>(&meta)) m.value = vec(v3i->value(), 3);
    else if (auto v3s = dynamic_cast<const Vec3SMetadata*>(&meta)) m.value = vec(v3s->value(), 3);
    else if (auto v3d = dynamic_cast<const Vec3DMetadata*>(&meta)) m.value = vec(v3d->value(), 3);
    else if (auto v4d = dynamic_cast<const Vec4DMetadata*>(&meta)) m.value = vec(v4d->value(), 4);
    else if (auto m4d = dynamic_cast<const Mat4DMetadata*>(&meta)) m.value = vec(m4d->value().asPointer(), 16);
    else if (auto m4s = dynamic_cast<const Mat4SMetadata*>(&meta)) m.value = vec(m4s->value().asPointer(), 16);
    else m.value = meta.str();
    return m;
}

} // namespace

std::string metaValueString(const MetaValue& m, std::size_t maxChars)
{
    if (const auto* text = std::get_if<std::string>(&m.value); text && maxChars > 0 && text->size() > maxChars) {
        const std::size_t keep = maxChars / 2;
        return text->substr(0, keep) + "... (" + std::to_string(text->size()) + " characters)";
    }
    std::ostringstream os;
    std::visit([&os](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>) os << (v ? "true" : "false");
        else if constexpr (std::is_same_v<T, std::vector<double>>) {
            os << '[';
            for (std::size_t i = 0; i < v.size(); ++i) os << (i ? ", " : "") << v[i];
            os << ']';
        } else os << v;
    }, m.value);
    return os.str();
}

std::vector<GridInfo> describeVdbFile(const std::string& path, const std::string& whereGiven)
{
    const std::string where = whereGiven.empty() ? "info(" + path + ")" : whereGiven;
    const openvdb::GridPtrVec grids = readVdbGrids(path, where);
    std::vector<GridInfo> out;
    for (const openvdb::GridBase::Ptr& grid : grids) {
        GridInfo g;
        g.name = grid->getName();
        g.type = grid->type();
        g.valueType = grid->valueType();
        g.gridClass = openvdb::GridBase::gridClassToString(grid->getGridClass());
        if (g.valueType.rfind("vec", 0) == 0) {
            g.vectorType = openvdb::GridBase::vecTypeToString(grid->getVectorType());
        }
        const openvdb::Vec3d vs = grid->voxelSize();
        g.voxelSize = Vec3d(vs.x(), vs.y(), vs.z());
        g.linear = grid->transform().isLinear();
        g.activeVoxels = grid->activeVoxelCount();
        g.memoryBytes = grid->memUsage();
        const openvdb::CoordBBox ibox = grid->evalActiveVoxelBoundingBox();
        if (!ibox.empty()) {
            const openvdb::BBoxd world = grid->transform().indexToWorld(
                openvdb::BBoxd(ibox.min().asVec3d() - 0.5, ibox.max().asVec3d() + 0.5));
            g.emptyBBox = false;
            g.bboxMin = Vec3d(world.min().x(), world.min().y(), world.min().z());
            g.bboxMax = Vec3d(world.max().x(), world.max().y(), world.max().z());
        }
        for (auto it = grid->beginMeta(); it != grid->endMeta(); ++it) {
            // Skip OpenVDB's own bookkeeping that restates the fields above.
            const std::string& key = it->first;
            if (key == openvdb::GridBase::META_GRID_NAME || key == openvdb::GridBase::META_GRID_CLASS ||
                key == openvdb::GridBase::META_VECTOR_TYPE || key == "file_bbox_min" ||
                key == "file_bbox_max" || key == "file_mem_bytes" || key == "file_voxel_count" ||
                key == "file_compression" || key == "file_delayed_load") {
                continue;
            }
            g.metadata.push_back(toMetaValue(key, *it->second));
        }
        if (const auto pg = openvdb::GridBase::grid<openvdb::points::PointDataGrid>(grid)) {
            g.isPoints = true;
            g.pointCount = openvdb::points::pointCount(pg->tree());
            if (const auto leaf = pg->tree().cbeginLeaf()) {
                const auto& desc = leaf->attributeSet().descriptor();
                // Attributes in their stored order.
                std::vector<std::pair<std::size_t, std::string>> ordered;
                for (const auto& [name, pos] : desc.map()) ordered.emplace_back(pos, name);
                std::sort(ordered.begin(), ordered.end());
                for (const auto& [pos, name] : ordered) {
                    const auto& type = desc.type(pos);
                    g.attributes.push_back({name, type.first, type.second});
                }
                for (const auto& [name, offset] : desc.groupMap()) {
                    (void)offset;
                    g.groups.push_back(name);
                }
            }
        }
        g.activeTiles = grid->baseTree().activeTileCount();
        g.leafNodes = grid->baseTree().leafCount();
        out.push_back(std::move(g));
    }
    return out;
}

} // namespace vdbhair
