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
#include <deque>
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

namespace {

/// One archive being written: the container, its indexed metadata, and the sample digests the
/// container borrows until it is written (a deque: they never move).
struct ArchiveOut
{
    ogawa::Writer w;
    MetaDataIndex mdIndex;
    std::deque<Sample> samples;
    std::deque<std::string> owned;  // bytes of values made while writing (the container borrows them)
};

/// A geometry parameter's metadata, as AbcGeom's OTypedGeomParam writes it.
std::string geomParam(const char* scope, const char* interpretation, unsigned extent, const char* podName)
{
    return std::string("arrayExtent=1;geoScope=") + scope + (*interpretation ? std::string(";interpretation=") + interpretation : std::string()) +
           ";isGeomParam=true;podExtent=" + std::to_string(extent) + ";podName=" + podName;
}

/// The properties of one object's compound, collected and encoded.
class PropertyList
{
public:
    explicit PropertyList(ArchiveOut& a) : mA(a) {}

    /// An array property of @a count elements; @a data must stay valid until the archive is written.
    void array(const std::string& name, const std::string& md, unsigned pod, unsigned extent, const void* data, std::uint64_t bytes,
               std::uint64_t count)
    {
        const Sample& s = mA.samples.emplace_back(makeSample(data, bytes));
        PropertyOut p{name, md, kArray, pod, extent, count == 1, {}};
        // Sample 0: its digest and bytes, then its dimensions (empty: rank 1, count from the size).
        const auto data0 = mA.w.addData(ogawa::Writer::Pieces{{s.digest, 16}, {s.data, s.size}});
        const auto dims = mA.w.addData(ogawa::Writer::Pieces{});
        p.group = mA.w.addGroup({data0, dims});
        mList.push_back(std::move(p));
    }
    /// As array(), the bytes copied (for values made here).
    void ownedArray(const std::string& name, const std::string& md, unsigned pod, unsigned extent, std::string bytes, std::uint64_t count)
    {
        const std::string& b = mA.owned.emplace_back(std::move(bytes));
        array(name, md, pod, extent, b.data(), b.size(), count);
    }
    void scalar(const std::string& name, const std::string& md, unsigned pod, unsigned extent, std::string bytes)
    {
        const std::string& b = mA.owned.emplace_back(std::move(bytes));
        const Sample& s = mA.samples.emplace_back(makeSample(b.data(), b.size()));
        PropertyOut p{name, md, kScalar, pod, extent, true, {}};
        p.group = mA.w.addGroup({mA.w.addData(ogawa::Writer::Pieces{{s.digest, 16}, {s.data, s.size}})});
        mList.push_back(std::move(p));
    }
    void compound(const std::string& name, const std::string& md, ogawa::Writer::Node group)
    {
        mList.push_back(PropertyOut{name, md, kCompound, 0, 0, false, group});
    }
    bool empty() const { return mList.empty(); }
    /// The compound's group: every property's group, then their headers. @a headers gets the headers.
    ogawa::Writer::Node group(std::string* headers = nullptr)
    {
        std::vector<ogawa::Writer::Node> children;
        for (const PropertyOut& p : mList) children.push_back(p.group);
        std::string h;
        for (const PropertyOut& p : mList) encodeProperty(h, p, mA.mdIndex);
        children.push_back(mA.w.addData(h));
        if (headers) *headers = std::move(h);
        return mA.w.addGroup(children);
    }

private:
    ArchiveOut& mA;
    std::vector<PropertyOut> mList;
};

template<typename T>
std::string bytesOf(const T* data, std::size_t count)
{
    return std::string(reinterpret_cast<const char*>(data), sizeof(T) * count);
}

/// Hashes of content (the reference library's are SpookyHash V2 of the same inputs; readers only
/// compare them, so any content hash keeps their meaning: equal content, equal hash).
void contentHash(const std::string& bytes, std::uint64_t out[2])
{
    ogawa::murmur3x64_128(bytes.data(), bytes.size(), out);
}

const std::string kCurvesSchema = "schema=AbcGeom_Curve_v2;schemaBaseType=AbcGeom_GeomBase_v1";

/// One written object: its group and the 16 bytes of its properties' hash.
struct ObjectOut
{
    ogawa::Writer::Node group;
    std::uint64_t hash[2];
};

/// The Curves object of @a c (AbcFile.h's layout).
ObjectOut writeCurvesObject(ArchiveOut& a, const AbcCurves& c)
{
    const StrandSet& strands = *c.strands;
    std::vector<std::int32_t> counts(strands.numStrands());
    for (std::size_t i = 0; i < counts.size(); ++i) counts[i] = std::int32_t(strands.size(i));
    const BBox box = computeBBox(strands);
    const double bounds[6] = {box.min.x(), box.min.y(), box.min.z(), box.max.x(), box.max.y(), box.max.z()};
    const std::uint8_t basisAndType[4] = {1, 0, 0, 0};  // kLinear, kNonPeriodic, kNoBasis, kNoBasis
    const float constantWidth = strands.defaults.thickness;
    const std::size_t firstSample = a.samples.size();

    PropertyList geom(a), arb(a);
    geom.scalar(".selfBnds", "interpretation=box", kFloat64, 6, bytesOf(bounds, 6));
    geom.array("P", "geoScope=vtx;interpretation=point", kFloat32, 3, strands.positions.data(), 12 * std::uint64_t(strands.numVertices()),
               strands.numVertices());
    geom.ownedArray("nVertices", "", kInt32, 1, bytesOf(counts.data(), counts.size()), counts.size());
    geom.scalar("curveBasisAndType", "", kUint8, 4, bytesOf(basisAndType, 4));
    if (!strands.rootUV.empty()) {
        geom.array("uv", geomParam("uni", "vector", 2, "float32_t"), kFloat32, 2, strands.rootUV.data(), 8 * std::uint64_t(strands.rootUV.size()),
                   strands.rootUV.size());
    }
    if (!strands.thickness.empty()) {
        geom.array("width", geomParam("vtx", "", 1, "float32_t"), kFloat32, 1, strands.thickness.data(),
                   4 * std::uint64_t(strands.thickness.size()), strands.thickness.size());
    } else {
        geom.ownedArray("width", geomParam("con", "", 1, "float32_t"), kFloat32, 1, bytesOf(&constantWidth, 1), 1);
    }
    // .arbGeomParams: colour as Cd (Houdini's, Maya's and Blender's name) and Unreal's groom
    // attributes (its "Alembic for Grooms" specification, schema version 1.5).
    const std::int16_t versionMajor = 1, versionMinor = 5;
    arb.ownedArray("groom_version_major", geomParam("con", "", 1, "int16_t"), kInt16, 1, bytesOf(&versionMajor, 1), 1);
    arb.ownedArray("groom_version_minor", geomParam("con", "", 1, "int16_t"), kInt16, 1, bytesOf(&versionMinor, 1), 1);
    const std::int32_t guideFlag = c.guides ? 1 : 0;
    arb.ownedArray("groom_guide", geomParam("con", "", 1, "int32_t"), kInt32, 1, bytesOf(&guideFlag, 1), 1);
    if (!strands.color.empty()) {
        arb.array("Cd", geomParam("vtx", "rgb", 3, "float32_t"), kFloat32, 3, strands.color.data(), 12 * std::uint64_t(strands.color.size()),
                  strands.color.size());
    }
    if (!strands.rootUV.empty()) {
        arb.array("groom_root_uv", geomParam("uni", "vector", 2, "float32_t"), kFloat32, 2, strands.rootUV.data(),
                  8 * std::uint64_t(strands.rootUV.size()), strands.rootUV.size());
    }
    if (!strands.strandId.empty()) {
        arb.array("groom_id", geomParam("uni", "", 1, "int32_t"), kInt32, 1, strands.strandId.data(), 4 * std::uint64_t(strands.strandId.size()),
                  strands.strandId.size());
    }
    if (!strands.thickness.empty()) {
        arb.array("groom_width", geomParam("vtx", "", 1, "float32_t"), kFloat32, 1, strands.thickness.data(),
                  4 * std::uint64_t(strands.thickness.size()), strands.thickness.size());
    }
    if (!c.groupId.empty()) {
        arb.array("groom_group_id", geomParam("uni", "", 1, "int32_t"), kInt32, 1, c.groupId.data(), 4 * std::uint64_t(c.groupId.size()),
                  c.groupId.size());
    }
    if (!c.closestGuides.empty()) {
        arb.array("groom_closest_guides", geomParam("uni", "", 3, "int32_t"), kInt32, 3, c.closestGuides.data(),
                  4 * std::uint64_t(c.closestGuides.size()), c.closestGuides.size() / 3);
        arb.array("groom_guide_weights", geomParam("uni", "", 3, "float32_t"), kFloat32, 3, c.guideWeights.data(),
                  4 * std::uint64_t(c.guideWeights.size()), c.guideWeights.size() / 3);
    }
    geom.compound(".arbGeomParams", "", arb.group());

    std::string geomHeaders;
    const ogawa::Writer::Node geomGroup = geom.group(&geomHeaders);
    PropertyList objectProps(a);
    objectProps.compound(".geom", kCurvesSchema, geomGroup);
    const ogawa::Writer::Node props = objectProps.group();

    ObjectOut out{};
    std::uint64_t hashes[4];
    std::string digestInput = geomHeaders;
    for (std::size_t k = firstSample; k < a.samples.size(); ++k) digestInput.append(reinterpret_cast<const char*>(a.samples[k].digest), 16);
    contentHash(digestInput, hashes);  // properties
    hashes[2] = hashes[3] = 0;         // no children
    out.group = a.w.addGroup({props, a.w.addData(std::string(reinterpret_cast<const char*>(hashes), 32))});
    out.hash[0] = hashes[0];
    out.hash[1] = hashes[1];
    return out;
}

} // namespace

void writeAbc(const std::string& path, const StrandSet& strands)
{
    AbcCurves hair;
    hair.strands = &strands;
    writeAbc(path, std::vector<AbcCurves>{std::move(hair)});
}

void writeAbc(const std::string& path, const std::vector<AbcCurves>& objects)
{
    const std::string where = "writeAbc(" + path + ")";
    if (objects.empty()) throw ValueError(where + ": no objects to write");
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const AbcCurves& c = objects[i];
        const std::string what = where + ": object '" + c.name + "'";
        if (!c.strands || c.strands->empty()) throw ValueError(what + ": no strands to write; an Alembic Curves object needs at least one");
        if (c.name.empty() || c.name.find('/') != std::string::npos) throw ValueError(what + ": a name is not empty and has no '/'");
        for (std::size_t j = 0; j < i; ++j)
            if (objects[j].name == c.name) throw ValueError(what + ": two objects of one name; names are unique among siblings");
        const std::size_t S = c.strands->numStrands();
        if (!c.groupId.empty() && c.groupId.size() != S)
            throw ValueError(what + ": " + std::to_string(c.groupId.size()) + " group ids for " + std::to_string(S) + " strands: one per strand");
        if (c.closestGuides.size() != c.guideWeights.size() || (!c.closestGuides.empty() && c.closestGuides.size() != 3 * S))
            throw ValueError(what + ": " + std::to_string(c.closestGuides.size()) + " closest guides and " + std::to_string(c.guideWeights.size()) +
                             " weights for " + std::to_string(S) + " strands: three of each per strand");
    }
    ArchiveOut a;
    // The top object's children: each object, then their headers (name, metadata) and hashes.
    std::vector<ogawa::Writer::Node> topChildren{a.w.addGroup({})};
    std::string topHeaders, childDigest;
    const std::string curvesMd = kCurvesSchema + ";schemaObjTitle=AbcGeom_Curve_v2:.geom";
    for (const AbcCurves& c : objects) {
        const ObjectOut o = writeCurvesObject(a, c);
        topChildren.push_back(o.group);
        pushU32(topHeaders, std::uint32_t(c.name.size()), 2);
        topHeaders += c.name;
        const std::uint32_t mdi = a.mdIndex.index(curvesMd);
        pushU32(topHeaders, mdi, 0);
        if (mdi == 255) { pushU32(topHeaders, std::uint32_t(curvesMd.size()), 2); topHeaders += curvesMd; }
        childDigest += std::string(reinterpret_cast<const char*>(o.hash), 16) + curvesMd + c.name;
    }
    std::uint64_t topHashes[4] = {0, 0, 0, 0};
    contentHash(childDigest, topHashes + 2);
    topHeaders.append(reinterpret_cast<const char*>(topHashes), 32);
    topChildren.push_back(a.w.addData(topHeaders));
    const auto topObject = a.w.addGroup(topChildren);

    // The archive: versions, top object, metadata, time samplings, indexed metadata.
    std::string versionBytes(4, '\0'), libraryBytes(4, '\0');
    std::memcpy(&versionBytes[0], &kOgawaFileVersion, 4);
    std::memcpy(&libraryBytes[0], &kLibraryVersion, 4);
    const auto v0 = a.w.addData(versionBytes);
    const auto v1 = a.w.addData(libraryBytes);
    const std::string archiveMd = std::string("_ai_AlembicVersion=Alembic 1.8.12 (written by ") + creatorString() +
                                  ");_ai_Application=" + creatorString();
    std::string timeSamplings;
    const double timePerCycle = 1.0, time0 = 0.0;
    pushU32(timeSamplings, 1, 2);  // the most samples any property has in time sampling 0
    timeSamplings.append(reinterpret_cast<const char*>(&timePerCycle), 8);
    pushU32(timeSamplings, 1, 2);  // one stored time
    timeSamplings.append(reinterpret_cast<const char*>(&time0), 8);
    const auto md = a.w.addData(archiveMd);
    const auto ts = a.w.addData(timeSamplings);
    const auto indexed = a.w.addData(a.mdIndex.serialize());
    a.w.addGroup({v0, v1, topObject, md, ts, indexed});

    AtomicFileWriter file(path, where);
    a.w.write([&](const void* data, std::uint64_t n) { file.append(data, std::size_t(n)); });
    file.commit();
}

} // namespace vdbhair
