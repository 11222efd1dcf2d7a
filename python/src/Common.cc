// The exception mapping, the interrupter and Ctrl-C for the vdbhair Python module.
#include "Common.h"

#include <pybind11/stl.h>

#include <vdbhair/Exceptions.h>
#include <vdbhair/Parameters.h>
#include <vdbhair/scalp/HeadFile.h>

#include <cmath>
#include <csignal>

namespace vdbhair::py {

// ---------------------------------------------------------------------------------------------
// Exceptions

namespace {

PyObject* gError = nullptr;

/// A new exception class vdbhair.<name> deriving from vdbhair.Error and @a builtin (if any).
PyObject* newException(pyb::module_& m, const char* name, PyObject* builtin, const char* doc)
{
    const std::string qualified = std::string("vdbhair.") + name;
    pyb::tuple bases = pyb::make_tuple(pyb::handle(gError), pyb::handle(builtin));
    PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
    if (!type) throw pyb::error_already_set();
    m.add_object(name, pyb::handle(type));  // the module holds a reference
    return type;
}

} // namespace

void registerExceptions(pyb::module_& m)
{
    gError = PyErr_NewExceptionWithDoc("vdbhair.Error",
                                       "Base of every error vdbhair raises (the library's vdbhair::Error). Its message is the "
                                       "library's one line: where, what, the value received and the rule broken.",
                                       PyExc_Exception, nullptr);
    if (!gError) throw pyb::error_already_set();
    m.add_object("Error", pyb::handle(gError));
    static PyObject* ioError = newException(m, "IoError", PyExc_OSError,
                                            "A file could not be opened, read, written or renamed (also an OSError).");
    static PyObject* formatError = newException(m, "FormatError", PyExc_ValueError,
                                                "A file's content breaks its format (also a ValueError).");
    static PyObject* unsupportedError = newException(m, "UnsupportedError", PyExc_ValueError,
                                                     "A format or version recognised but not supported (also a ValueError).");
    static PyObject* argumentError = newException(m, "ArgumentError", PyExc_ValueError,
                                                  "An argument out of its valid range (the library's ValueError; also a ValueError).");
    static PyObject* lookupError = newException(m, "NotFoundError", PyExc_LookupError,
                                                "A named item is missing, such as a grid not in a file (also a LookupError).");
    static PyObject* typeError = newException(m, "GridTypeError", PyExc_TypeError,
                                              "An item of the wrong type, such as a float grid where a vector grid is needed "
                                              "(the library's TypeError; also a TypeError).");
    static PyObject* limitError = newException(m, "LimitError", PyExc_ValueError,
                                               "Work would exceed a resource cap; the message says the estimate and the cap "
                                               "(also a ValueError).");

    // A library error that names parameters (ParamError) gives them as Python's keywords.
    pyb::register_exception_translator([](std::exception_ptr p) {
        const auto message = [](const std::exception& e) { return spelledMessage(e, ParamSpelling::Keyword); };
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InterruptedError& e) {
            PyErr_SetString(PyExc_KeyboardInterrupt, message(e).c_str());
        } catch (const IoError& e) {
            PyErr_SetString(ioError, message(e).c_str());
        } catch (const FormatError& e) {
            PyErr_SetString(formatError, message(e).c_str());
        } catch (const UnsupportedError& e) {
            PyErr_SetString(unsupportedError, message(e).c_str());
        } catch (const ValueError& e) {
            PyErr_SetString(argumentError, message(e).c_str());
        } catch (const LookupError& e) {
            PyErr_SetString(lookupError, message(e).c_str());
        } catch (const TypeError& e) {
            PyErr_SetString(typeError, message(e).c_str());
        } catch (const LimitError& e) {
            PyErr_SetString(limitError, message(e).c_str());
        } catch (const Error& e) {
            PyErr_SetString(gError, message(e).c_str());
        }
    });
}

// ---------------------------------------------------------------------------------------------
// Ctrl-C

namespace {

std::atomic<bool> gSignalled{false};
int gDepth = 0;             ///< nested InterruptScopes (touched with the GIL held only)
struct sigaction gPrevious;  ///< the handler the outermost scope replaced

extern "C" void onSigint(int)
{
    gSignalled.store(true, std::memory_order_relaxed);  // lock-free: async-signal-safe
}

/// Whether the calling thread is Python's main thread and SIGINT has Python's default handler
/// (which would raise KeyboardInterrupt): only then does a scope take SIGINT over.
bool mayTakeSigint()
{
    pyb::module_ threading = pyb::module_::import("threading");
    if (!threading.attr("current_thread")().is(threading.attr("main_thread")())) return false;
    pyb::module_ signal = pyb::module_::import("signal");
    return signal.attr("getsignal")(signal.attr("SIGINT")).is(signal.attr("default_int_handler"));
}

} // namespace

InterruptScope::InterruptScope()
{
    if (gDepth++ > 0) return;
    gSignalled.store(false);
    if (!mayTakeSigint()) return;
    struct sigaction action = {};
    action.sa_handler = onSigint;
    sigemptyset(&action.sa_mask);
    mInstalled = sigaction(SIGINT, &action, &gPrevious) == 0;
}

InterruptScope::~InterruptScope()
{
    --gDepth;
    if (mInstalled) sigaction(SIGINT, &gPrevious, nullptr);
}

bool InterruptScope::signalled() { return gSignalled.load(std::memory_order_relaxed); }

// ---------------------------------------------------------------------------------------------
// The interrupter

void PyInterrupter::start(const char* name)
{
    startWork(name, 0, "");
}

void PyInterrupter::startWork(const char* name, std::uint64_t total, const char* unit)
{
    if (mProgress.is_none()) return;
    std::lock_guard<std::mutex> lock(mMutex);
    mStage = name ? name : "";
    mUnit = unit ? unit : "";
    mTotal = total;
    report(0, true);
}

bool PyInterrupter::wasInterrupted(int)
{
    return InterruptScope::signalled() || mCallbackFailed.load(std::memory_order_relaxed);
}

bool PyInterrupter::wasInterruptedAt(std::uint64_t done, int percent)
{
    if (!mProgress.is_none() && !mCallbackFailed.load(std::memory_order_relaxed)) {
        std::unique_lock<std::mutex> lock(mMutex, std::try_to_lock);  // another thread reporting: skip
        if (lock.owns_lock()) report(done, false);
    }
    return wasInterrupted(percent);
}

void PyInterrupter::report(std::uint64_t done, bool force)
{
    if (mCallbackFailed.load(std::memory_order_relaxed)) return;
    const auto now = std::chrono::steady_clock::now();
    if (!force && now - mLast < std::chrono::milliseconds(100)) return;
    mLast = now;
    pyb::gil_scoped_acquire acquire;
    try {
        mProgress(mStage, done, mTotal, mUnit);
    } catch (pyb::error_already_set& e) {
        mError.emplace(std::move(e));
        mCallbackFailed.store(true);
    }
}

bool isPathLike(const pyb::handle& obj)
{
    return pyb::isinstance<pyb::str>(obj) || pyb::isinstance<pyb::bytes>(obj) || pyb::hasattr(obj, "__fspath__");
}

std::string pathString(const pyb::handle& obj, const std::string& what)
{
    if (!isPathLike(obj)) {
        throw TypeError(what + ": must be a path (str or os.PathLike such as pathlib.Path), got " +
                        std::string(pyb::str(obj.get_type().attr("__name__"))));
    }
    const pyb::module_ os = pyb::module_::import("os");
    return os.attr("fsdecode")(os.attr("fspath")(obj)).cast<std::string>();
}

HeadArgument::HeadArgument(const pyb::object& h, const std::string& policyName) : policy(headPolicyFromName(policyName))
{
    if (h.is_none()) return;
    if (isPathLike(h)) {
        const std::string name = pathString(h, "head");
        if (name == "none") head = HeadObstacle::none();
        else path = name;
        return;
    }
    std::array<double, 4> s{};
    try {
        s = h.cast<std::array<double, 4>>();
    } catch (const pyb::cast_error&) {
        throw TypeError("head: must be None, 'none', a path to a mesh or a .vdb level set (str or os.PathLike), or a sphere (x, y, z, r); got " +
                        std::string(pyb::str(h.get_type().attr("__name__"))));
    }
    head = HeadObstacle::sphere(Vec3d(s[0], s[1], s[2]), s[3], policy);
}

HeadObstacle HeadArgument::get(const std::string& where) const
{
    return path ? readHeadObstacle(*path, where + ": head=" + *path, policy) : head;
}

std::vector<Vec3d> pointsArgument(const pyb::handle& obj, const std::string& what)
{
    const auto a = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(obj);
    if (!a || a.ndim() != 2 || a.shape(1) != 3) throw ValueError(what + ": must be an (N, 3) array of points");
    std::vector<Vec3d> out(std::size_t(a.shape(0)));
    const double* d = a.data();
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = Vec3d(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
        if (!std::isfinite(d[3 * i]) || !std::isfinite(d[3 * i + 1]) || !std::isfinite(d[3 * i + 2]))
            throw ValueError(what + "[" + std::to_string(i) + "]: not finite");
    }
    return out;
}

} // namespace vdbhair::py
