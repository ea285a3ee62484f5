// The extension module dpoint._dpoint (issue #26): the same libraries as the CLI, with NumPy
// arrays in and out. python/dpoint/__init__.py is the Python face over it (keyword arguments,
// pandas, warnings); this file holds the errors and the module's parts.
#include "cli/version.h"
#include "python/module.h"

#include <stdexcept>
#include <unordered_set>

namespace dpoint::python {

bool catchesSigint() {
  py::module_ threading = py::module_::import("threading");
  if (!threading.attr("current_thread")().is(threading.attr("main_thread")())) return false;
  py::module_ signal = py::module_::import("signal");
  py::object handler = signal.attr("getsignal")(signal.attr("SIGINT"));
  return !handler.is_none() && !handler.equal(signal.attr("SIG_IGN")) && !handler.equal(signal.attr("SIG_DFL"));
}

void raiseInterrupt() {
  PyErr_SetInterrupt();  // as if SIGINT came now, to the handler the scope had put aside
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  PyErr_SetNone(PyExc_KeyboardInterrupt);
  throw py::error_already_set();
}

namespace {
// The sets calls are reading now (SetInUse), a set once per call.
std::unordered_multiset<const PointSet*>& setsInUse() {
  static std::unordered_multiset<const PointSet*> sets;
  return sets;
}
}  // namespace

SetInUse::SetInUse(const PointSet* set) : set_(set) {
  if (set_) setsInUse().insert(set_);
}

SetInUse::~SetInUse() {
  if (set_) setsInUse().erase(setsInUse().find(set_));
}

void warnAtCaller(const std::vector<std::string>& lines) {
  for (const std::string& line : lines)
    if (PyErr_WarnEx(PyExc_UserWarning, line.c_str(), 2) < 0) throw py::error_already_set();
}

void checkNotInUse(const PointSet& set, const std::string& what) {
  if (setsInUse().count(&set))
    throw std::runtime_error(what + ": the set is being read by a dpoint call in another thread (write, info, render, "
                          "sample); change it once that call returns");
}

namespace {

PyObject* g_error = nullptr;         // dpoint.Error (ValueError)
PyObject* g_device_error = nullptr;  // dpoint.DeviceError (RuntimeError)

void setError(PyObject* type, const Error& error) {
  PyObject* value = PyObject_CallFunction(type, "s", error.message.c_str());
  if (!value) return;  // its own error stands
  PyObject* code = PyLong_FromLong(static_cast<long>(error.code));
  if (code) {
    PyObject_SetAttrString(value, "exit_code", code);
    Py_DECREF(code);
  }
  PyErr_SetObject(type, value);
  Py_DECREF(value);
}

void translate(std::exception_ptr thrown) {
  try {
    if (thrown) std::rethrow_exception(thrown);
  } catch (const LibraryError& e) {
    switch (e.error.code) {
      case ExitCode::kResourceLimit: setError(PyExc_MemoryError, e.error); break;
      case ExitCode::kNoDevice: setError(g_device_error, e.error); break;
      case ExitCode::kInterrupted:
      case ExitCode::kTerminated: setError(PyExc_KeyboardInterrupt, e.error); break;
      default: setError(g_error, e.error); break;
    }
  }
}

}  // namespace
}  // namespace dpoint::python

PYBIND11_MODULE(_dpoint, m) {
  using namespace dpoint::python;
  m.doc() = "dpoint's libraries for Python: double-precision point sets as NumPy arrays (see dpoint/__init__.py)";
  m.attr("__version__") = DPOINT_VERSION;
  m.attr("_install_prefix") = DPOINT_INSTALL_PREFIX;
  g_error = PyErr_NewExceptionWithDoc("dpoint.Error",
                                      "Bad input or a bad option: the CLI's message (exit_code 1 or 2)",
                                      PyExc_ValueError, nullptr);
  g_device_error = PyErr_NewExceptionWithDoc("dpoint.DeviceError",
                                             "No usable Vulkan device, or a Vulkan fault (the CLI's exit code 3)",
                                             PyExc_RuntimeError, nullptr);
  // The exit code of one raised without one (the package's own checks, a DataFrame's columns).
  py::handle(g_error).attr("exit_code") = static_cast<int>(dpoint::ExitCode::kBadInput);
  py::handle(g_device_error).attr("exit_code") = static_cast<int>(dpoint::ExitCode::kNoDevice);
  m.attr("Error") = py::handle(g_error);
  m.attr("DeviceError") = py::handle(g_device_error);
  py::register_exception_translator(translate);
  addPointSet(m);
  addRender(m);
  addCommands(m);
}
