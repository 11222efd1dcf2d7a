// vdbhair.Grid, vdbhair.TangentField and the field operations: estimate_tangent_field, retrace,
// refine, read_grid, read_grids, write_grids, suggest_voxel_size.
#include "Common.h"
#include "Params.h"

#include <vdbhair/Exceptions.h>
#include <vdbhair/compare/HairComparison.h>
#include <vdbhair/field/DenseArray.h>
#include <vdbhair/field/FieldJson.h>
#include <vdbhair/field/Refine.h>
#include <vdbhair/field/RefineJson.h>
#include <vdbhair/field/ScalpSpace.h>
#include <vdbhair/field/StreamlineTracer.h>
#include <vdbhair/field/TangentField.h>
#include <vdbhair/io/VdbFile.h>
#include <vdbhair/io/VdbPoints.h>
#include <vdbhair/scalp/ScalpSurface.h>
#include <vdbhair/strands/Measures.h>

#include <openvdb/openvdb.h>

#include <pybind11/stl.h>

#include <tbb/parallel_for.h>

#include <array>
#include <cstring>
#include <memory>
#include <optional>
#include <variant>

namespace vdbhair::py {

namespace {

using IndexBox = std::array<std::array<int, 3>, 2>;

/// A field of one level as Python sees it.
struct PyField
{
    TangentField field;
};

/// Call @a op with @a grid as a Vec3SGrid or a FloatGrid; other value types are refused.
template <typename OpT>
auto applyVoxelGrid(const openvdb::GridBase& grid, const std::string& where, OpT&& op)
{
    if (const auto* g = dynamic_cast<const openvdb::Vec3SGrid*>(&grid)) return op(*g);
    if (const auto* g = dynamic_cast<const openvdb::FloatGrid*>(&grid)) return op(*g);
    throw TypeError(where + ": grid '" + grid.getName() + "' holds " + grid.valueType() +
                    " values; value arrays are made of vec3s and float grids only (a bool grid has active_coords())");
}

/// Components per value of a grid type (3 for vectors, 0 for scalars: no last axis).
template <typename GridT>
constexpr std::size_t componentsOf()
{
    return std::is_same_v<typename GridT::ValueType, openvdb::Vec3s> ? 3 : 0;
}

/// Where each active value of a grid goes in active_coords() / values(): leaves in the tree's
/// order, each in its own voxel order, then active tiles voxel by voxel.
template <typename GridT>
struct ActiveLayout
{
    using LeafT = typename GridT::TreeType::LeafNodeType;
    std::vector<const LeafT*> leaves;
    std::vector<std::size_t> leafStart;  ///< #leaves+1
    std::vector<std::pair<openvdb::CoordBBox, typename GridT::ValueType>> tiles;
    std::size_t total = 0;

    explicit ActiveLayout(const GridT& grid)
    {
        const auto& tree = grid.tree();
        leafStart.push_back(0);
        for (auto it = tree.cbeginLeaf(); it; ++it) {
            leaves.push_back(it.getLeaf());
            leafStart.push_back(leafStart.back() + it->onVoxelCount());
        }
        total = leafStart.back();
        if (tree.activeTileCount() > 0) {
            for (auto it = tree.cbeginValueOn(); it; ++it) {
                if (!it.isTileValue()) continue;
                tiles.emplace_back(it.getBoundingBox(), *it);
                total += it.getBoundingBox().volume();
            }
        }
    }

    /// Call @a f(index, coord, value) for every active value, leaves in parallel.
    template <typename FuncT>
    void forEach(FuncT&& f) const
    {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t l = r.begin(); l != r.end(); ++l) {
                std::size_t n = leafStart[l];
                for (auto v = leaves[l]->cbeginValueOn(); v; ++v) f(n++, v.getCoord(), *v);
            }
        });
        std::size_t n = leafStart.back();
        for (const auto& [box, value] : tiles) {
            for (auto c = box.begin(); c; ++c) f(n++, *c, value);
        }
    }
};

pyb::array activeCoords(const openvdb::GridBase& grid)
{
    auto coords = [](const auto& g) {
        using GridT = std::decay_t<decltype(g)>;
        const ActiveLayout<GridT> layout(g);
        pyb::array_t<std::int32_t> out({pyb::ssize_t(layout.total), pyb::ssize_t(3)});
        std::int32_t* data = out.mutable_data();
        {
            pyb::gil_scoped_release release;
            layout.forEach([&](std::size_t n, const openvdb::Coord& c, const auto&) {
                data[3 * n] = c.x();
                data[3 * n + 1] = c.y();
                data[3 * n + 2] = c.z();
            });
        }
        return pyb::array(out);
    };
    // A bool grid (a scalp's region) is its active voxels: coordinates, not values.
    if (const auto* g = dynamic_cast<const openvdb::BoolGrid*>(&grid)) return coords(*g);
    return applyVoxelGrid(grid, "active_coords", coords);
}

pyb::array activeValues(const openvdb::GridBase& grid)
{
    return applyVoxelGrid(grid, "values", [](const auto& g) {
        using GridT = std::decay_t<decltype(g)>;
        constexpr std::size_t kC = componentsOf<GridT>();
        const ActiveLayout<GridT> layout(g);
        pyb::array_t<float> out = kC ? pyb::array_t<float>({pyb::ssize_t(layout.total), pyb::ssize_t(kC)})
                                     : pyb::array_t<float>(pyb::ssize_t(layout.total));
        float* data = out.mutable_data();
        {
            pyb::gil_scoped_release release;
            layout.forEach([&](std::size_t n, const openvdb::Coord&, const auto& v) {
                if constexpr (kC == 3) {
                    data[3 * n] = v[0];
                    data[3 * n + 1] = v[1];
                    data[3 * n + 2] = v[2];
                } else {
                    data[n] = v;
                }
            });
        }
        return pyb::array(out);
    });
}

std::optional<IndexBox> activeBox(const openvdb::GridBase& grid)
{
    const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (box.empty()) return std::nullopt;
    return IndexBox{{{box.min().x(), box.min().y(), box.min().z()}, {box.max().x(), box.max().y(), box.max().z()}}};
}

pyb::array toDense(const openvdb::GridBase& grid, const std::optional<IndexBox>& bboxArg)
{
    const std::string where = "to_dense(" + grid.getName() + ")";
    std::optional<IndexBox> bbox = bboxArg ? bboxArg : activeBox(grid);
    if (!bbox) throw ValueError(where + ": the grid has no active voxels; give bbox=((i0, j0, k0), (i1, j1, k1))");
    const IndexBox& b = *bbox;
    for (int a = 0; a < 3; ++a) {
        if (b[1][a] < b[0][a]) {
            throw ValueError(where + ": bbox max[" + std::to_string(a) + "] = " + std::to_string(b[1][a]) + " is below min[" +
                             std::to_string(a) + "] = " + std::to_string(b[0][a]) + "; bbox is ((i0, j0, k0), (i1, j1, k1)), inclusive");
        }
    }
    const openvdb::CoordBBox box(openvdb::Coord(b[0][0], b[0][1], b[0][2]), openvdb::Coord(b[1][0], b[1][1], b[1][2]));
    return applyVoxelGrid(grid, where, [&](const auto& g) {
        using GridT = std::decay_t<decltype(g)>;
        constexpr std::size_t kC = componentsOf<GridT>();
        const auto dim = box.dim();  // x, y, z
        std::vector<pyb::ssize_t> shape{pyb::ssize_t(dim.z()), pyb::ssize_t(dim.y()), pyb::ssize_t(dim.x())};
        if (kC) shape.push_back(pyb::ssize_t(kC));
        pyb::array_t<float> out(shape);
        float* data = out.mutable_data();
        {
            pyb::gil_scoped_release release;
            copyToDenseArray(g, box, data);  // x varies fastest: the array is [z][y][x] (D x H x W)
        }
        return pyb::array(out);
    });
}

using WorldBox = std::array<std::array<double, 3>, 2>;

pyb::array orientationVolumeArray(const openvdb::GridBase& grid, const WorldBox& box, const std::array<int, 3>& shape)
{
    const auto* tangent = dynamic_cast<const openvdb::Vec3SGrid*>(&grid);
    if (!tangent) throw TypeError("orientation_volume: grid '" + grid.getName() + "' holds " + grid.valueType() + " values; it needs a vec3s tangent grid");
    DenseBox dense;
    dense.worldMin = openvdb::Vec3d(box[0][0], box[0][1], box[0][2]);
    dense.worldMax = openvdb::Vec3d(box[1][0], box[1][1], box[1][2]);
    dense.size = openvdb::Coord(shape[2], shape[1], shape[0]);
    std::vector<float> volume;
    {
        pyb::gil_scoped_release release;
        volume = orientationVolume(*tangent, dense);
    }
    pyb::array_t<float> out({pyb::ssize_t(shape[0]), pyb::ssize_t(shape[1]), pyb::ssize_t(shape[2]), pyb::ssize_t(4)});
    std::copy(volume.begin(), volume.end(), out.mutable_data());
    return pyb::array(out);
}

/// Rows of @a points (N x 3) mapped by @a f(Vec3d) -> Vec3d, as float64.
template <typename FuncT>
pyb::array mapPoints(const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& points, const char* where, FuncT&& f)
{
    if (points.ndim() != 2 || points.shape(1) != 3) throw ValueError(std::string(where) + ": points must be an (N, 3) array");
    const std::size_t n = std::size_t(points.shape(0));
    pyb::array_t<double> out({pyb::ssize_t(n), pyb::ssize_t(3)});
    const double* in = points.data();
    double* o = out.mutable_data();
    for (std::size_t i = 0; i < n; ++i) {
        const openvdb::Vec3d r = f(openvdb::Vec3d(in[3 * i], in[3 * i + 1], in[3 * i + 2]));
        o[3 * i] = r.x();
        o[3 * i + 1] = r.y();
        o[3 * i + 2] = r.z();
    }
    return pyb::array(out);
}

pyb::dict metadataDict(const openvdb::GridBase& grid)
{
    pyb::dict d;
    for (auto it = grid.beginMeta(); it != grid.endMeta(); ++it) {
        const openvdb::Metadata& m = *it->second;
        const std::string type = m.typeName();
        pyb::object v;
        if (const auto* s = dynamic_cast<const openvdb::StringMetadata*>(&m)) v = pyb::str(s->value());
        else if (const auto* f = dynamic_cast<const openvdb::FloatMetadata*>(&m)) v = pyb::float_(f->value());
        else if (const auto* dd = dynamic_cast<const openvdb::DoubleMetadata*>(&m)) v = pyb::float_(dd->value());
        else if (const auto* i = dynamic_cast<const openvdb::Int32Metadata*>(&m)) v = pyb::int_(i->value());
        else if (const auto* l = dynamic_cast<const openvdb::Int64Metadata*>(&m)) v = pyb::int_(l->value());
        else if (const auto* b = dynamic_cast<const openvdb::BoolMetadata*>(&m)) v = pyb::bool_(b->value());
        else if (const auto* vs = dynamic_cast<const openvdb::Vec3SMetadata*>(&m)) v = pyb::make_tuple(vs->value()[0], vs->value()[1], vs->value()[2]);
        else if (const auto* vd = dynamic_cast<const openvdb::Vec3DMetadata*>(&m)) v = pyb::make_tuple(vd->value()[0], vd->value()[1], vd->value()[2]);
        else if (const auto* vi = dynamic_cast<const openvdb::Vec3IMetadata*>(&m)) v = pyb::make_tuple(vi->value()[0], vi->value()[1], vi->value()[2]);
        else v = pyb::str(m.str());
        d[pyb::str(it->first)] = v;
    }
    return d;
}

/// The vector grid of a TangentField or Grid argument.
openvdb::GridBase::ConstPtr fieldArgument(const pyb::handle& field, const char* where)
{
    if (pyb::isinstance<PyField>(field)) return field.cast<const PyField&>().field.tangent;
    if (pyb::isinstance<PyGrid>(field)) return field.cast<const PyGrid&>().grid;
    throw TypeError(std::string(where) + ": field must be a vdbhair.TangentField or a vdbhair.Grid, not " +
                    std::string(pyb::str(field.get_type().attr("__name__"))));
}

/// The array methods Grid and TangentField share (TangentField's act on its tangent grid).
template <typename ClassT, typename GetT>
void addArrayMethods(ClassT& cls, GetT get, const char* subject)
{
    const std::string s = subject;
    cls.def_property_readonly(
        "voxel_size", [get](const typename ClassT::type& self) { return get(self).voxelSize().x(); },
        ("Voxel size of " + s + " in world units.").c_str());
    cls.def_property_readonly(
        "bbox", [get](const typename ClassT::type& self) { return activeBox(get(self)); },
        ("Index bounding box of the active voxels of " + s +
         ", ((i0, j0, k0), (i1, j1, k1)) inclusive, or None when there are none.").c_str());
    cls.def_property_readonly(
        "active_voxel_count", [get](const typename ClassT::type& self) { return get(self).activeVoxelCount(); },
        ("Number of active voxels of " + s + ".").c_str());
    cls.def(
        "active_coords", [get](const typename ClassT::type& self) { return activeCoords(get(self)); },
        ("(N, 3) int32 index coordinates (i, j, k) of the active voxels of " + s +
         ", in the order of values(): leaf by leaf as the tree stores them, then active tiles voxel by voxel.")
            .c_str());
    cls.def(
        "values", [get](const typename ClassT::type& self) { return activeValues(get(self)); },
        ("Values of the active voxels of " + s +
         " in the order of active_coords(): (N, 3) float32 for vector grids, (N,) float32 for scalar grids.")
            .c_str());
    cls.def(
        "to_dense", [get](const typename ClassT::type& self, const std::optional<IndexBox>& bbox) { return toDense(get(self), bbox); },
        pyb::arg("bbox") = pyb::none(),
        ("A dense float32 copy of " + s +
         " over the index box bbox = ((i0, j0, k0), (i1, j1, k1)), inclusive (default: the active voxels' box).\n\n"
         "Shape (D, H, W, 3) for vector grids, (D, H, W) for scalar ones, with D = k1-k0+1 (z), H = j1-j0+1 (y), "
         "W = i1-i0+1 (x): ``dense[k - k0, j - j0, i - i0]`` is the value at index (i, j, k), x varying fastest, the "
         "layout learning code expects (e.g. NeuralHDHair's 96 x 128 x 128 x 3 orientation volume). Inactive voxels "
         "hold the grid's background (zero for vdbhair's grids).")
            .c_str());
    cls.def(
        "orientation_volume",
        [get](const typename ClassT::type& self, const WorldBox& box, const std::array<int, 3>& shape) {
            return orientationVolumeArray(get(self), box, shape);
        },
        pyb::arg("box"), pyb::arg("shape") = kDefaultDenseShape,
        ("The orientation volume of " + s +
         " resampled over the world box box = ((x0, y0, z0), (x1, y1, z1)) at shape = (D, H, W) samples along (z, y, x), "
         "each at the centre of its cell: float32 (D, H, W, 4), channels tx, ty, tz (the trilinear tangent of the active voxels, "
         "normalized; zero outside the hair) and occupancy (the active mask, trilinear, in [0, 1]). The same array as "
         "``vdbhair field --dense``.")
            .c_str());
    cls.def(
        "index_to_world",
        [get](const typename ClassT::type& self, const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& points) {
            const openvdb::math::Transform& xform = get(self).transform();
            return mapPoints(points, "index_to_world", [&](const openvdb::Vec3d& p) { return xform.indexToWorld(p); });
        },
        pyb::arg("points"), ("(N, 3) index coordinates of " + s + " to (N, 3) float64 world positions (voxel centres at integers).").c_str());
    cls.def(
        "world_to_index",
        [get](const typename ClassT::type& self, const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& points) {
            const openvdb::math::Transform& xform = get(self).transform();
            return mapPoints(points, "world_to_index", [&](const openvdb::Vec3d& p) { return xform.worldToIndex(p); });
        },
        pyb::arg("points"), ("(N, 3) world positions to (N, 3) float64 (fractional) index coordinates of " + s + ".").c_str());
}

} // namespace

/// The scalp argument of estimate_tangent_field() and refine(), as `--space`, `--scalp` and `--up`:
/// a sphere (cx, cy, cz, r), a head (the path of a scalp .vdb or a mesh) or None (the sphere
/// fitted to the roots), for space="scalp" only.
using ScalpArgument = std::optional<std::variant<std::array<double, 4>, PathArg>>;

/// In scalp space (fp.space, a declared parameter as fp.scalp.up is), @a fp's scalp from @a scalp.
/// @return the head's level set when @a scalp named one (refine's default head), else null
openvdb::FloatGrid::Ptr applyScalpArgument(FieldParams& fp, const StrandSet& strands, const ScalpArgument& scalp, const std::string& where)
{
    const Vec3d upAxis = fp.scalp.up;
    if (fp.space != FieldSpace::Scalp) {
        if (scalp) throw ValueError(where + ": scalp= is for space='scalp'");
        return nullptr;
    }
    std::vector<Vec3f> roots;
    for (std::size_t i = 0; i < strands.numStrands(); ++i) roots.push_back(strands.root(i));
    ScalpSphere given;
    openvdb::FloatGrid::Ptr surface;
    if (scalp) {
        if (const auto* path = std::get_if<PathArg>(&*scalp)) {
            surface = readScalp(*path);
        } else {
            const auto& v = std::get<std::array<double, 4>>(*scalp);
            if (!(v[3] > 0.0) || !std::isfinite(v[3])) throw ValueError(where + ": scalp=(cx, cy, cz, r) needs r > 0");
            given.center = Vec3d(v[0], v[1], v[2]);
            given.radius = v[3];
        }
    }
    try {
        useScalpSpace(fp, roots, upAxis, scalp && !surface ? &given : nullptr, surface);
    } catch (const ValueError& e) {
        throw ValueError(where + ": " + e.what());
    }
    return surface;
}

namespace {

/// vdbhair.Grid: one OpenVDB grid with NumPy access.
void bindGrid(pyb::module_& m)
{
    // ---- Grid ----------------------------------------------------------------------------
    pyb::class_<PyGrid> grid(m, "Grid", R"doc(One OpenVDB grid (a vec3s or float voxel grid) with NumPy access.

Made by vdbhair.read_grid / read_grids, or taken from a TangentField (``field.density``). Grids
are shared, not copied: a Grid taken from a field sees the same voxels.)doc");
    grid.def_property_readonly("name", [](const PyGrid& g) { return g.grid->getName(); }, "The grid's name.");
    grid.def_property_readonly("value_type", [](const PyGrid& g) { return g.grid->valueType(); }, "OpenVDB's value type name: 'vec3s', 'float', ...");
    grid.def_property_readonly("grid_class", [](const PyGrid& g) { return openvdb::GridBase::gridClassToString(g.grid->getGridClass()); },
                               "'unknown', 'level set', 'fog volume' or 'staggered'.");
    grid.def_property_readonly("metadata", [](const PyGrid& g) { return metadataDict(*g.grid); },
                               "The grid's metadata as a dict (vdbhair records the parameters that made it, e.g. vdbhair_voxel_size).");
    addArrayMethods(grid, [](const PyGrid& g) -> const openvdb::GridBase& { return *g.grid; }, "the grid");
    grid.def(
        "point_attributes",
        [](const PyGrid& g) {
            std::vector<PointColumn> columns;
            std::vector<std::string> skipped;
            try {
                pyb::gil_scoped_release release;
                columns = pointColumns(*g.grid, &skipped);
            } catch (const TypeError& e) {
                throw TypeError(std::string("Grid.point_attributes: ") + e.what());
            }
            pyb::dict d;
            for (const PointColumn& c : columns) {
                const std::size_t n = c.values.size() / c.components;
                std::vector<pyb::ssize_t> shape{pyb::ssize_t(n)};
                if (c.components > 1) shape.push_back(pyb::ssize_t(c.components));
                if (c.type == "group") {
                    pyb::array_t<bool> a(shape);
                    for (std::size_t i = 0; i < c.values.size(); ++i) a.mutable_data()[i] = c.values[i] != 0.0;
                    d[pyb::str(c.name)] = a;
                } else if (c.integer) {
                    pyb::array_t<std::int64_t> a(shape);
                    for (std::size_t i = 0; i < c.values.size(); ++i) a.mutable_data()[i] = std::int64_t(c.values[i]);
                    d[pyb::str(c.name)] = a;
                } else {
                    pyb::array_t<double> a(shape);
                    std::copy(c.values.begin(), c.values.end(), a.mutable_data());
                    d[pyb::str(c.name)] = a;
                }
            }
            return d;
        },
        R"doc(Every attribute of every point of a points grid, in the grid's own order (leaf by leaf, voxel
by voxel: the order Houdini's Convert VDB Points gives), as a dict name -> NumPy array: ``P`` the
world positions (N, 3) float64; integer attributes int64, real ones float64, vectors (N, 3); each
point group as a bool array by its name. Attributes of other types (strings) are left out.

Raises:
    vdbhair.GridTypeError when the grid holds voxels, not points.)doc");
    grid.def(
        "write",
        [](const PyGrid& g, const PathArg& path) {
            pyb::gil_scoped_release release;
            writeVdbGrids(path, {g.grid}, "Grid.write(" + path + ")");
        },
        pyb::arg("path"), "Write this grid alone to a .vdb file, atomically.");
    grid.def("__repr__", [](const PyGrid& g) {
        return "<vdbhair.Grid '" + g.grid->getName() + "': " + g.grid->valueType() + ", " + std::to_string(g.grid->activeVoxelCount()) +
               " active voxels>";
    });
}

/// vdbhair.TangentField: the grids of one level of a tangent field.
void bindTangentField(pyb::module_& m)
{
    // ---- TangentField --------------------------------------------------------------------
    pyb::class_<PyField> field(m, "TangentField", R"doc(The robust tangent field of a hairstyle at one voxel size
(Wang et al. 2009, Eq. 9), as estimate_tangent_field returns it.

The array methods (active_coords, values, to_dense, bbox, ...) act on the ``tangent`` grid: unit
hair directions, root to tip, in world space. The other grids are attributes: ``density`` (fog
volume in [0, 1]), ``hair_length`` (summed segment length per voxel, world units), ``coherence``
and ``spread`` (both in [0, 1]).)doc");
    field.def_property_readonly("tangent", [](const PyField& f) { return PyGrid{f.field.tangent}; }, "The vec3s grid 'tangent' (unit directions).");
    field.def_property_readonly("density", [](const PyField& f) { return PyGrid{f.field.density}; }, "The float grid 'density' (fog volume in [0, 1]).");
    field.def_property_readonly("hair_length", [](const PyField& f) { return PyGrid{f.field.hairLength}; },
                                "The float grid 'hair_length' (world units per voxel).");
    field.def_property_readonly("coherence", [](const PyField& f) { return PyGrid{f.field.coherence}; },
                                "The float grid 'coherence' in [0, 1] (1: all contributions parallel).");
    field.def_property_readonly("spread", [](const PyField& f) { return PyGrid{f.field.spread}; },
                                "The float grid 'spread' in [0, 1] (mean squared sine to the robust direction).");
    field.def_property_readonly("density_reference", [](const PyField& f) { return f.field.densityReference; },
                                "The hair length per unit volume (world units^-2) that density 1 means.");
    field.def_property_readonly("metadata", [](const PyField& f) { return metadataDict(*f.field.tangent); },
                                "The tangent grid's metadata as a dict (creator and the parameters that made it).");
    addArrayMethods(field, [](const PyField& f) -> const openvdb::GridBase& { return *f.field.tangent; }, "the tangent grid");
    field.def(
        "grids", [](const PyField& f) {
            std::vector<PyGrid> out;
            for (const auto& g : {openvdb::GridBase::Ptr(f.field.tangent), openvdb::GridBase::Ptr(f.field.density),
                                  openvdb::GridBase::Ptr(f.field.hairLength), openvdb::GridBase::Ptr(f.field.coherence),
                                  openvdb::GridBase::Ptr(f.field.spread)}) {
                if (g) out.push_back(PyGrid{g});
            }
            return out;
        },
        "The grids [tangent, density, hair_length, coherence, spread] as Grid objects.");
    field.def(
        "write",
        [](const PyField& f, const PathArg& path) {
            pyb::gil_scoped_release release;
            writeVdbGrids(path, f.field.grids(), "TangentField.write(" + path + ")");
        },
        pyb::arg("path"),
        "Write the five grids (tangent, density, hair_length, coherence, spread) to a .vdb file, atomically, as "
        "``vdbhair field`` does; they open in Houdini, Blender and pyopenvdb.");
    field.def("__repr__", [](const PyField& f) {
        return "<vdbhair.TangentField: voxel size " + std::to_string(f.field.tangent->voxelSize().x()) + ", " +
               std::to_string(f.field.tangent->activeVoxelCount()) + " active voxels>";
    });
}

/// read_grid, read_grids and write_grids: grids from and to .vdb files.
void bindGridFiles(pyb::module_& m)
{
    // ---- Reading and writing grids ---------------------------------------------------------
    m.def(
        "read_grid",
        [](const PathArg& path, const std::string& name) {
            pyb::gil_scoped_release release;
            return PyGrid{readVdbGrid(path, name, "read_grid(" + path + ")")};
        },
        pyb::arg("path"), pyb::arg("name") = "tangent",
        R"doc(Read the grid ``name`` of a .vdb file (any OpenVDB writer's: pyopenvdb, Houdini, Blender).

Raises:
    vdbhair.NotFoundError (a LookupError) listing the grids the file has; vdbhair.IoError,
    vdbhair.FormatError.)doc");
    m.def(
        "read_grids",
        [](const PathArg& path) {
            openvdb::GridPtrVec grids;
            {
                pyb::gil_scoped_release release;
                grids = readVdbGrids(path, "read_grids(" + path + ")");
            }
            pyb::dict d;
            for (const auto& g : grids) d[pyb::str(g->getName())] = PyGrid{g};
            return d;
        },
        pyb::arg("path"), "Every grid of a .vdb file as a dict name -> Grid, in file order (points grids included as Grids "
                          "without array access: their points through Grid.point_attributes(); strands with vdbhair.read).");
    m.def(
        "write_grids",
        [](const PathArg& path, const std::vector<pyb::object>& items) {
            openvdb::GridCPtrVec grids;
            for (const pyb::object& o : items) {
                if (pyb::isinstance<PyGrid>(o)) grids.push_back(o.cast<const PyGrid&>().grid);
                else if (pyb::isinstance<PyField>(o)) {
                    for (const auto& g : o.cast<const PyField&>().field.grids()) grids.push_back(g);
                } else {
                    throw TypeError("write_grids(" + path + "): items must be vdbhair.Grid or vdbhair.TangentField, not " +
                                    std::string(pyb::str(o.get_type().attr("__name__"))));
                }
            }
            pyb::gil_scoped_release release;
            writeVdbGrids(path, grids, "write_grids(" + path + ")");
        },
        pyb::arg("path"), pyb::arg("grids"),
        "Write Grids (and every grid of TangentFields) to one .vdb file, atomically. Grid names should differ "
        "(rename levels first if you write several fields).");
}

/// suggest_voxel_size and estimate_tangent_field (fieldParameters()).
void bindEstimateField(pyb::module_& m)
{
    // ---- Operations ----------------------------------------------------------------------
    m.def(
        "suggest_voxel_size", [](const StrandSet& s) { return suggestVoxelSize(s); }, pyb::arg("strands"),
        R"doc(The default finest voxel size of a hairstyle (world units): three times the median distance
between neighbouring roots, kept between 1/64 and 1/4 of the head radius (vdbhair/field/Refine.h).)doc");

    auto fieldImpl = [](const StrandsPtr& strands, const pyb::dict& kw) -> pyb::object {
        FieldLevelsParams params;
        applyKeywords(fieldLevelsParameters(), kw, params, "estimate_tangent_field");
        FieldParams& fp = params.field;
        applyScalpArgument(fp, *strands, kw["scalp"].cast<ScalpArgument>(), "estimate_tangent_field");
        const bool levels = !kw["levels"].is_none();  // None: one field, not a list of one
        auto fields = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            if (!levels) return std::vector<TangentField>{estimateTangentField(*strands, fp, true, interrupter)};
            return estimateTangentFieldLevels(*strands, fp, params.levels, true, interrupter);
        });
        // field --json's report (FieldJson.h) of the grids `field` writes, less the file names and the seconds.
        nlohmann::json report;
        if (kw["return_report"].cast<bool>()) {
            openvdb::GridCPtrVec grids;
            for (const TangentField& f : fields) grids.insert(grids.end(), {f.tangent, f.density, f.hairLength});
            FieldParams used = fp;
            used.voxelSize = resolveVoxelSize(*strands, fp);
            report = fieldReport(strands->numStrands(), used, int(fields.size()), grids);
        }
        pyb::object out;
        if (!levels) {
            out = pyb::cast(PyField{fields.front()});
        } else {
            pyb::list list;
            for (TangentField& f : fields) list.append(PyField{std::move(f)});
            out = list;
        }
        if (report.is_null()) return out;
        return pyb::make_tuple(out, toPython(report));
    };
    defineVerb(m, "estimate_tangent_field", {"strands: vdbhair.Strands"}, fieldLevelsParameters(),
               {{"scalp", "", pyb::none(),
                 "with space=\"scalp\", the sphere (cx, cy, cz, r) in world units, or a head (the path of a scalp .vdb with a level "
                 "set 'surface', or of a mesh): w is then the height above that head, measured along rays from the sphere fitted "
                 "to the roots, and the grids carry the measured table (vdbhair_scalp_distance); None fits a sphere to the roots."},
                {"return_report", "bool", pyb::bool_(false),
                 "also return ``field --json``'s report as a dict (less the file name and the seconds: strands, voxel_size, "
                 "iterations, levels, space, grids (name, voxel_size, active_voxels of each tangent, density and hair_length "
                 "grid), and scalp in scalp space)."}},
               "The robust tangent field of a hairstyle (Wang et al. 2009, Eq. 9), in world space by default: ``vdbhair field``.\n\n"
               "Every segment contributes its unit tangent to every voxel it passes through, weighted by its\n"
               "length there; each iteration reweights contributions by 0.5 (T . v + 1) and renormalizes.\n"
               "Results are bitwise identical for any thread count. Raises vdbhair.ArgumentError / LimitError\n"
               "(ValueErrors), KeyboardInterrupt on Ctrl-C.",
               "    strands: a Strands.\n",
               "TangentField, or a list of them (element 0 the finest) when ``levels`` is given; (that, report) with return_report.",
               pyb::cpp_function(fieldImpl, pyb::arg("strands"), pyb::arg("keywords")), 1);
}

/// retrace: strands retraced through a vector field (retraceParameters()).
void bindRetrace(pyb::module_& m)
{
    auto retraceImpl = [](const StrandsPtr& strands, const pyb::object& fieldArg, const pyb::dict& kw) -> pyb::object {
        const openvdb::GridBase::ConstPtr grid = fieldArgument(fieldArg, "retrace");
        RetraceParams rp;
        applyKeywords(retraceParameters(), kw, rp, "retrace");
        const TraceParams& tp = rp.trace;
        const bool returnStats = renamedKeywordValue(kw, "return_report", "return_stats", "retrace").cast<bool>(), measure = rp.measure;
        TraceStats stats;
        std::optional<TangentAngles> angles;
        double displacement = 0.0;
        auto out = runLong(kw["threads"].cast<int>(), kw["progress"], [&](WorkInterrupter* interrupter) {
            auto o = std::make_shared<StrandSet>(retraceStrands(*strands, *grid, tp, &stats, nullptr, true, interrupter));
            if (measure && returnStats) angles = meanTangentAnglesDeg(*strands, *o, *grid);
            if (returnStats) displacement = meanVertexDisplacement(*strands, *o);
            return o;
        });
        if (!returnStats) return pyb::cast(out);
        // `retrace --json`'s report (retraceReport()), less the file name.
        return pyb::make_tuple(out, toPython(retraceReport(stats, tp, resolveStep(*grid, tp), displacement, angles)));
    };
    defineVerb(m, "retrace", {"strands: vdbhair.Strands", "field"}, retraceParameters(),
               {{"return_report", "bool", pyb::bool_(false),
                 "also return a dict: `retrace --json`'s report key for key, less the file name (strands, full_length, "
                 "stopped: vanished, left_field, max_steps; steps, mean_displacement, step, integrator, and tangent_angle_deg "
                 "with measure)."},
                renamedKeyword("return_stats", "return_report")},
               "Retrace every strand through a vector field from its own root, for its own length\n"
               "(Wang et al. 2009, Sec. 5.3): ``vdbhair retrace``.\n\n"
               "Raises vdbhair.GridTypeError (a TypeError) for a non-vector grid, vdbhair.ArgumentError,\n"
               "KeyboardInterrupt on Ctrl-C.",
               "    strands: a Strands (roots, lengths and vertex spacing to follow).\n"
               "    field: a TangentField (its tangent grid is followed) or a vector Grid (vec3s), e.g. read with\n"
               "        read_grid from any OpenVDB writer.\n",
               "Strands, or (Strands, report) with return_report.",
               pyb::cpp_function(retraceImpl, pyb::arg("strands"), pyb::arg("field"), pyb::arg("keywords")));
}

/// refine: vector-field refinement (refineParameters()).
void bindRefine(pyb::module_& m)
{
    auto refineImpl = [](const StrandsPtr& strands, const pyb::dict& kw) -> pyb::object {
        RefineParams rp;
        applyKeywords(refineParameters(), kw, rp, "refine");
        const pyb::object head = kw["head"];
        const HeadArgument headArg(head, headPolicyName(rp.headPolicy));
        rp.head = headArg.head;
        // A scalp given as a sphere or a head is also the head strands keep out of, unless head= says (as the CLI).
        const ScalpArgument scalp = kw["scalp"].cast<ScalpArgument>();
        const openvdb::FloatGrid::Ptr scalpSurface = applyScalpArgument(rp.field, *strands, scalp, "refine");
        const bool scalpHead = head.is_none() && scalp.has_value();
        if (scalpHead) {
            rp.head = scalpSurface ? HeadObstacle::levelSet(scalpSurface, headArg.policy)
                                   : HeadObstacle::sphere(rp.field.scalp.center, rp.field.scalp.radius, headArg.policy);
        }
        rp.validate("refine");
        const int threads = kw["threads"].cast<int>();
        const bool returnReport = kw["return_report"].cast<bool>();
        RefineResult result = runLong(threads, kw["progress"], [&](WorkInterrupter* interrupter) {
            RefineParams p = rp;
            if (!scalpHead) p.head = headArg.get("refine");
            return refineStrands(*strands, p, true, interrupter);
        });
        pyb::object comparison = pyb::none();  // the output against the input, as `vdbhair compare` (refine --measure --json's "compare")
        if (rp.measure && returnReport) {
            const HairComparison c = runLong(threads, pyb::none(), [&](WorkInterrupter*) { return measureAgainst(*strands, result.strands, &result.head); });
            comparison = toPython(toJson(c));
        }
        // refine --json's report (RefineJson.h), with the output compared to the input and each
        // level's TangentField (0 the finest).
        const nlohmann::json json = returnReport ? refineReport(result, rp) : nlohmann::json();
        auto out = std::make_shared<StrandSet>(std::move(result.strands));
        if (!returnReport) return pyb::cast(out);
        pyb::dict report = toPython(json);
        if (rp.measure) report["compare"] = comparison;
        pyb::list fields;
        for (TangentField& f : result.fields) fields.append(PyField{std::move(f)});
        report["fields"] = fields;
        return pyb::make_tuple(out, report);
    };
    defineVerb(m, "refine", {"strands: vdbhair.Strands"}, refineParameters(),
               {{"head", "", pyb::none(),
                 "None (a sphere fitted to the roots), \"none\" (no head), a path to a mesh (.ply, .obj) or a .vdb level set, "
                 "or a sphere (cx, cy, cz, r) in world units."},
                {"scalp", "", pyb::none(),
                 "space='scalp': a sphere (cx, cy, cz, r) or a head (a scalp .vdb or a mesh); None fits a sphere to the roots. "
                 "A scalp given is also the head strands keep out of unless head= says otherwise."},
                {"return_report", "bool", pyb::bool_(false),
                 "also return a dict: `refine --json`'s report (the same keys and values: settings, the finest level's measures "
                 "with measure=True, per_level, and compare), plus fields (the TangentField of each level, 0 the finest)."}},
               "Vector-field refinement (Wang et al. 2009, Sec. 5.3): estimate, retrace, repeat from the\n"
               "coarsest level to the finest: ``vdbhair refine``.",
               "    strands: a Strands.\n", "Strands, or (Strands, report) with return_report.",
               pyb::cpp_function(refineImpl, pyb::arg("strands"), pyb::arg("keywords")));
}

} // namespace

void bindFields(pyb::module_& m)
{
    bindGrid(m);
    bindTangentField(m);
    bindGridFiles(m);
    bindEstimateField(m);
    bindRetrace(m);
    bindRefine(m);
}

} // namespace vdbhair::py
