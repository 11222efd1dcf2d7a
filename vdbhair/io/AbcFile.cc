// Reading Alembic Curves from the Ogawa container (AbcFile.h; writing is in AbcWrite.cc). The
// encoding follows the reference library's AbcCoreOgawa (ReadPropertyHeaders, ReadObjectHeaders,
// MetaDataMap) and AbcGeom's ICurves; checked against it (docs/development.md).
#include "AbcFile.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/Xform.h>
#include <vdbhair/io/FreeFormCurve.h>
#include <vdbhair/io/MappedFile.h>
#include <vdbhair/io/Ogawa.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <unordered_set>

namespace vdbhair {

namespace {

using namespace abc;
using namespace xform;

/// Alembic's basis (1 Bezier, 2 B-spline, 3 Catmull-Rom) and wrap (0 nonperiodic, 1 periodic).
CubicBasis cubicBasis(unsigned basis) { return basis == 1 ? CubicBasis::Bezier : basis == 2 ? CubicBasis::BSpline : CubicBasis::CatmullRom; }
CurveWrap curveWrap(unsigned wrap) { return wrap == 1 ? CurveWrap::Periodic : CurveWrap::Nonperiodic; }

/// Values of "varying" scope on a curve of @a n control points: one per segment end (linear
/// curves: one per point).
std::size_t varyingCount(std::uint32_t n, bool linear, unsigned basis, unsigned wrap)
{
    return linear ? n : cubicVaryingCount(cubicBasis(basis), curveWrap(wrap), n);
}

struct PropertyIn
{
    std::string name, metaData;
    PropertyType type = kCompound;
    unsigned pod = 0, extent = 0;
    std::uint32_t numSamples = 0;
    bool constant = false;  // every sample the same (one stored)
    std::size_t child = 0;  // its group's index in the compound
};

/// The value of @a key in serialized metadata "k1=v1;k2=v2" ("" if absent).
std::string metaValue(const std::string& md, const std::string& key)
{
    std::size_t at = 0;
    while (at < md.size()) {
        std::size_t end = md.find(';', at);
        if (end == std::string::npos) end = md.size();
        const std::size_t eq = md.find('=', at);
        if (eq != std::string::npos && eq < end && md.compare(at, eq - at, key) == 0) {
            return md.substr(eq + 1, end - eq - 1);
        }
        at = end + 1;
    }
    return {};
}

/// One curve as a polyline, with its widths and colours where the object has them.
struct Polyline
{
    std::vector<Vec3f> points;
    std::vector<float> widths;
    std::vector<Vec3f> colors;
};

/// The property named @a name among @a fields, or null.
const PropertyIn* findField(const std::vector<PropertyIn>& fields, const char* name)
{
    for (const PropertyIn& p : fields) if (p.name == name) return &p;
    return nullptr;
}

class AbcReader
{
public:
    AbcReader(const std::string& path, const ReadOptions& opts, ReadReport* report)
        : mWhere("readAbc(" + path + ")"), mFile(path, mWhere, opts.interrupter),
          mOgawa(mFile.data(), mFile.size(), mWhere), mOpts(opts), mReport(report) {}

    StrandSet read();

private:
    std::uint32_t readU32(const ogawa::Reader::Data& d, std::uint64_t& at, unsigned hint, const char* what) const
    {
        const unsigned n = hint == 0 ? 1 : hint == 1 ? 2 : 4;
        if (at + n > d.size) {
            mOgawa.failAt(d.pos + 8 + at, std::string(what) + " needs " + std::to_string(n) +
                                              " bytes but the header block ends at its byte " + std::to_string(d.size));
        }
        std::uint32_t v = 0;
        for (unsigned i = 0; i < n; ++i) v |= std::uint32_t(static_cast<unsigned char>(d.bytes[at + i])) << (8 * i);
        at += n;
        return v;
    }
    std::string readString(const ogawa::Reader::Data& d, std::uint64_t& at, std::uint32_t n, const char* what) const
    {
        if (n > d.size - at) {
            mOgawa.failAt(d.pos + 8 + at, std::string(what) + " of " + std::to_string(n) +
                                              " bytes runs past the header block's " + std::to_string(d.size) + " bytes");
        }
        std::string s(d.bytes + at, std::size_t(n));
        at += n;
        return s;
    }
    std::string indexedMetaData(std::uint32_t index, std::uint64_t at) const
    {
        if (index == 0) return {};
        if (index - 1 >= mIndexedMetaData.size()) {
            mOgawa.failAt(at, "metadata index " + std::to_string(index) + " but the archive has " +
                                  std::to_string(mIndexedMetaData.size()) + " indexed metadata strings");
        }
        return mIndexedMetaData[index - 1];
    }
    void enterGroup(std::uint64_t pos, const std::string& what)
    {
        if (pos != 0 && !mVisited.insert(pos).second) {
            mOgawa.failAt(pos, what + ": group reached a second time; Alembic's groups form a tree (a cycle?)");
        }
    }

    std::vector<PropertyIn> readPropertyHeaders(const ogawa::Reader::Group& g, const std::string& what) const;
    /// @a object's properties group (entered) and, among them, the compound @a compound (".geom",
    /// ".xform") entered: its group, or nothing when the object has none.
    std::optional<ogawa::Reader::Group> objectCompound(const ogawa::Reader::Group& object, const std::string& name,
                                                       const std::string& compound, std::uint64_t& propsPos);
    /// A Curves object's strands, into @a out (or, for guides, into mGuides): the steps below.
    void readCurves(const ogawa::Reader::Group& object, const std::string& what, const Matrix& world, StrandSet& out);
    struct Curves;
    void readCurveType(const ogawa::Reader::Group& geom, const std::vector<PropertyIn>& fields, Curves& c);
    void readCurveCounts(const ogawa::Reader::Data& dN, Curves& c) const;
    void readCurvePoints(const ogawa::Reader::Data& dP, unsigned pod, const Matrix& world, Curves& c) const;
    void readCurveParams(const ogawa::Reader::Group& geom, const std::vector<PropertyIn>& fields, const Matrix& world, Curves& c);
    void curvePolyline(const Curves& c, std::uint64_t i, std::uint64_t first, std::uint64_t firstVarying, Polyline& poly) const;
    StrandSet curvesToStrands(const Curves& c, std::vector<char>& isGuide) const;
    void addCurves(StrandSet&& set, std::vector<char>& isGuide, StrandSet& out);
    /// The local matrix of an Xform object (AbcGeom's XformSample::getMatrix) and whether it
    /// inherits its parent's.
    Matrix readXform(const ogawa::Reader::Group& object, const std::string& name, bool& inherits);
    /// Sample 0 of a scalar property: its bytes after the digest.
    ogawa::Reader::Data scalarSample(const ogawa::Reader::Group& compound, const PropertyIn& p, const std::string& what);
    /// Sample 0 of an array property: its bytes, checked to be whole elements of pod x extent.
    ogawa::Reader::Data arraySample(const ogawa::Reader::Group& compound, const PropertyIn& p,
                                    const std::string& what, std::uint64_t& count);
    struct ArbParams;
    ArbParams readArbGeomParams(const ogawa::Reader::Group& geom, const PropertyIn& arb, const std::string& what,
                                std::uint64_t numPoints, std::uint64_t numCurves);
    std::vector<float> floatParam(const ogawa::Reader::Group& compound, const PropertyIn& p,
                                  unsigned extent, const std::string& what, std::string& scope);
    void warn(const std::string& msg)
    {
        if (mReport) mReport->warnings.push_back(mWhere + ": " + msg);
    }

    std::string mWhere;
    MappedFile mFile;
    ogawa::Reader mOgawa;
    const ReadOptions& mOpts;
    ReadReport* mReport;
    std::vector<std::string> mIndexedMetaData;
    std::unordered_set<std::uint64_t> mVisited;
    StrandSet mGuides;  ///< the curves whose groom_guide is not 0
    bool mWarnedAnimated = false;
};

std::vector<PropertyIn> AbcReader::readPropertyHeaders(const ogawa::Reader::Group& g, const std::string& what) const
{
    std::vector<PropertyIn> props;
    if (g.children.empty()) return props;
    const ogawa::Reader::Data d = mOgawa.childData(g, g.children.size() - 1, what + " property headers");
    std::uint64_t at = 0;
    while (at < d.size) {
        const std::uint64_t start = d.pos + 8 + at;
        PropertyIn p;
        const std::uint32_t info = readU32(d, at, 2, "property info");
        const unsigned hint = (info >> 2) & 3;
        if (hint == 3) mOgawa.failAt(start, what + ": property info " + std::to_string(info) + " has size hint 3; hints are 0, 1 or 2");
        const unsigned kind = info & 3;
        p.type = kind == 0 ? kCompound : kind == 1 ? kScalar : kArray;
        if (p.type != kCompound) {
            p.pod = (info >> 4) & 0xf;
            p.extent = (info >> 12) & 0xff;
            if (p.pod >= 12 || p.extent == 0) {
                mOgawa.failAt(start, what + ": property of pod " + std::to_string(p.pod) + " and extent " +
                                         std::to_string(p.extent) + "; numeric pods are 0-11 with an extent of at least 1");
            }
            p.numSamples = readU32(d, at, hint, "sample count");
            p.constant = (info & 0x800) != 0;
            if (info & 0x200) { readU32(d, at, hint, "first changed"); readU32(d, at, hint, "last changed"); }
            if (info & 0x100) readU32(d, at, hint, "time sampling index");
        }
        const std::uint32_t nameSize = readU32(d, at, hint, "property name size");
        p.name = readString(d, at, nameSize, "property name");
        const std::uint32_t mdi = (info >> 20) & 0xff;
        if (mdi == 255) {
            const std::uint32_t mdSize = readU32(d, at, hint, "metadata size");
            p.metaData = readString(d, at, mdSize, "property metadata");
        } else {
            p.metaData = indexedMetaData(mdi, start);
        }
        p.child = props.size();
        if (p.child >= g.children.size() - 1) {
            mOgawa.failAt(start, what + ": property header " + std::to_string(p.child) + " (" + p.name +
                                     ") has no group: the compound has " + std::to_string(g.children.size() - 1));
        }
        props.push_back(std::move(p));
    }
    return props;
}

ogawa::Reader::Data AbcReader::arraySample(const ogawa::Reader::Group& compound, const PropertyIn& p,
                                           const std::string& what, std::uint64_t& count)
{
    const std::uint64_t pos = mOgawa.childGroup(compound, p.child, what);
    enterGroup(pos, what);
    const ogawa::Reader::Group g = mOgawa.group(pos, what);
    if (p.numSamples > 1 && !p.constant && !mWarnedAnimated) {
        mWarnedAnimated = true;
        warn(what + " has " + std::to_string(p.numSamples) + " samples; the first is read (animation is not)");
    }
    if (p.numSamples == 0 || g.children.empty()) { count = 0; return {}; }
    ogawa::Reader::Data d = mOgawa.childData(g, 0, what + " sample 0");
    if (d.size == 0) { count = 0; return d; }
    if (d.size < 16) mOgawa.failAt(d.pos, what + ": sample of " + std::to_string(d.size) + " bytes; a sample starts with a 16-byte digest");
    d.bytes += 16;
    d.size -= 16;
    const std::uint64_t element = std::uint64_t(kPodBytes[p.pod]) * p.extent;
    if (d.size % element != 0) {
        mOgawa.failAt(d.pos, what + ": sample of " + std::to_string(d.size) + " bytes is not a whole number of " +
                                 std::to_string(element) + "-byte elements");
    }
    count = d.size / element;
    return d;
}

std::vector<float> AbcReader::floatParam(const ogawa::Reader::Group& compound, const PropertyIn& p,
                                         unsigned extent, const std::string& what, std::string& scope)
{
    scope = metaValue(p.metaData, "geoScope");
    std::vector<float> vals;
    auto readVals = [&](const ogawa::Reader::Group& g, const PropertyIn& v) {
        if (v.type != kArray || v.pod != kFloat32 || v.extent != extent) {
            mOgawa.failAt(g.pos, what + " (" + v.name + ") has pod " + std::to_string(v.pod) + " and extent " +
                                     std::to_string(v.extent) + "; float32 with extent " + std::to_string(extent) + " is read");
        }
        std::uint64_t n = 0;
        const ogawa::Reader::Data d = arraySample(g, v, what, n);
        vals.resize(std::size_t(n * extent));
        if (n) std::memcpy(vals.data(), d.bytes, std::size_t(d.size));
    };
    if (p.type != kCompound) { readVals(compound, p); return vals; }
    // An indexed geometry parameter: a compound of .vals and .indices.
    const std::uint64_t pos = mOgawa.childGroup(compound, p.child, what);
    enterGroup(pos, what);
    const ogawa::Reader::Group g = mOgawa.group(pos, what);
    const std::vector<PropertyIn> sub = readPropertyHeaders(g, what);
    const PropertyIn *pv = nullptr, *pi = nullptr;
    for (const PropertyIn& s : sub) { if (s.name == ".vals") pv = &s; if (s.name == ".indices") pi = &s; }
    if (!pv) mOgawa.failAt(g.pos, what + ": indexed parameter without .vals");
    readVals(g, *pv);
    if (scope.empty()) scope = metaValue(pv->metaData, "geoScope");
    if (!pi) return vals;
    if (pi->type != kArray || pi->pod != kUint32 || pi->extent != 1) {
        mOgawa.failAt(g.pos, what + ".indices has pod " + std::to_string(pi->pod) + "; uint32 indices are read");
    }
    std::uint64_t n = 0;
    const ogawa::Reader::Data d = arraySample(g, *pi, what + ".indices", n);
    std::vector<float> out(std::size_t(n * extent));
    const std::uint64_t numVals = vals.size() / extent;
    for (std::uint64_t i = 0; i < n; ++i) {
        std::uint32_t k;
        std::memcpy(&k, d.bytes + 4 * i, 4);
        if (k >= numVals) {
            mOgawa.failAt(d.pos + 24 + 4 * i, what + ".indices[" + std::to_string(i) + "] = " + std::to_string(k) +
                                                  " but .vals has " + std::to_string(numVals) + " values");
        }
        std::copy_n(vals.begin() + k * extent, extent, out.begin() + i * extent);
    }
    return out;
}

StrandSet AbcReader::read()
{
    // The archive: version, library version, top object, metadata, time samplings, indexed metadata.
    const ogawa::Reader::Group root = mOgawa.group(mOgawa.rootPos(), "archive root");
    if (root.children.size() < 6) {
        mOgawa.failAt(root.pos, "archive root group has " + std::to_string(root.children.size()) +
                                    " children; an Alembic archive has 6 (version, library version, top object, "
                                    "metadata, time samplings, indexed metadata)");
    }
    const ogawa::Reader::Data version = mOgawa.childData(root, 0, "archive version");
    std::int32_t fileVersion = -1;
    if (version.size == 4) std::memcpy(&fileVersion, version.bytes, 4);
    if (fileVersion != kOgawaFileVersion) {
        mOgawa.failAt(version.pos, "archive file version " + std::to_string(fileVersion) + " (" +
                                       std::to_string(version.size) + " bytes); version 0 (4 bytes) is read");
    }
    const ogawa::Reader::Data md = mOgawa.childData(root, 5, "indexed metadata");
    for (std::uint64_t at = 0; at < md.size;) {
        const unsigned n = static_cast<unsigned char>(md.bytes[at++]);
        if (n > md.size - at) mOgawa.failAt(md.pos + 8 + at, "indexed metadata string of " + std::to_string(n) + " bytes runs past its block");
        mIndexedMetaData.emplace_back(md.bytes + at, n);
        at += n;
    }

    // Objects depth first, children in file order, with an explicit stack.
    StrandSet out;
    struct Item { std::uint64_t pos; std::string name, metaData; Matrix world; };
    std::vector<Item> stack{{mOgawa.childGroup(root, 2, "top object"), "", "", kIdentity}};
    std::size_t curveObjects = 0;
    InterruptPoll poll(mOpts.interrupter, mWhere);
    while (!stack.empty()) {
        poll();
        const Item item = std::move(stack.back());
        stack.pop_back();
        const std::string what = "object " + (item.name.empty() ? std::string("/") : item.name);
        enterGroup(item.pos, what);
        const ogawa::Reader::Group g = mOgawa.group(item.pos, what);
        if (g.children.empty()) continue;
        const std::string schema = metaValue(item.metaData, "schema");
        Matrix world = item.world;
        if (schema.rfind("AbcGeom_Curve_v", 0) == 0) {
            readCurves(g, item.name, world, out);
            ++curveObjects;
        } else if (schema.rfind("AbcGeom_Xform_v", 0) == 0) {
            bool inherits = true;
            const Matrix local = readXform(g, item.name, inherits);
            world = inherits ? multiply(local, item.world) : local;  // row vectors: local first
        }
        // Children: headers in the last block (ending with 32 bytes of hashes), groups 1..n.
        const ogawa::Reader::Data h = mOgawa.childData(g, g.children.size() - 1, what + " child headers");
        std::vector<Item> children;
        const std::uint64_t end = h.size > 32 ? h.size - 32 : 0;
        ogawa::Reader::Data body = h;
        body.size = end;
        for (std::uint64_t at = 0; at < end;) {
            const std::uint64_t start = h.pos + 8 + at;
            const std::uint32_t nameSize = readU32(body, at, 2, "object name size");
            Item child;
            child.name = item.name + "/" + readString(body, at, nameSize, "object name");
            const std::uint32_t mdi = readU32(body, at, 0, "object metadata index");
            if (mdi == 255) {
                const std::uint32_t mdSize = readU32(body, at, 2, "object metadata size");
                child.metaData = readString(body, at, mdSize, "object metadata");
            } else {
                child.metaData = indexedMetaData(mdi, start);
            }
            child.world = world;
            const std::size_t index = children.size() + 1;
            if (index + 1 >= g.children.size()) {
                mOgawa.failAt(start, what + ": child header " + std::to_string(index - 1) + " (" + child.name +
                                         ") has no group: the object has " + std::to_string(g.children.size()) + " children");
            }
            child.pos = mOgawa.childGroup(g, index, child.name);
            children.push_back(std::move(child));
        }
        for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back(std::move(*it));
    }
    if (curveObjects == 0) {
        throw FormatError(mWhere + ": no Curves object (schema AbcGeom_Curve_v2) in the archive");
    }
    // Simulation guides beside the hair (Unreal's groom_guide): the hair is what is read.
    if (mGuides.numStrands() > 0) {
        if (out.numStrands() == 0) return std::move(mGuides);
        warn(std::to_string(mGuides.numStrands()) + " guide curves (groom_guide = 1) left out; the " + std::to_string(out.numStrands()) +
             " other curves are the hair read");
    }
    return out;
}

ogawa::Reader::Data AbcReader::scalarSample(const ogawa::Reader::Group& compound, const PropertyIn& p, const std::string& what)
{
    const std::uint64_t pos = mOgawa.childGroup(compound, p.child, what);
    const ogawa::Reader::Group g = mOgawa.group(pos, what);
    ogawa::Reader::Data d = mOgawa.childData(g, 0, what + " sample 0");
    const std::uint64_t bytes = std::uint64_t(kPodBytes[p.pod]) * p.extent;
    if (d.size != 16 + bytes) {
        mOgawa.failAt(d.pos, what + ": sample of " + std::to_string(d.size) + " bytes; 16 + " + std::to_string(bytes) + " expected");
    }
    if (p.numSamples > 1 && !p.constant && !mWarnedAnimated) {
        mWarnedAnimated = true;
        warn(what + " has " + std::to_string(p.numSamples) + " samples; the first is read (animation is not)");
    }
    d.bytes += 16;
    d.size -= 16;
    return d;
}

std::optional<ogawa::Reader::Group> AbcReader::objectCompound(const ogawa::Reader::Group& object, const std::string& name,
                                                              const std::string& compound, std::uint64_t& propsPos)
{
    propsPos = mOgawa.childGroup(object, 0, name + " properties");
    enterGroup(propsPos, name + " properties");
    const ogawa::Reader::Group props = mOgawa.group(propsPos, name + " properties");
    const PropertyIn* header = nullptr;
    const std::vector<PropertyIn> top = readPropertyHeaders(props, name);
    for (const PropertyIn& p : top) if (p.name == compound && p.type == kCompound) header = &p;
    if (!header) return std::nullopt;
    const std::string what = name + "/" + compound;
    const std::uint64_t pos = mOgawa.childGroup(props, header->child, what);
    enterGroup(pos, what);
    return mOgawa.group(pos, what);
}

Matrix AbcReader::readXform(const ogawa::Reader::Group& object, const std::string& name, bool& inherits)
{
    // The object's properties, then its .xform compound: .ops (one byte per operation, type in
    // the high 4 bits), .vals (float64 channels, scalar or array), .inherits (bool).
    const std::string what = name + "/.xform";
    std::uint64_t propsPos = 0;
    const std::optional<ogawa::Reader::Group> found = objectCompound(object, name, ".xform", propsPos);
    if (!found) return kIdentity;
    const ogawa::Reader::Group& xform = *found;
    const std::vector<PropertyIn> fields = readPropertyHeaders(xform, what);
    std::vector<std::uint8_t> ops;
    std::vector<double> vals;
    for (const PropertyIn& p : fields) {
        if (p.name == ".inherits" && p.type == kScalar && p.pod == 0 && p.extent == 1) {
            inherits = scalarSample(xform, p, what + "/.inherits").bytes[0] != 0;
        } else if (p.name == ".ops" && p.type == kScalar && p.pod == kUint8) {
            const ogawa::Reader::Data d = scalarSample(xform, p, what + "/.ops");
            ops.assign(d.bytes, d.bytes + d.size);
        } else if (p.name == ".vals" && p.pod == kFloat64) {
            std::uint64_t n = 0;
            const ogawa::Reader::Data d = p.type == kScalar ? scalarSample(xform, p, what + "/.vals")
                                                            : arraySample(xform, p, what + "/.vals", n);
            vals.resize(std::size_t(d.size / 8));
            if (!vals.empty()) std::memcpy(vals.data(), d.bytes, vals.size() * 8);
        }
    }
    Matrix m = kIdentity;
    const std::string rule = composeAbcOps(ops, vals, m);
    if (!rule.empty()) throw FormatError(mWhere + ": " + what + ": " + rule);
    return m;
}

/// What readCurves() takes from `.arbGeomParams`: Cd (colour; per control point, or one value
/// for the curve or the object), Unreal's groom_root_uv and groom_id (per curve) and groom_width
/// (per control point; used where `width` is absent).
struct AbcReader::ArbParams
{
    std::vector<float> cd, rootUV, groomWidth;
    std::string cdScope;
    std::vector<std::int32_t> ids;
    std::vector<std::int32_t> guide;  ///< groom_guide: one value (the object) or one per curve
};

AbcReader::ArbParams AbcReader::readArbGeomParams(const ogawa::Reader::Group& geom, const PropertyIn& arb, const std::string& what,
                                                  std::uint64_t numPoints, std::uint64_t numCurves)
{
    ArbParams out;
    const std::string here = what + "/.geom/.arbGeomParams";
    const std::uint64_t pos = mOgawa.childGroup(geom, arb.child, here);
    enterGroup(pos, here);
    const ogawa::Reader::Group g = mOgawa.group(pos, here);
    std::string scope;
    for (const PropertyIn& p : readPropertyHeaders(g, here)) {
        if (p.name == "Cd" && p.pod == kFloat32 && p.extent == 3) {
            out.cd = floatParam(g, p, 3, here + "/Cd", out.cdScope);
            const std::uint64_t need = out.cdScope == "con" ? 1 : out.cdScope == "uni" ? numCurves : numPoints;
            if (out.cd.size() != 3 * need) {
                warn(here + "/Cd has " + std::to_string(out.cd.size() / 3) + " values but scope '" + out.cdScope + "' needs " + std::to_string(need) + "; ignored");
                out.cd.clear();
            }
        } else if (p.name == "groom_root_uv" && p.pod == kFloat32 && p.extent == 2) {
            out.rootUV = floatParam(g, p, 2, here + "/groom_root_uv", scope);
            if (out.rootUV.size() != 2 * numCurves) out.rootUV.clear();
        } else if (p.name == "groom_width" && p.pod == kFloat32 && p.extent == 1) {
            out.groomWidth = floatParam(g, p, 1, here + "/groom_width", scope);
            if (out.groomWidth.size() != numPoints) out.groomWidth.clear();
        } else if (p.name == "groom_guide" && p.type != kCompound && (p.pod == kInt8 || p.pod == kInt16 || p.pod == kInt32) && p.extent == 1) {
            std::uint64_t n = 1;
            const ogawa::Reader::Data d = p.type == kArray ? arraySample(g, p, here + "/groom_guide", n) : scalarSample(g, p, here + "/groom_guide");
            const unsigned size = kPodBytes[p.pod];
            if ((n == 1 || n == numCurves) && d.size == n * size) {
                for (std::uint64_t i = 0; i < n; ++i) {
                    std::int32_t v = 0;
                    if (size == 1) v = std::int8_t(d.bytes[i]);
                    else if (size == 2) { std::int16_t x; std::memcpy(&x, d.bytes + 2 * i, 2); v = x; }
                    else std::memcpy(&v, d.bytes + 4 * i, 4);
                    out.guide.push_back(v);
                }
            } else {
                warn(here + "/groom_guide has " + std::to_string(n) + " values for " + std::to_string(numCurves) + " curves; one, or one per curve, is read; ignored");
            }
        } else if (p.name == "groom_id" && p.type == kArray && p.pod == kInt32 && p.extent == 1) {
            std::uint64_t n = 0;
            const ogawa::Reader::Data d = arraySample(g, p, here + "/groom_id", n);
            if (n == numCurves) {
                out.ids.resize(std::size_t(n));
                if (n) std::memcpy(out.ids.data(), d.bytes, std::size_t(4 * n));
            }
        }
    }
    return out;
}

/// One Curves object as readCurves() reads it, step by step.
struct AbcReader::Curves
{
    std::string what;                       ///< the object's name, for messages
    std::uint64_t numPoints = 0, numCurves = 0;
    std::uint64_t countsPos = 0;            ///< where nVertices' sample is, for messages
    std::vector<std::uint32_t> counts;      ///< control points per curve
    std::vector<Vec3f> points;              ///< the control points, in world space
    bool linear = false;
    unsigned wrap = 0, basis = 0;
    std::vector<float> widths, uvs;
    std::string widthScope, uvScope;
    ArbParams arb;
    bool uvPerCurve = false, perVertexColor = false;  ///< uvs: one a curve; arb.cd: one a control point or a curve
};

void AbcReader::readCurves(const ogawa::Reader::Group& object, const std::string& what, const Matrix& world, StrandSet& out)
{
    Curves c;
    c.what = what;
    // The object's properties, then its .geom compound.
    std::uint64_t propsPos = 0;
    const std::optional<ogawa::Reader::Group> found = objectCompound(object, what, ".geom", propsPos);
    if (!found) mOgawa.failAt(propsPos, what + ": a Curves object without its .geom compound");
    const ogawa::Reader::Group& geom = *found;
    const std::vector<PropertyIn> fields = readPropertyHeaders(geom, what + "/.geom");

    // Points and counts, of the types read.
    const PropertyIn* pP = findField(fields, "P");
    const PropertyIn* pN = findField(fields, "nVertices");
    if (!pP || !pN) mOgawa.failAt(geom.pos, what + ": Curves without " + (pP ? "nVertices" : "P"));
    if (pP->type != kArray || pP->extent != 3 || (pP->pod != kFloat32 && pP->pod != kFloat64)) {
        mOgawa.failAt(geom.pos, what + "/P has pod " + std::to_string(pP->pod) + " and extent " +
                                    std::to_string(pP->extent) + "; float32 or float64 points of extent 3 are read");
    }
    if (pN->type != kArray || pN->extent != 1 || pN->pod != kInt32) {
        mOgawa.failAt(geom.pos, what + "/nVertices has pod " + std::to_string(pN->pod) + "; int32 counts are read");
    }
    const ogawa::Reader::Data dP = arraySample(geom, *pP, what + "/P", c.numPoints);
    const ogawa::Reader::Data dN = arraySample(geom, *pN, what + "/nVertices", c.numCurves);

    readCurveType(geom, fields, c);
    readCurveCounts(dN, c);
    readCurvePoints(dP, pP->pod, world, c);
    readCurveParams(geom, fields, world, c);
    std::vector<char> isGuide;  // per kept curve
    StrandSet set = curvesToStrands(c, isGuide);
    addCurves(std::move(set), isGuide, out);
}

/// The curves' type, wrap and basis (curveBasisAndType), refusing the kinds not read.
void AbcReader::readCurveType(const ogawa::Reader::Group& geom, const std::vector<PropertyIn>& fields, Curves& c)
{
    const std::string& what = c.what;
    std::uint8_t basisAndType[4] = {1, 0, 0, 0};
    if (const PropertyIn* pB = findField(fields, "curveBasisAndType")) {
        if (pB->type != kScalar || pB->pod != kUint8 || pB->extent != 4) {
            mOgawa.failAt(geom.pos, what + "/curveBasisAndType has pod " + std::to_string(pB->pod) + " and extent " +
                                        std::to_string(pB->extent) + "; uint8 x 4 is read");
        }
        const std::uint64_t pos = mOgawa.childGroup(geom, pB->child, what + "/curveBasisAndType");
        const ogawa::Reader::Group g = mOgawa.group(pos, what + "/curveBasisAndType");
        const ogawa::Reader::Data d = mOgawa.childData(g, 0, what + "/curveBasisAndType sample 0");
        if (d.size != 20) mOgawa.failAt(d.pos, what + "/curveBasisAndType sample of " + std::to_string(d.size) + " bytes; 16 + 4 expected");
        std::memcpy(basisAndType, d.bytes + 16, 4);
    }
    const unsigned type = basisAndType[0], wrap = basisAndType[1], basis = basisAndType[2];
    if (type > 2 || wrap > 1 || basis > 5) {
        mOgawa.failAt(geom.pos, what + ": curveBasisAndType (" + std::to_string(type) + ", " + std::to_string(wrap) + ", " +
                                    std::to_string(basis) + "): type 0-2, wrap 0-1, basis 0-5");
    }
    c.wrap = wrap;
    c.basis = basis;
    c.linear = type == 1;
    if (type == 2) {  // variable order: linear only when every order is 2
        const PropertyIn* pO = findField(fields, "orders");
        std::uint64_t n = 0;
        const ogawa::Reader::Data d = pO && pO->pod == kUint8 ? arraySample(geom, *pO, what + "/orders", n) : ogawa::Reader::Data{};
        for (std::uint64_t i = 0; i < n; ++i) {
            if (static_cast<unsigned char>(d.bytes[i]) != 2) {
                throw UnsupportedError(mWhere + ": " + what + ": NURBS curves (kVariableOrder, order " +
                                       std::to_string(static_cast<unsigned char>(d.bytes[i])) + ") are not read; linear and cubic curves are");
            }
        }
        if (n == 0) throw UnsupportedError(mWhere + ": " + what + ": kVariableOrder curves without orders are not read");
        c.linear = true;
    } else if (!c.linear && (basis == 0 || basis >= 4)) {
        throw UnsupportedError(mWhere + ": " + what + ": cubic curves of basis " + std::to_string(basis) +
                               " (" + (basis == 4 ? "hermite" : basis == 5 ? "power" : "none") +
                               ") are not read; bezier, bspline and catmullrom are");
    }
}

/// The control points of each curve (nVertices at @a dN), which must add up to the points (each
/// bounded by the points, so no sum overflows).
void AbcReader::readCurveCounts(const ogawa::Reader::Data& dN, Curves& c) const
{
    c.countsPos = dN.pos;
    c.counts.resize(static_cast<std::size_t>(c.numCurves));
    std::uint64_t total = 0;
    for (std::uint64_t i = 0; i < c.numCurves; ++i) {
        std::int32_t n;
        std::memcpy(&n, dN.bytes + 4 * i, 4);
        if (n < 0 || std::uint64_t(n) > c.numPoints - total) {
            mOgawa.failAt(dN.pos + 24 + 4 * i, c.what + "/nVertices[" + std::to_string(i) + "] = " + std::to_string(n) +
                                                   " but only " + std::to_string(c.numPoints - total) + " of the " +
                                                   std::to_string(c.numPoints) + " points remain");
        }
        c.counts[i] = std::uint32_t(n);
        total += std::uint64_t(n);
    }
    if (total != c.numPoints) {
        mOgawa.failAt(dN.pos, c.what + "/nVertices add up to " + std::to_string(total) + " but P has " +
                                  std::to_string(c.numPoints) + " points");
    }
}

/// The control points (P at @a dP, of @a pod float32 or float64), checked finite, then moved by
/// the parent Xforms' transform @a world.
void AbcReader::readCurvePoints(const ogawa::Reader::Data& dP, unsigned pod, const Matrix& world, Curves& c) const
{
    std::vector<Vec3f>& points = c.points;
    points.resize(static_cast<std::size_t>(c.numPoints));
    if (pod == kFloat32) {
        if (c.numPoints) std::memcpy(points.data(), dP.bytes, std::size_t(dP.size));
    } else {
        for (std::uint64_t i = 0; i < c.numPoints; ++i) {
            double v[3];
            std::memcpy(v, dP.bytes + 24 * i, 24);
            points[i] = Vec3f(float(v[0]), float(v[1]), float(v[2]));
        }
    }
    if (!allFinite(points.data(), 3 * points.size())) {
        for (std::size_t i = 0; i < points.size(); ++i) {
            const std::size_t bytes = pod == kFloat32 ? 12 : 24;
            checkFinite(points[i], i, mWhere, "at byte " + std::to_string(dP.pos + 24 + bytes * i) + ": " + c.what + "/P");
        }
    }
    if (world != kIdentity) {  // the parent Xforms' transform, in double precision
        for (Vec3f& p : points) p = transformPoint(world, p);
        if (!allFinite(points.data(), 3 * points.size())) {
            throw FormatError(mWhere + ": " + c.what + ": a point is not finite after its parents' transform");
        }
    }
}

/// Widths, root UVs and the arbitrary parameters (colour, Unreal's groom_*), their sizes fixed
/// by their scope: a size that does not fit is warned about and the values ignored.
void AbcReader::readCurveParams(const ogawa::Reader::Group& geom, const std::vector<PropertyIn>& fields, const Matrix& world,
                                Curves& c)
{
    const std::string& what = c.what;
    if (const PropertyIn* pW = findField(fields, "width")) c.widths = floatParam(geom, *pW, 1, what + "/width", c.widthScope);
    if (const PropertyIn* pU = findField(fields, "uv")) c.uvs = floatParam(geom, *pU, 2, what + "/uv", c.uvScope);
    if (const PropertyIn* pA = findField(fields, ".arbGeomParams"); pA && pA->type == kCompound) {
        c.arb = readArbGeomParams(geom, *pA, what, c.numPoints, c.numCurves);
    }
    if (c.widths.empty() && !c.arb.groomWidth.empty()) { c.widths = std::move(c.arb.groomWidth); c.widthScope = "vtx"; }
    if (c.uvs.empty() && !c.arb.rootUV.empty()) { c.uvs = std::move(c.arb.rootUV); c.uvScope = "uni"; }
    if (world != kIdentity) {  // widths scale with the transform, as the points do
        const float scale = float(lengthScale(world));
        for (float& w : c.widths) w *= scale;
    }
    std::size_t numVarying = 0;  // per segment end: one per control point of linear curves
    for (std::uint32_t n : c.counts) numVarying += varyingCount(n, c.linear, c.basis, c.wrap);
    auto widthCount = [&](const std::string& s) -> std::uint64_t {
        if (s == "con") return 1;
        if (s == "uni") return c.numCurves;
        if (s == "var") return numVarying;
        return c.numPoints;  // vtx, fvr or none
    };
    if (!c.widths.empty() && c.widths.size() != widthCount(c.widthScope)) {
        warn(what + "/width has " + std::to_string(c.widths.size()) + " values but scope '" + c.widthScope + "' needs " +
             std::to_string(widthCount(c.widthScope)) + "; widths ignored");
        c.widths.clear();
    }
    c.uvPerCurve = !c.uvs.empty() && c.uvs.size() == 2 * c.numCurves;
    if (!c.uvs.empty() && !c.uvPerCurve) warn(what + "/uv is not one value per curve (scope '" + c.uvScope + "'); ignored");
    c.perVertexColor = !c.arb.cd.empty() && c.arb.cdScope != "con";
}

/// Curve @a i (its control points from @a first, its varying values from @a firstVarying) as a
/// polyline: linear curves as they are (closed when periodic), cubic ones flattened, with widths
/// and colours interpolated along them.
void AbcReader::curvePolyline(const Curves& c, std::uint64_t i, std::uint64_t first, std::uint64_t firstVarying,
                              Polyline& poly) const
{
    const std::uint32_t n = c.counts[i];
    const Vec3f* cp = c.points.data() + first;
    const std::vector<float>& widths = c.widths;
    auto widthOf = [&](std::size_t k, std::size_t m) -> float {  // control k of m along the curve
        if (widths.size() == 1) return widths[0];
        if (c.widthScope == "uni") return widths[i];
        if (c.widthScope == "var") {
            const std::size_t nv = varyingCount(n, c.linear, c.basis, c.wrap);
            return nv ? widths[firstVarying + std::min<std::size_t>(nv - 1, k * nv / std::max<std::size_t>(m, 1))] : 1.f;
        }
        return widths[first + std::min<std::size_t>(k, n - 1)];
    };
    auto colorOf = [&](std::size_t k) {  // control k
        const std::size_t at = c.arb.cdScope == "uni" ? std::size_t(i) : std::size_t(first) + std::min<std::size_t>(k, n - 1);
        return Vec3f(c.arb.cd[3 * at], c.arb.cd[3 * at + 1], c.arb.cd[3 * at + 2]);
    };
    poly.points.clear();
    poly.widths.clear();
    poly.colors.clear();
    if (c.linear) {
        poly.points.assign(cp, cp + n);
        for (std::uint32_t k = 0; k < n; ++k) poly.widths.push_back(widths.empty() ? 0.f : widthOf(k, n));
        if (c.perVertexColor) for (std::uint32_t k = 0; k < n; ++k) poly.colors.push_back(colorOf(k));
        if (c.wrap == 1 && n >= 2) {
            poly.points.push_back(cp[0]);
            poly.widths.push_back(poly.widths.front());
            if (c.perVertexColor) poly.colors.push_back(poly.colors.front());
        }
    } else if (n >= 4) {
        const FreeFormCurve curve = cubicCurve(cubicBasis(c.basis), curveWrap(c.wrap), cp, n);
        const std::string rule = flattenCurve(curve, mOpts.curveSamples, poly.points);
        if (!rule.empty()) throw FormatError(mWhere + ": " + c.what + ": curve " + std::to_string(i) + ": " + rule);
        if (!widths.empty()) {
            for (std::size_t k = 0; k < poly.points.size(); ++k) {
                const CurvePosition at = positionAlong(k, poly.points.size(), n);
                poly.widths.push_back((1.f - at.f) * widthOf(at.i0, n) + at.f * widthOf(at.i1, n));
            }
        }
        for (std::size_t k = 0; c.perVertexColor && k < poly.points.size(); ++k) {
            const CurvePosition at = positionAlong(k, poly.points.size(), n);
            poly.colors.push_back((1.f - at.f) * colorOf(at.i0) + at.f * colorOf(at.i1));
        }
    }
}

/// The curves as strands, with the attributes the object has; the short-strand policy drops
/// curves. @a isGuide gets, per kept curve, whether groom_guide marks it a guide.
StrandSet AbcReader::curvesToStrands(const Curves& c, std::vector<char>& isGuide) const
{
    StrandSet set;
    const bool perVertexWidth = !c.widths.empty() && c.widths.size() > 1;
    ShortStrandFilter filter(mOpts, mReport, mWhere + ": " + c.what);
    Polyline poly;
    std::vector<float> keptWidths;
    std::vector<Vec2f> keptUV;
    std::vector<Vec3f> keptColor;
    std::vector<std::int32_t> keptIds;
    const ArbParams& arb = c.arb;
    std::uint64_t first = 0, firstVarying = 0;
    for (std::uint64_t i = 0; i < c.numCurves; ++i) {
        const std::uint32_t n = c.counts[i];
        curvePolyline(c, i, first, firstVarying, poly);
        firstVarying += varyingCount(n, c.linear, c.basis, c.wrap);
        first += n;
        if (!filter.keep(std::size_t(i), poly.points.size(), "at byte " + std::to_string(c.countsPos + 24 + 4 * i))) continue;
        set.addStrand(poly.points);
        if (perVertexWidth) keptWidths.insert(keptWidths.end(), poly.widths.begin(), poly.widths.end());
        if (c.uvPerCurve) keptUV.emplace_back(c.uvs[2 * i], c.uvs[2 * i + 1]);
        if (c.perVertexColor) keptColor.insert(keptColor.end(), poly.colors.begin(), poly.colors.end());
        if (!arb.ids.empty()) keptIds.push_back(arb.ids[i]);
        isGuide.push_back(!arb.guide.empty() && arb.guide[arb.guide.size() == 1 ? 0 : std::size_t(i)] != 0);
    }
    filter.finish();
    if (!arb.cd.empty() && !c.perVertexColor) set.defaults.color = Vec3f(arb.cd[0], arb.cd[1], arb.cd[2]);
    if (c.perVertexColor) set.color = std::move(keptColor);
    if (!arb.ids.empty()) set.strandId = std::move(keptIds);
    if (c.widths.size() == 1) set.defaults.thickness = c.widths[0];
    if (perVertexWidth) set.thickness = std::move(keptWidths);
    if (c.uvPerCurve) set.rootUV = std::move(keptUV);
    return set;
}

/// @a set's hair into @a out and its guides (per @a isGuide) into mGuides: read() chooses.
void AbcReader::addCurves(StrandSet&& set, std::vector<char>& isGuide, StrandSet& out)
{
    auto add = [](StrandSet& to, StrandSet&& from) {
        if (to.empty() && to.positions.empty()) to = std::move(from);
        else to.append(std::move(from));
    };
    const std::size_t guides = std::size_t(std::count(isGuide.begin(), isGuide.end(), char(1)));
    if (guides == 0) {
        add(out, std::move(set));
    } else if (guides == set.numStrands()) {
        add(mGuides, std::move(set));
    } else {
        add(mGuides, selectStrands(set, isGuide));
        for (char& g : isGuide) g = !g;
        add(out, selectStrands(set, isGuide));
    }
}

} // namespace

StrandSet readAbc(const std::string& path, const ReadOptions& opts, ReadReport* report)
{
    AbcReader reader(path, opts, report);
    StrandSet s = reader.read();
    s.validate("readAbc(" + path + ")");
    return s;
}

} // namespace vdbhair
