// Writing Alembic Curves in the Ogawa container (AbcFile.h). The encoding follows the reference
// library's AbcCoreOgawa (WritePropertyInfo, WriteObjectHeader, WriteTimeSampling, MetaDataMap)
// and AbcGeom's OCurves; checked against it (docs/development.md).
#include "AbcFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/Version.h>
#include <vdbhair/io/FileUtil.h>
#include <vdbhair/io/Ogawa.h>

#include <algorithm>
#include <cstring>
#include <map>

namespace vdbhair {

namespace {

using namespace abc;

/// Indexed metadata (AbcCoreOgawa's MetaDataMap): strings shorter than 256 bytes get indices
/// 1..254 in the order first asked for; "" is 0; anything else 255 (written inline).
class MetaDataIndex
{
public:
    std::uint32_t index(const std::string& md)
    {
        if (md.empty()) return 0;
        if (md.size() >= 256) return 255;
        auto it = mMap.find(md);
        if (it != mMap.end()) return it->second;
        if (mList.size() >= 254) return 255;
        mList.push_back(md);
        return mMap[md] = std::uint32_t(mList.size());
    }
    std::string serialize() const
    {
        std::string out;
        for (const std::string& s : mList) { out += char(s.size()); out += s; }
        return out;
    }
private:
    std::map<std::string, std::uint32_t> mMap;
    std::vector<std::string> mList;
};

void pushU32(std::string& out, std::uint32_t v, unsigned hint)
{
    const unsigned n = hint == 0 ? 1 : hint == 1 ? 2 : 4;
    for (unsigned i = 0; i < n; ++i) out += char((v >> (8 * i)) & 0xff);
}

struct PropertyOut
{
    std::string name, metaData;
    PropertyType type = kArray;
    unsigned pod = kFloat32, extent = 1;
    bool scalarLike = false;  // an array whose every sample has one element
    ogawa::Writer::Node group{};
};

/// One property header as WritePropertyInfo encodes it, for one static sample (first and last
/// changed index 0: the "constant" bit) in time sampling 0.
void encodeProperty(std::string& out, const PropertyOut& p, MetaDataIndex& mdIndex)
{
    const std::uint32_t maxSize = std::max<std::uint32_t>({std::uint32_t(p.metaData.size()),
                                                          std::uint32_t(p.name.size()), 1u});
    const unsigned hint = maxSize > 255 && maxSize < 65536 ? 1 : maxSize >= 65536 ? 2 : 0;
    const std::uint32_t mdi = mdIndex.index(p.metaData);
    std::uint32_t info = (hint << 2) | (mdi << 20);
    if (p.type != kCompound) {
        info |= std::uint32_t(p.type) | std::uint32_t(p.type == kScalar || p.scalarLike);
        info |= (p.pod & 0xf) << 4;
        info |= 0x800;  // first and last changed sample 0: constant
        info |= (p.extent & 0xff) << 12;
        // "Homogeneous": the reference library compares a sample's element count with its pod
        // count, so only scalars and arrays of extent 1 are marked so.
        if (p.type == kScalar || p.extent == 1) info |= 0x400;
        pushU32(out, info, 2);
        pushU32(out, 1, hint);  // one sample
    } else {
        pushU32(out, info, 2);
    }
    pushU32(out, std::uint32_t(p.name.size()), hint);
    out += p.name;
    if (mdi == 255) { pushU32(out, std::uint32_t(p.metaData.size()), hint); out += p.metaData; }
}

/// A sample's bytes behind its 16-byte digest (AbcCoreAbstract's ArraySample key).
struct Sample
{
    std::uint64_t digest[2];
    const void* data;
    std::uint64_t size;
};

Sample makeSample(const void* data, std::uint64_t size)
{
    Sample s{{0, 0}, data, size};
    ogawa::murmur3x64_128(data, std::size_t(size), s.digest);
    return s;
}

} // namespace

void writeAbc(const std::string& path, const StrandSet& strands)
{
    const std::string where = "writeAbc(" + path + ")";
    if (strands.empty()) throw ValueError(where + ": no strands to write; an Alembic Curves object needs at least one");
    ogawa::Writer w;
    MetaDataIndex mdIndex;

    // Arrays: points, counts, bounds, basis and type, widths, root UVs.
    std::vector<std::int32_t> counts(strands.numStrands());
    for (std::size_t i = 0; i < counts.size(); ++i) counts[i] = std::int32_t(strands.size(i));
    const BBox box = computeBBox(strands);
    const double bounds[6] = {box.min.x(), box.min.y(), box.min.z(), box.max.x(), box.max.y(), box.max.z()};
    const std::uint8_t basisAndType[4] = {1, 0, 0, 0};  // kLinear, kNonPeriodic, kNoBasis, kNoBasis
    const float constantWidth = strands.defaults.thickness;

    std::vector<PropertyOut> props, arbProps;
    std::vector<Sample> samples;  // kept alive until write: the digests are borrowed
    samples.reserve(10);
    auto arrayPropertyIn = [&](std::vector<PropertyOut>& to, const char* name, const std::string& md, unsigned pod, unsigned extent,
                               const void* data, std::uint64_t bytes, std::uint64_t count) {
        samples.push_back(makeSample(data, bytes));
        const Sample& s = samples.back();
        PropertyOut p{name, md, kArray, pod, extent, count == 1, {}};
        // Sample 0: its digest and bytes, then its dimensions (empty: rank 1, count from the size).
        const auto data0 = w.addData(ogawa::Writer::Pieces{{s.digest, 16}, {s.data, s.size}});
        const auto dims = w.addData(ogawa::Writer::Pieces{});
        p.group = w.addGroup({data0, dims});
        to.push_back(std::move(p));
    };
    auto arrayProperty = [&](const char* name, const std::string& md, unsigned pod, unsigned extent, const void* data, std::uint64_t bytes,
                             std::uint64_t count) { arrayPropertyIn(props, name, md, pod, extent, data, bytes, count); };
    // A geometry parameter's metadata, as AbcGeom's OTypedGeomParam writes it.
    auto geomParam = [](const char* scope, const char* interpretation, unsigned extent, const char* podName) {
        return std::string("arrayExtent=1;geoScope=") + scope + (*interpretation ? std::string(";interpretation=") + interpretation : std::string()) +
               ";isGeomParam=true;podExtent=" + std::to_string(extent) + ";podName=" + podName;
    };
    auto scalarProperty = [&](const char* name, const char* md, unsigned pod, unsigned extent,
                              const void* data, std::uint64_t bytes) {
        samples.push_back(makeSample(data, bytes));
        const Sample& s = samples.back();
        PropertyOut p{name, md, kScalar, pod, extent, true, {}};
        p.group = w.addGroup({w.addData(ogawa::Writer::Pieces{{s.digest, 16}, {s.data, s.size}})});
        props.push_back(std::move(p));
    };
    scalarProperty(".selfBnds", "interpretation=box", kFloat64, 6, bounds, sizeof(bounds));
    arrayProperty("P", "geoScope=vtx;interpretation=point", kFloat32, 3, strands.positions.data(),
                  12 * std::uint64_t(strands.numVertices()), strands.numVertices());
    arrayProperty("nVertices", "", kInt32, 1, counts.data(), 4 * std::uint64_t(counts.size()), counts.size());
    scalarProperty("curveBasisAndType", "", kUint8, 4, basisAndType, 4);
    if (!strands.rootUV.empty()) {
        arrayProperty("uv", "arrayExtent=1;geoScope=uni;interpretation=vector;isGeomParam=true;podExtent=2;podName=float32_t", kFloat32, 2,
                      strands.rootUV.data(), 8 * std::uint64_t(strands.rootUV.size()), strands.rootUV.size());
    }
    if (!strands.thickness.empty()) {
        arrayProperty("width", "arrayExtent=1;geoScope=vtx;isGeomParam=true;podExtent=1;podName=float32_t", kFloat32, 1,
                      strands.thickness.data(), 4 * std::uint64_t(strands.thickness.size()), strands.thickness.size());
    } else {
        arrayProperty("width", "arrayExtent=1;geoScope=con;isGeomParam=true;podExtent=1;podName=float32_t", kFloat32, 1,
                      &constantWidth, 4, 1);
    }
    // .arbGeomParams: colour as Cd (Houdini's, Maya's and Blender's name) and Unreal's groom
    // attributes (its "Alembic for Grooms" specification): groom_root_uv and groom_id per curve,
    // groom_width per vertex.
    if (!strands.color.empty()) {
        arrayPropertyIn(arbProps, "Cd", geomParam("vtx", "rgb", 3, "float32_t"), kFloat32, 3, strands.color.data(),
                        12 * std::uint64_t(strands.color.size()), strands.color.size());
    }
    if (!strands.rootUV.empty()) {
        arrayPropertyIn(arbProps, "groom_root_uv", geomParam("uni", "vector", 2, "float32_t"), kFloat32, 2, strands.rootUV.data(),
                        8 * std::uint64_t(strands.rootUV.size()), strands.rootUV.size());
    }
    if (!strands.strandId.empty()) {
        arrayPropertyIn(arbProps, "groom_id", geomParam("uni", "", 1, "int32_t"), kInt32, 1, strands.strandId.data(),
                        4 * std::uint64_t(strands.strandId.size()), strands.strandId.size());
    }
    if (!strands.thickness.empty()) {
        arrayPropertyIn(arbProps, "groom_width", geomParam("vtx", "", 1, "float32_t"), kFloat32, 1, strands.thickness.data(),
                        4 * std::uint64_t(strands.thickness.size()), strands.thickness.size());
    }

    // Header blocks: properties of .geom, the object's compound, the objects.
    const std::string curvesSchema = "schema=AbcGeom_Curve_v2;schemaBaseType=AbcGeom_GeomBase_v1";
    auto headers = [&](const std::vector<PropertyOut>& list) {
        std::string out;
        for (const PropertyOut& p : list) encodeProperty(out, p, mdIndex);
        return out;
    };
    // Hashes of the content (the reference library's are SpookyHash V2 of the same inputs;
    // readers only compare them, so any content hash keeps their meaning: equal content, equal hash).
    auto contentHash = [](const std::string& bytes, std::uint64_t out[2]) { ogawa::murmur3x64_128(bytes.data(), bytes.size(), out); };

    if (!arbProps.empty()) {
        std::vector<ogawa::Writer::Node> arbChildren;
        for (const PropertyOut& p : arbProps) arbChildren.push_back(p.group);
        arbChildren.push_back(w.addData(headers(arbProps)));
        props.push_back(PropertyOut{".arbGeomParams", "", kCompound, 0, 0, false, w.addGroup(arbChildren)});
    }
    std::vector<ogawa::Writer::Node> geomChildren;
    for (const PropertyOut& p : props) geomChildren.push_back(p.group);
    const std::string geomHeaders = headers(props);
    geomChildren.push_back(w.addData(geomHeaders));
    PropertyOut geom{".geom", curvesSchema, kCompound, 0, 0, false, w.addGroup(geomChildren)};
    const std::string objPropHeaders = headers({geom});
    const auto objProps = w.addGroup({geom.group, w.addData(objPropHeaders)});

    std::uint64_t hashes[4];
    std::string digestInput = geomHeaders;
    for (const Sample& s : samples) digestInput.append(reinterpret_cast<const char*>(s.digest), 16);
    contentHash(digestInput, hashes);  // properties
    hashes[2] = hashes[3] = 0;         // no children
    const auto hairObject = w.addGroup({objProps, w.addData(std::string(reinterpret_cast<const char*>(hashes), 32))});

    std::string topHeaders;
    const std::string hairMd = curvesSchema + ";schemaObjTitle=AbcGeom_Curve_v2:.geom";
    pushU32(topHeaders, 4, 2);
    topHeaders += "hair";
    const std::uint32_t hairMdi = mdIndex.index(hairMd);
    pushU32(topHeaders, hairMdi, 0);
    if (hairMdi == 255) { pushU32(topHeaders, std::uint32_t(hairMd.size()), 2); topHeaders += hairMd; }
    std::uint64_t topHashes[4] = {0, 0, 0, 0};
    contentHash(std::string(reinterpret_cast<const char*>(hashes), 16) + hairMd + "hair", topHashes + 2);
    topHeaders.append(reinterpret_cast<const char*>(topHashes), 32);
    const auto topObject = w.addGroup({w.addGroup({}), hairObject, w.addData(topHeaders)});

    // The archive: versions, top object, metadata, time samplings, indexed metadata.
    std::string versionBytes(4, '\0'), libraryBytes(4, '\0');
    std::memcpy(&versionBytes[0], &kOgawaFileVersion, 4);
    std::memcpy(&libraryBytes[0], &kLibraryVersion, 4);
    const auto v0 = w.addData(versionBytes);
    const auto v1 = w.addData(libraryBytes);
    const std::string archiveMd = std::string("_ai_AlembicVersion=Alembic 1.8.12 (written by ") + creatorString() +
                                  ");_ai_Application=" + creatorString();
    std::string timeSamplings;
    const double timePerCycle = 1.0, time0 = 0.0;
    pushU32(timeSamplings, 1, 2);  // the most samples any property has in time sampling 0
    timeSamplings.append(reinterpret_cast<const char*>(&timePerCycle), 8);
    pushU32(timeSamplings, 1, 2);  // one stored time
    timeSamplings.append(reinterpret_cast<const char*>(&time0), 8);
    const auto md = w.addData(archiveMd);
    const auto ts = w.addData(timeSamplings);
    const auto indexed = w.addData(mdIndex.serialize());
    w.addGroup({v0, v1, topObject, md, ts, indexed});

    AtomicFileWriter file(path, where);
    w.write([&](const void* data, std::uint64_t n) { file.append(data, std::size_t(n)); });
    file.commit();
}

} // namespace vdbhair
