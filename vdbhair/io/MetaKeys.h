/// @file MetaKeys.h
/// @brief Names of vdbhair's grid metadata.
///
/// Keys are `vdbhair_` + a name (`vdbhair_voxel_size`, `vdbhair_strand_count`, ...): letters,
/// digits and `_` only, because Houdini turns grid metadata into attributes by name and drops
/// names that are not valid attribute names (such as the `vdbhair:` keys of vdbhair 0.1, which
/// every reader here still accepts).
#pragma once

#include <openvdb/Metadata.h>
#include <openvdb/MetaMap.h>

#include <string>

namespace vdbhair {

/// The key vdbhair writes for @a name: "vdbhair_" + name.
inline std::string metaKey(const std::string& name) { return "vdbhair_" + name; }

/// The older spelling of the same key, "vdbhair:" + name, still read.
inline std::string legacyMetaKey(const std::string& name) { return "vdbhair:" + name; }

/// Whether @a key is one of vdbhair's own (either spelling).
inline bool isVdbhairMetaKey(const std::string& key)
{
    return key.rfind("vdbhair_", 0) == 0 || key.rfind("vdbhair:", 0) == 0;
}

/// @brief The metadata @a name of type @a MetaT under the new key, else under the old one;
/// null when neither is there with that type.
template<typename MetaT>
typename MetaT::ConstPtr findVdbhairMeta(const openvdb::MetaMap& meta, const std::string& name)
{
    if (auto m = meta.getMetadata<MetaT>(metaKey(name))) return m;
    return meta.getMetadata<MetaT>(legacyMetaKey(name));
}

} // namespace vdbhair
