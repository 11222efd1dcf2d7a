/// @file Common.h
/// @brief What every binding file of the `vdbhair` Python module shares: the exception mapping,
/// the interrupter that turns Ctrl-C and a Python progress callback into the library's
/// interrupter (vdbhair/Progress.h), and runLong(), which runs library work with the GIL
/// released, a thread cap and that interrupter.
#pragma once

#include <vdbhair/Exceptions.h>
#include <vdbhair/field/HeadObstacle.h>
#include <vdbhair/Progress.h>
#include <vdbhair/RunOptions.h>
#include <vdbhair/Types.h>
#include <vdbhair/strands/StrandSet.h>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <openvdb/Grid.h>

#include <tbb/global_control.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vdbhair::py {

/// @brief A JSON value as a Python object, through Python's json module (reports and scenes are
/// small): the library's JSON reports reach Python with the command line's keys and values.
inline pybind11::object toPython(const nlohmann::json& j)
{
    return pybind11::module_::import("json").attr("loads")(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

namespace pyb = pybind11;

/// How the module holds strands (vdbhair.Strands).
using StrandsPtr = std::shared_ptr<StrandSet>;

/// @brief Register vdbhair.Error and its subclasses on @a m and translate the library's typed
/// exceptions (vdbhair/Exceptions.h) to them; InterruptedError becomes KeyboardInterrupt.
void registerExceptions(pyb::module_& m);

/// @brief The interrupter handed to the library during one call from Python.
///
/// wasInterrupted() is true once SIGINT arrived during the call (InterruptScope installs the
/// handler) or once the progress callback raised. The callback, when given, is called as
/// `progress(stage, done, total, unit)` with the GIL taken: at the start of every stage and then at
/// most ten times a second, from whichever thread reports (never two at once).
class PyInterrupter : public WorkInterrupter
{
public:
    explicit PyInterrupter(pyb::object progress) : mProgress(std::move(progress)) {}

    void start(const char* name = nullptr) override;
    void startWork(const char* name, std::uint64_t total, const char* unit) override;
    void end() override {}
    bool wasInterrupted(int percent = -1) override;
    bool wasInterruptedAt(std::uint64_t done, int percent) override;

    /// The Python exception the callback raised, if any (rethrown by runLong()).
    std::optional<pyb::error_already_set>& callbackError() { return mError; }

private:
    void report(std::uint64_t done, bool force);

    pyb::object mProgress;
    std::mutex mMutex;  ///< one callback at a time; guards the fields below
    std::string mStage, mUnit;
    std::uint64_t mTotal = 0;
    std::chrono::steady_clock::time_point mLast{};
    std::atomic<bool> mCallbackFailed{false};
    std::optional<pyb::error_already_set> mError;
};

/// @brief While alive (and called on Python's main thread with Python's default SIGINT handler in
/// place), Ctrl-C sets a flag the interrupter polls instead of waiting for the GIL; the previous
/// handler is restored on destruction. Nested scopes share the outermost one's handler.
class InterruptScope
{
public:
    InterruptScope();
    ~InterruptScope();
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;
    /// Whether SIGINT arrived while this scope (or an enclosing one) was alive.
    static bool signalled();

private:
    bool mInstalled = false;
};

/// @brief Run @a work(interrupter) with the GIL released, at most @a threads worker threads
/// (0: all cores) and Ctrl-C / @a progress wired to the interrupter. A Python exception raised by
/// the callback is rethrown in place of the library's InterruptedError; a Ctrl-C that arrives
/// after the work's last check still raises KeyboardInterrupt (as Python would).
/// @throw ValueError (Python) for a negative @a threads.
template <typename WorkT>
auto runLong(int threads, const pyb::object& progress, WorkT&& work)
{
    checkParams(runParameters(), RunOptions{threads}, ParamSpelling::Keyword, "");
    if (!progress.is_none() && !PyCallable_Check(progress.ptr())) {
        throw TypeError("progress: must be a callable progress(stage, done, total, unit) or None");
    }
    using ResultT = decltype(work(std::declval<WorkInterrupter*>()));
    PyInterrupter interrupter(progress);
    InterruptScope scope;
    std::unique_ptr<tbb::global_control> cap;
    if (threads > 0) cap = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    std::optional<ResultT> result;
    try {
        pyb::gil_scoped_release release;
        result.emplace(work(static_cast<WorkInterrupter*>(&interrupter)));
    } catch (const InterruptedError&) {
        if (interrupter.callbackError()) throw pyb::error_already_set(std::move(*interrupter.callbackError()));
        throw;
    }
    if (interrupter.callbackError()) throw pyb::error_already_set(std::move(*interrupter.callbackError()));
    // A Ctrl-C after the work's last check: Python's own KeyboardInterrupt, at its next check.
    if (InterruptScope::signalled()) PyErr_SetInterrupt();
    return std::move(*result);
}

/// @brief A read-only NumPy view of @a count rows of @a cols values at @a data, kept alive by
/// @a owner (the Python object owning the storage). @a cols 0 makes a 1-D array.
template <typename T>
pyb::array readOnlyView(const T* data, std::size_t count, std::size_t cols, pyb::handle owner)
{
    pyb::array a = cols == 0 ? pyb::array(pyb::dtype::of<T>(), {count}, {sizeof(T)}, data, owner)
                             : pyb::array(pyb::dtype::of<T>(), {count, cols}, {sizeof(T) * cols, sizeof(T)}, data, owner);
    a.attr("setflags")(pyb::arg("write") = false);
    return a;
}

/// @brief An (N, 3) array of finite numbers (any real dtype) as points.
/// @param what names the array in messages ("interpolate: roots")
/// @throw ValueError (another shape, a non-finite value).
std::vector<Vec3d> pointsArgument(const pyb::handle& obj, const std::string& what);

/// @brief One OpenVDB grid as Python sees it (vdbhair.Grid, registered in Fields.cc): a shared
/// pointer to the grid, which a TangentField may share. Cast it with std::dynamic_pointer_cast,
/// never GridBase::grid<T>() or isType<T>(): those instantiate Tree::treeType()'s std::call_once
/// in the module, whose exported helper libopenvdb then binds to, and openvdb::initialize()
/// crashes at import (the lambda fills the module's hidden copy of the type name, not libopenvdb's).
struct PyGrid
{
    openvdb::GridBase::Ptr grid;
};

/// @brief The head= and head_policy= keywords of refine and comb: None (the operation's default
/// head), "none" (no head), a path (a mesh, or a .vdb with a level set, read by get()), or
/// (x, y, z, r), a sphere.
struct HeadArgument
{
    /// @throw ValueError for a policy that is not one of no-deeper, outside.
    HeadArgument(const pyb::object& head, const std::string& policy);
    /// @brief The head (reading the file of a path: call it inside runLong()).
    /// @param where the operation, for messages ("refine")
    HeadObstacle get(const std::string& where) const;

    HeadObstacle head;  ///< unset (None), none() or a sphere
    std::optional<std::string> path;
    HeadPolicy policy;
};

/// @brief A file path argument: a str or any os.PathLike (pathlib.Path), as Python's own open()
/// takes (os.fspath; bytes paths decoded with os.fsdecode). A std::string, so it goes wherever
/// the library takes a path. Registered by the type caster below.
struct PathArg : std::string
{
    PathArg() = default;
    PathArg(std::string s) : std::string(std::move(s)) {}
};

/// @brief Whether @a obj is a path (str, bytes or os.PathLike).
bool isPathLike(const pyb::handle& obj);
/// @brief @a obj as a path string (os.fsdecode(os.fspath(obj))).
/// @throw TypeError naming @a what when it is not a path.
std::string pathString(const pyb::handle& obj, const std::string& what = "path");

// The bindings of each file.
void bindStrands(pyb::module_& m);
void bindFields(pyb::module_& m);
void bindOperations(pyb::module_& m);
void bindSynthesis(pyb::module_& m);  ///< synth, transfer, comb (Synthesis.cc)
void bindScalp(pyb::module_& m);
void bindDataset(pyb::module_& m);

} // namespace vdbhair::py

namespace pybind11::detail {
/// str or os.PathLike -> PathArg (a pathlib.Path, as every Python file API accepts).
template <>
struct type_caster<vdbhair::py::PathArg>
{
    PYBIND11_TYPE_CASTER(vdbhair::py::PathArg, const_name("os.PathLike | str"));
    bool load(handle src, bool)
    {
        if (!src || !vdbhair::py::isPathLike(src)) return false;
        value = vdbhair::py::PathArg(vdbhair::py::pathString(src));
        return true;
    }
    static handle cast(const vdbhair::py::PathArg& p, return_value_policy, handle) { return pybind11::str(p).release(); }
};
} // namespace pybind11::detail
