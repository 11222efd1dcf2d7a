// vdbhair.Strands (a StrandSet seen as NumPy arrays), vdbhair.read and vdbhair.write.
#include "Common.h"
#include "Params.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/io/ConvertStrands.h>
#include <vdbhair/io/StrandIO.h>
#include <vdbhair/strands/StrandSet.h>

#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace vdbhair::py {

namespace {


std::string shapeText(const pyb::array& a)
{
    std::ostringstream os;
    os << "(";
    for (pyb::ssize_t d = 0; d < a.ndim(); ++d) os << (d ? ", " : "") << a.shape(d);
    os << (a.ndim() == 1 ? ",)" : ")");
    return os.str();
}

/// @a obj as a C-contiguous array of T with @a cols columns (0: one dimension) and, when
/// @a rows is not -1, that many rows; a ValueError naming @a name and the rule otherwise.
template <typename T>
pyb::array_t<T, pyb::array::c_style | pyb::array::forcecast> checkedArray(const pyb::handle& obj, const char* name,
                                                                         pyb::ssize_t rows, pyb::ssize_t cols,
                                                                         const std::string& rowsRule)
{
    const std::string where = std::string("Strands(") + name + ")";
    pyb::array a = pyb::array::ensure(obj);
    if (!a) throw ValueError(where + ": not convertible to a NumPy array");
    const char kind = a.dtype().kind();
    const bool integral = std::is_integral_v<T>;
    if (integral ? (kind != 'i' && kind != 'u') : (kind != 'f' && kind != 'i' && kind != 'u')) {
        throw ValueError(where + ": dtype " + std::string(pyb::str(a.dtype())) + "; must hold " +
                               (integral ? "integers" : "real numbers"));
    }
    const std::string want = cols == 0 ? std::string("(") + rowsRule + ",)" : "(" + rowsRule + ", " + std::to_string(cols) + ")";
    const bool shapeOk = cols == 0 ? a.ndim() == 1 : (a.ndim() == 2 && a.shape(1) == cols);
    if (!shapeOk || (rows >= 0 && a.shape(0) != rows)) {
        throw ValueError(where + ": shape " + shapeText(a) + "; must be " + want);
    }
    return pyb::array_t<T, pyb::array::c_style | pyb::array::forcecast>::ensure(a);
}

template <typename T>
void checkFiniteValues(const T* data, std::size_t n, std::size_t cols, const char* name, const char* what)
{
    for (std::size_t i = 0; i < n * cols; ++i) {
        if (!std::isfinite(data[i])) {
            throw ValueError(std::string("Strands(") + name + "): " + what + " " + std::to_string(i / cols) +
                                   " is not finite (" + std::to_string(data[i]) + "); values must be finite");
        }
    }
}

/// The constructor: arrays checked by the readers' rules (StrandSet::validate), one copy each.
StrandsPtr makeStrands(const pyb::handle& positions, const pyb::handle& offsets, const pyb::handle& thickness,
                       const pyb::handle& transparency, const pyb::handle& color, const pyb::handle& rootUV,
                       const pyb::handle& strandId)
{
    auto set = std::make_shared<StrandSet>();
    const auto p = checkedArray<float>(positions, "positions", -1, 3, "V");
    const std::size_t nV = std::size_t(p.shape(0));
    if (nV > std::numeric_limits<std::uint32_t>::max()) {
        throw ValueError("Strands(positions): " + std::to_string(nV) + " vertices; at most 2^32-1 fit a strand set");
    }
    for (std::size_t v = 0; v < nV; ++v) {
        const float* q = p.data() + 3 * v;
        if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2])) {
            std::ostringstream os;
            os << "Strands(positions): vertex " << v << " has a non-finite coordinate (" << q[0] << ", " << q[1] << ", " << q[2]
               << "); coordinates must be finite";
            throw ValueError(os.str());
        }
    }
    const auto o = checkedArray<std::int64_t>(offsets, "offsets", -1, 0, "S+1");
    const std::size_t nO = std::size_t(o.shape(0));
    if (nO == 0) throw ValueError("Strands(offsets): empty; must hold S+1 prefix sums starting at 0 ([0] for no strands)");
    if (o.data()[0] != 0) throw ValueError("Strands(offsets): offsets[0] = " + std::to_string(o.data()[0]) + "; must be 0");
    for (std::size_t i = 0; i + 1 < nO; ++i) {
        const std::int64_t a = o.data()[i], b = o.data()[i + 1];
        if (b - a < 2) {
            throw ValueError("Strands(offsets): strand " + std::to_string(i) + " has " + std::to_string(b - a) +
                                   " vertices (offsets[" + std::to_string(i) + "] = " + std::to_string(a) + ", offsets[" +
                                   std::to_string(i + 1) + "] = " + std::to_string(b) + "); a strand needs at least 2");
        }
        if (b > std::int64_t(nV)) {
            throw ValueError("Strands(offsets): offsets[" + std::to_string(i + 1) + "] = " + std::to_string(b) +
                                   " is beyond the " + std::to_string(nV) + " positions");
        }
    }
    if (o.data()[nO - 1] != std::int64_t(nV)) {
        throw ValueError("Strands(offsets): the last offset is " + std::to_string(o.data()[nO - 1]) + " but positions has " +
                               std::to_string(nV) + " rows; it must equal the vertex count");
    }
    const std::size_t nS = nO - 1;
    set->positions.resize(nV);
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f must be three packed floats");
    if (nV) std::memcpy(static_cast<void*>(set->positions.data()), p.data(), nV * sizeof(Vec3f));
    set->offsets.assign(o.data(), o.data() + nO);

    if (!thickness.is_none()) {
        const auto a = checkedArray<float>(thickness, "thickness", pyb::ssize_t(nV), 0, "V");
        checkFiniteValues(a.data(), nV, 1, "thickness", "vertex");
        set->thickness.assign(a.data(), a.data() + nV);
    }
    if (!transparency.is_none()) {
        const auto a = checkedArray<float>(transparency, "transparency", pyb::ssize_t(nV), 0, "V");
        checkFiniteValues(a.data(), nV, 1, "transparency", "vertex");
        set->transparency.assign(a.data(), a.data() + nV);
    }
    if (!color.is_none()) {
        const auto a = checkedArray<float>(color, "color", pyb::ssize_t(nV), 3, "V");
        checkFiniteValues(a.data(), nV, 3, "color", "vertex");
        set->color.resize(nV);
        if (nV) std::memcpy(static_cast<void*>(set->color.data()), a.data(), nV * sizeof(Vec3f));
    }
    if (!rootUV.is_none()) {
        const auto a = checkedArray<float>(rootUV, "root_uv", pyb::ssize_t(nS), 2, "S");
        checkFiniteValues(a.data(), nS, 2, "root_uv", "strand");
        set->rootUV.resize(nS);
        for (std::size_t i = 0; i < nS; ++i) set->rootUV[i] = Vec2f(a.data()[2 * i], a.data()[2 * i + 1]);
    }
    if (!strandId.is_none()) {
        const auto a = checkedArray<std::int64_t>(strandId, "strand_id", pyb::ssize_t(nS), 0, "S");
        set->strandId.resize(nS);
        for (std::size_t i = 0; i < nS; ++i) {
            const std::int64_t id = a.data()[i];
            if (id < std::numeric_limits<std::int32_t>::min() || id > std::numeric_limits<std::int32_t>::max()) {
                throw ValueError("Strands(strand_id): strand " + std::to_string(i) + " has id " + std::to_string(id) +
                                       "; ids must fit in 32 bits");
            }
            set->strandId[i] = std::int32_t(id);
        }
    }
    set->validate("Strands");  // the library's own rules, as the readers apply them
    return set;
}

/// Strand @a i (negative counts from the end) as a read-only (n, 3) view kept alive by @a self.
pyb::array strandView(const pyb::object& self, const StrandSet& s, std::ptrdiff_t i)
{
    const std::ptrdiff_t n = std::ptrdiff_t(s.numStrands());
    if (i < 0) i += n;
    if (i < 0 || i >= n) throw pyb::index_error("strand index out of range (" + std::to_string(n) + " strands)");
    return readOnlyView(reinterpret_cast<const float*>(s.data(std::size_t(i))), s.size(std::size_t(i)), 3, self);
}

/// write()'s keywords: writeParameters(), the declared parameters of how strands are written
/// (the command line's `convert` options), by their Python names, in the declaration's order.
/// The C++ types of writeWithOptions()'s keywords follow that order; writeKeywords() checks them.
const std::vector<std::string>& writeKeywordNames()
{
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const Param<WriteOptions>& p : writeParameters()) n.push_back(p.pythonName());
        return n;
    }();
    return names;
}

/// The keywords' pybind11 arguments, each with the declaration's default.
/// @throw std::logic_error when the declaration no longer matches writeWithOptions()'s types.
std::vector<pyb::arg_v> writeKeywords()
{
    const ParamTable<WriteOptions>& table = writeParameters();
    const std::vector<std::string> types{"str", "str", "str", "float", "Optional[str]", "float", "float"};
    std::vector<std::string> declared;
    for (const Param<WriteOptions>& p : table) declared.push_back(pythonAnnotation(p));
    if (declared != types) throw std::logic_error("write(): writeParameters() changed; update writeWithOptions()'s keywords");
    std::vector<pyb::arg_v> args;
    for (std::size_t i = 0; i < table.size(); ++i) args.emplace_back(writeKeywordNames()[i].c_str(), pythonDefault(table[i]));
    return args;
}

/// write()'s Args for the keywords: each one's help, unit, range and choices from the declaration.
std::string writeKeywordsDoc()
{
    std::string doc;
    for (const Param<WriteOptions>& p : writeParameters()) {
        doc += "    " + p.pythonName() + ": " + paramHelp(p) + " (the CLI's ``convert " + p.flag() + "``" +
               (p.pythonNone ? "; None: " + p.defaultText() : "") + ").\n";
    }
    return doc;
}

void writeWithOptions(const StrandSet& s, const PathArg& path, const std::string& plyEncoding, const std::string& objLines,
                      const std::string& codec, double voxelSize, const std::optional<std::string>& usdUp, double metersPerUnit,
                      double width)
{
    const std::vector<std::string>& k = writeKeywordNames();
    pyb::dict kw;
    kw[k[0].c_str()] = plyEncoding;
    kw[k[1].c_str()] = objLines;
    kw[k[2].c_str()] = codec;
    kw[k[3].c_str()] = voxelSize;
    kw[k[4].c_str()] = usdUp ? pyb::object(pyb::str(*usdUp)) : pyb::object(pyb::none());
    kw[k[5].c_str()] = metersPerUnit;
    kw[k[6].c_str()] = width;
    WriteOptions opts;
    applyKeywords(writeParameters(), kw, opts, "write");
    pyb::gil_scoped_release release;
    writeStrands(path, s, opts);
}

const char* kStrandsDoc = R"doc(A hairstyle: strands (polylines, root to tip) as flat NumPy arrays.

Strand ``i`` is ``positions[offsets[i]:offsets[i+1]]``.

Arrays (all read-only; copy to change them and build a new ``Strands``):

- ``positions``: (V, 3) float32, world units, a **view** of the C++ storage (no copy; it keeps
  this object alive).
- ``offsets``: (S+1,) int64 prefix sums. The library stores 32-bit offsets, so this is **one copy**
  made on each access.
- ``thickness``, ``transparency``: (V,) float32 or None; ``color``: (V, 3) float32 linear RGB or
  None; ``root_uv``: (S, 2) float32 or None; ``strand_id``: (S,) int32 or None. Views, no copy.

``len(strands)`` is S; ``strands[i]`` and iteration give each strand as a read-only (n, 3) view.

The constructor copies its arrays once and checks them by the readers' rules (finite positions,
offsets from 0 to V, at least two vertices a strand, attribute lengths); a broken rule raises
``ValueError`` naming the array and the rule, e.g.
``Strands(offsets): strand 1 has 1 vertices (offsets[1] = 2, offsets[2] = 3); a strand needs at least 2``.)doc";

using StrandsClass = pyb::class_<StrandSet, StrandsPtr>;

/// Strands' constructor and its arrays: positions, offsets, counts and the optional attributes.
void bindStrandArrays(StrandsClass& cls)
{
    cls.def(pyb::init(&makeStrands), pyb::arg("positions"), pyb::arg("offsets"), pyb::kw_only(),
            pyb::arg("thickness") = pyb::none(), pyb::arg("transparency") = pyb::none(), pyb::arg("color") = pyb::none(),
            pyb::arg("root_uv") = pyb::none(), pyb::arg("strand_id") = pyb::none(),
            R"doc(Strands from arrays (each copied once, then checked).

Args:
    positions: (V, 3) real numbers, world units (converted to float32).
    offsets: (S+1,) integers, offsets[0] = 0, offsets[-1] = V, at least 2 vertices a strand.
    thickness: optional (V,) world units.
    transparency: optional (V,), 0 = opaque.
    color: optional (V, 3) linear RGB in [0, 1].
    root_uv: optional (S, 2).
    strand_id: optional (S,) integers that fit in 32 bits.

Raises:
    ValueError: naming the array and the rule it breaks.)doc");
    cls.def_property_readonly(
        "positions",
        [](const pyb::object& self) {
            const StrandSet& s = self.cast<const StrandSet&>();
            return readOnlyView(reinterpret_cast<const float*>(s.positions.data()), s.positions.size(), 3, self);
        },
        "(V, 3) float32 world positions: a read-only view (no copy).");
    cls.def_property_readonly(
        "offsets",
        [](const StrandSet& s) {
            pyb::array_t<std::int64_t> a(pyb::ssize_t(s.offsets.size()));
            std::copy(s.offsets.begin(), s.offsets.end(), a.mutable_data());
            return a;
        },
        "(S+1,) int64 prefix sums into positions: a copy (the library stores uint32).");
    cls.def_property_readonly(
        "counts",
        [](const StrandSet& s) {
            pyb::array_t<std::int64_t> a(pyb::ssize_t(s.numStrands()));
            for (std::size_t i = 0; i < s.numStrands(); ++i) a.mutable_data()[i] = std::int64_t(s.size(i));
            return a;
        },
        "(S,) int64 vertices per strand: a copy.");
    auto optionalView = [](auto member, std::size_t cols, const char* doc) {
        return std::make_pair(
            [member, cols](const pyb::object& self) -> pyb::object {
                const StrandSet& s = self.cast<const StrandSet&>();
                const auto& v = s.*member;
                if (v.empty()) return pyb::none();
                using ElemT = typename std::decay_t<decltype(v)>::value_type;
                if constexpr (std::is_same_v<ElemT, float> || std::is_same_v<ElemT, std::int32_t>) {
                    return readOnlyView(v.data(), v.size(), 0, self);
                } else {
                    return readOnlyView(reinterpret_cast<const float*>(v.data()), v.size(), cols, self);
                }
            },
            doc);
    };
    {
        auto [f, d] = optionalView(&StrandSet::thickness, 0, "(V,) float32 thickness in world units, or None: a view.");
        cls.def_property_readonly("thickness", f, d);
    }
    {
        auto [f, d] = optionalView(&StrandSet::transparency, 0, "(V,) float32 transparency (0 = opaque), or None: a view.");
        cls.def_property_readonly("transparency", f, d);
    }
    {
        auto [f, d] = optionalView(&StrandSet::color, 3, "(V, 3) float32 linear RGB, or None: a view.");
        cls.def_property_readonly("color", f, d);
    }
    {
        auto [f, d] = optionalView(&StrandSet::rootUV, 2, "(S, 2) float32 root UV, or None: a view.");
        cls.def_property_readonly("root_uv", f, d);
    }
    {
        auto [f, d] = optionalView(&StrandSet::strandId, 0, "(S,) int32 ids of an upstream source, or None: a view.");
        cls.def_property_readonly("strand_id", f, d);
    }
}

/// Strands' per-vertex defaults, declared unit and up axis, and convert_units.
void bindStrandDeclarations(StrandsClass& cls)
{
    cls.def_property(
        "defaults",
        [](const StrandSet& s) {
            pyb::dict d;
            d["thickness"] = s.defaults.thickness;
            d["transparency"] = s.defaults.transparency;
            d["color"] = pyb::make_tuple(s.defaults.color.x(), s.defaults.color.y(), s.defaults.color.z());
            return d;
        },
        [](StrandSet& s, const pyb::dict& d) {
            // Checked whole before anything is set: a bad key or value leaves the defaults as they were.
            StrandDefaults next = s.defaults;
            auto finite = [](const char* key, const pyb::handle& v) {
                const float x = v.cast<float>();
                if (!std::isfinite(x)) throw ValueError(std::string("Strands.defaults: ") + key + " = " + std::string(pyb::str(v)) + "; must be a finite number");
                return x;
            };
            for (const auto& [key, value] : d) {
                const std::string k = key.cast<std::string>();
                if (k == "thickness") next.thickness = finite("thickness", value);
                else if (k == "transparency") next.transparency = finite("transparency", value);
                else if (k == "color") {
                    const auto c = value.cast<std::vector<pyb::handle>>();
                    if (c.size() != 3) throw ValueError("Strands.defaults: color has " + std::to_string(c.size()) + " values; must be (r, g, b)");
                    for (int i = 0; i < 3; ++i) next.color[i] = finite("color", c[i]);
                } else {
                    throw ValueError("Strands.defaults: unknown key '" + k + "'; the keys are thickness, transparency, color");
                }
            }
            s.defaults = next;
        },
        "The per-vertex defaults used where an attribute array is None (cyHair's header): a dict. Setting it (a dict "
        "of some or all of its keys) changes those defaults, as a .hair file's header writes them.");
    cls.def_property(
        "meters_per_unit", [](const StrandSet& s) -> pyb::object { return s.metersPerUnit > 0.0 ? pyb::cast(s.metersPerUnit) : pyb::none(); },
        [](StrandSet& s, const pyb::object& v) {
            const double m = v.is_none() ? 0.0 : v.cast<double>();
            if (!(m >= 0.0) || !std::isfinite(m)) {
                throw ValueError("meters_per_unit=" + std::to_string(m) + ": must be a positive length in metres, or None (not declared)");
            }
            s.metersPerUnit = m;
        },
        "The unit the file declared (a USD stage's metersPerUnit), in metres, or None when it declared none. Setting it declares "
        "a unit (nothing is scaled); convert_units() scales.");
    cls.def_property_readonly(
        "up_axis", [](const StrandSet& s) -> pyb::object { return s.upAxis ? pyb::cast(std::string(1, s.upAxis)) : pyb::none(); },
        "The up axis the file declared, \"Y\" or \"Z\", or None.");
    cls.def(
        "convert_units",
        [](StrandSet& s, const pyb::object& unit) {
            const double target = pyb::isinstance<pyb::str>(unit) ? metersPerUnitFromName(unit.cast<std::string>(), "unit") : unit.cast<double>();
            if (!(s.metersPerUnit > 0.0)) {
                throw ValueError("convert_units: the strands declare no unit to convert from; set meters_per_unit first (e.g. 0.01 for centimetres)");
            }
            convertUnits(s, target);
        },
        pyb::arg("unit"),
        "Express the strands in ``unit`` (\"mm\", \"cm\", \"dm\", \"m\", \"in\" or metres as a float), in place: positions and thickness "
        "scaled from meters_per_unit, which becomes ``unit`` (the CLI's ``convert --units``).");
}

/// Strands as a sequence of strands (len, indexing, iteration), its repr and write.
void bindStrandSequence(StrandsClass& cls)
{
    cls.def_property_readonly("num_strands", &StrandSet::numStrands, "S, the number of strands.");
    cls.def_property_readonly("num_vertices", &StrandSet::numVertices, "V, the number of vertices.");
    cls.def("__len__", &StrandSet::numStrands, "The number of strands S.");
    cls.def(
        "__getitem__", [](const pyb::object& self, std::ptrdiff_t i) { return strandView(self, self.cast<const StrandSet&>(), i); },
        pyb::arg("i"), "Strand i (negative from the end) as a read-only (n, 3) float32 view.");
    cls.def(
        "__iter__",
        [](const pyb::object& self) {
            // A generator over the strands; each item is a view kept alive with this object.
            pyb::module_ builtins = pyb::module_::import("builtins");
            const std::size_t n = self.cast<const StrandSet&>().numStrands();
            return builtins.attr("map")(self.attr("__getitem__"), builtins.attr("range")(n));
        },
        "Iterate over the strands, each a read-only (n, 3) float32 view.");
    cls.def("__repr__", [](const StrandSet& s) {
        return "<vdbhair.Strands: " + std::to_string(s.numStrands()) + " strands, " + std::to_string(s.numVertices()) + " vertices>";
    });
    const std::vector<pyb::arg_v> kw = writeKeywords();
    cls.def("write", &writeWithOptions, pyb::arg("path"), pyb::kw_only(), kw[0], kw[1], kw[2], kw[3], kw[4], kw[5], kw[6],
            "Write to ``path`` in the format of its extension (.hair .data .obj .ply .vdb .usda), atomically; see vdbhair.write.");

}

/// vdbhair.read: strands from a file, its keywords the readers' declared options (readParameters()).
void bindRead(pyb::module_& m)
{
    auto readImpl = [](const PathArg& path, const pyb::dict& kw) {
        ReadOptions base;  // the readers name their options as read()'s keywords (ReadOptions::spelling's default)
        applyKeywords(readParameters(), kw, base, "read");
        if (!kw["root_near"].is_none()) {
            const auto xyz = kw["root_near"].cast<std::vector<double>>();
            if (xyz.size() != 3) throw ValueError("read: root_near: must be (x, y, z), got " + std::to_string(xyz.size()) + " numbers");
            base.objRootNear = Vec3f(float(xyz[0]), float(xyz[1]), float(xyz[2]));
        }
        ReadReport report;
        auto set = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            ReadOptions opts = base;
            opts.interrupter = interrupter;
            return std::make_shared<StrandSet>(readStrands(path, opts, &report));
        });
        pyb::module_ warnings = pyb::module_::import("warnings");
        for (const std::string& w : report.warnings) warnings.attr("warn")(w, pyb::module_::import("builtins").attr("UserWarning"), 2);
        return set;
    };
    defineVerb(m, "read", {"path: os.PathLike | str"}, readParameters(),
               {{"root_near", "Optional[Tuple[float, float, float]]", pyb::none(),
                 "for an .obj (and a .ply line set), root each strand at its end nearest this (x, y, z) (world units) instead of its "
                 "end with the lower vertex index (the CLI's ``convert --root-near``)."}},
               "Read strands from a file, the format chosen by extension (and checked by magic).\n\n"
               "Formats: .hair (cyHair), .data (USC-HairSalon), .obj (line elements and curv curves), .ply (hairutil, line sets, points\n"
               "in runs), .vdb (points grid), .usda (USD BasisCurves), .abc (Alembic curves), .tfx (TressFX), .bin (CT2Hair), .convdata\n"
               "(HairNet). Its keywords are the command line's reading options (``--strict``, ``--grid``, ``--points-per-strand``,\n"
               "``--curve-samples``, ``--roots``); the readers' warnings (strands dropped, roots reversed) are UserWarnings.",
               "    path: the file, a str or any os.PathLike (pathlib.Path).\n",
               "Strands.\n\n"
               "Raises:\n"
               "    vdbhair.IoError (an OSError), vdbhair.FormatError / UnsupportedError (ValueErrors) naming the\n"
               "    file, the byte offset or line and the rule; vdbhair.ArgumentError for a keyword outside its range\n"
               "    or choices (\"read: roots 'tip': must be one of first, last, auto\"); KeyboardInterrupt on Ctrl-C.",
               pyb::cpp_function(readImpl, pyb::arg("path"), pyb::arg("keywords")));
}

/// vdbhair.write: strands to a file, with the keywords writeParameters() declares.
void bindWrite(pyb::module_& m)
{
    static const std::string doc = R"doc(Write strands in the format of ``path``'s extension, atomically (a temporary file renamed
into place: a failed write leaves nothing and never damages an existing file).

Writable formats: .hair .data .obj .ply .vdb .usda.

Args:
    strands: a Strands.
    path: the output file, a str or any os.PathLike (pathlib.Path).
)doc" + writeKeywordsDoc() + R"doc(
Raises:
    vdbhair.ArgumentError (a ValueError) for a format that cannot be written or a keyword's value
    outside its range or choices ("write: codec 'zip': must be one of float, fixed16, fixed8"),
    vdbhair.IoError.)doc";
    const std::vector<pyb::arg_v> kw = writeKeywords();
    m.def("write", &writeWithOptions, pyb::arg("strands"), pyb::arg("path"), pyb::kw_only(), kw[0], kw[1], kw[2], kw[3], kw[4], kw[5], kw[6],
          doc.c_str());
}

} // namespace

void bindStrands(pyb::module_& m)
{
    pyb::class_<StrandSet, StrandsPtr> cls(m, "Strands", kStrandsDoc);
    bindStrandArrays(cls);
    bindStrandDeclarations(cls);
    bindStrandSequence(cls);
    bindRead(m);
    bindWrite(m);
}

} // namespace vdbhair::py
