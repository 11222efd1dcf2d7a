#include <vdbhair/io/ConvertStrands.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/AxisName.h>
#include <vdbhair/strands/Resample.h>

#include <cmath>
#include <string>

namespace vdbhair {

namespace {

const char* plyEncodingName(PlyEncoding e) { return e == PlyEncoding::Ascii ? "ascii" : "binary"; }
const char* objLineStyleName(ObjLineStyle s) { return s == ObjLineStyle::Polylines ? "polylines" : "edges"; }

/// The USD stage's upAxis by its option's names: auto (empty: the strands' declared axis, else
/// Y), y or z.
ParamAccess<WriteOptions, std::string> usdUpAccess()
{
    return {[](const WriteOptions& w) -> std::string { return w.usd.upAxis.empty() ? "auto" : w.usd.upAxis == "Z" ? "z" : "y"; },
            [](WriteOptions& w, std::string v) {
                if (v == "auto") w.usd.upAxis.clear();
                else if (v == "y" || v == "z") w.usd.upAxis = v == "z" ? "Z" : "Y";
                else throw ValueError("usd-up '" + v + "' is not one of auto, y, z");
            }};
}

} // namespace

const ParamTable<WriteOptions>& writeParameters()
{
    using P = WriteOptions;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto ply = makeParam<P>("ply-encoding", "PLY output encoding: binary (little-endian) or ascii", "",
                                named<P>([](P& p) -> PlyEncoding& { return p.plyEncoding; }, plyEncodingName, [](const std::string& v) {
                                    if (v == "binary") return PlyEncoding::Binary;
                                    if (v == "ascii") return PlyEncoding::Ascii;
                                    throw ValueError("ply-encoding '" + v + "' is not one of binary, ascii");
                                }));
        ply.choices = {"binary", "ascii"};
        t.push_back(ply);
        auto obj = makeParam<P>("obj-lines",
                                "OBJ output: edges (a two-vertex 'l' per segment, what Blender's importer reads whole) or polylines (one 'l' "
                                "per strand, Houdini)", "",
                                named<P>([](P& p) -> ObjLineStyle& { return p.objLines; }, objLineStyleName, objLineStyleFromName));
        obj.choices = {"edges", "polylines"};
        t.push_back(obj);
        auto codec = makeParam<P>("codec", "VDB output: the position codec, float (exact), fixed16 or fixed8", "",
                                  named<P>([](P& p) -> PositionCodec& { return p.vdb.codec; }, positionCodecName, positionCodecFromName));
        codec.choices = {"float", "fixed16", "fixed8"};
        t.push_back(codec);
        auto voxel = makeParam<P>("voxel-size", "VDB output: the points grid's voxel size", "world units",
                                  member<P>([](P& p) -> double& { return p.vdb.voxelSize; }));
        voxel.min = 0.0;
        voxel.zeroMeans = "about " + std::to_string(VdbPointsOptions{}.pointsPerVoxel) + " points per voxel";
        t.push_back(voxel);
        auto usdUp = makeParam<P>("usd-up", "USD output: the stage's upAxis; coordinates are not rotated (auto: the input's declared axis, else y)",
                                  "", usdUpAccess());
        usdUp.choices = {"auto", "y", "z"};
        usdUp.pythonNone = true;
        t.push_back(usdUp);
        auto mpu = makeParam<P>("meters-per-unit", "USD output: the stage's metersPerUnit; nothing is scaled", "metres",
                                member<P>([](P& p) -> double& { return p.usd.metersPerUnit; }));
        mpu.min = 0.0;
        mpu.zeroMeans = "the input's own, from a USD stage, else 0.01: centimetres";
        t.push_back(mpu);
        // UsdWriteOptions::width is a float: read and written as a double.
        ParamAccess<P, double> widthAccess{[](const P& p) { return double(p.usd.width); }, [](P& p, double v) { p.usd.width = float(v); }};
        auto width = makeParam<P>("width", "USD output: the widths of strands without thickness", "world units", widthAccess);
        width.min = 0.0;
        width.zeroMeans = "the file's own default thickness, else 1/1000 of the bounding box's diagonal";
        t.push_back(width);
        return t;
    }();
    return table;
}

const ParamTable<ConvertParams>& convertParameters()
{
    using P = ConvertParams;
    static const ParamTable<P> table = [] {
        ParamTable<P> t;
        auto resample = makeParam<P>("resample", "Resample every strand to N vertices, at least 2, equally spaced in arc length", "",
                                     member<P>([](P& p) -> std::size_t& { return p.resample; }));
        resample.min = 0;
        resample.zeroMeans = "keep them";
        t.push_back(resample);
        t.push_back(makeParam<P>("scale", "Multiply every position (and thickness) by S, not 0", "",
                                 member<P>([](P& p) -> double& { return p.scale; })));
        auto up = makeParam<P>("up", "The input's up axis, turned onto +Y, vdbhair's and OBJ's convention (cyHair models: z)", "",
                               named<P>([](P& p) -> Vec3d& { return p.up; }, axisName, [](const std::string& v) { return axisFromName(v, "up"); }));
        up.choices = axisNames();
        t.push_back(up);
        for (Param<P>& w : nestedParams<P>(writeParameters(), [](P& p) -> WriteOptions& { return p.write; })) t.push_back(std::move(w));
        return t;
    }();
    return table;
}

void ConvertParams::validate() const
{
    if (resample == 1) throw ParamError<ValueError>({paramName(convertParameters(), "resample"), " 1: a strand needs at least 2 vertices (0 keeps them)"});
    if (!std::isfinite(scale) || scale == 0.0) {
        throw ParamError<ValueError>({paramName(convertParameters(), "scale"), " " + formatNumber(scale) + ": must be finite and non-zero"});
    }
    axisName(up);  // a unit axis
}

void rotateUpToY(StrandSet& strands, const Vec3d& up)
{
    auto map = [&](const Vec3f& p) -> Vec3f {
        if (up.z() > 0.5) return Vec3f(p.x(), p.z(), -p.y());   // -90 deg about X
        if (up.z() < -0.5) return Vec3f(p.x(), -p.z(), p.y());  // +90 deg about X
        if (up.x() > 0.5) return Vec3f(-p.y(), p.x(), p.z());   // +90 deg about Z
        if (up.x() < -0.5) return Vec3f(p.y(), -p.x(), p.z());  // -90 deg about Z
        if (up.y() < -0.5) return Vec3f(p.x(), -p.y(), -p.z()); // 180 deg about X
        return p;
    };
    if (up.y() > 0.5) return;
    for (Vec3f& p : strands.positions) p = map(p);
    strands.upAxis = 'Y';
}

void convertStrands(StrandSet& strands, const ConvertParams& params)
{
    params.validate();
    if (params.scale != 1.0) scaleStrands(strands, float(params.scale));
    rotateUpToY(strands, params.up);
    if (params.resample >= 2) strands = resampleStrands(strands, params.resample);
}

} // namespace vdbhair
