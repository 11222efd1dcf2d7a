// The `vdbhair` Python module (issue 18): strands as NumPy arrays and the toolkit's operations.
#include "Common.h"

#include <vdbhair/Version.h>
#include <vdbhair/io/VdbFile.h>

PYBIND11_MODULE(vdbhair, m)
{
    namespace py = vdbhair::py;
    m.doc() = R"doc(vdbhair: hair geometry on OpenVDB, from Python.

Strands are NumPy arrays (vdbhair.Strands: positions (V, 3) float32, offsets (S+1,) int64);
fields are sparse VDB grids with NumPy access (vdbhair.TangentField, vdbhair.Grid).

    import vdbhair, numpy as np
    hair = vdbhair.read("hair.hair")
    field = vdbhair.estimate_tangent_field(hair, voxel_size=0.5)
    np.save("orientation.npy", field.to_dense())           # (D, H, W, 3) float32
    smooth = vdbhair.retrace(hair, field)
    vdbhair.write(smooth, "smooth.vdb")

Long calls release the GIL, take ``threads=`` (0: all cores; results never depend on it) and
``progress=`` (a callable progress(stage, done, total, unit)), and stop on Ctrl-C with
KeyboardInterrupt. Errors are vdbhair.Error subclasses that are also the matching built-in
exceptions (IoError is an OSError; FormatError, ArgumentError, UnsupportedError and LimitError
are ValueErrors; NotFoundError a LookupError; GridTypeError a TypeError), with the library's
one-line messages.)doc";
    m.attr("__version__") = VDBHAIR_VERSION_STRING;
    vdbhair::initializeOpenVdb();
    py::registerExceptions(m);
    py::bindStrands(m);
    py::bindFields(m);
    py::bindOperations(m);
    py::bindScalp(m);
}
