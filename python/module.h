// What the Python module's parts share (issue #26): library errors on their way to Python, and
// long work run with the GIL released and Ctrl-C caught.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "core/interrupt.h"
#include "core/point_set.h"
#include "core/progress.h"
#include "core/result.h"

namespace dpoint::python {

namespace py = pybind11;

// A library error, raised in Python by the translator module.cpp registers: dpoint.Error (a
// ValueError) for bad input and usage, MemoryError for resource limits, dpoint.DeviceError (a
// RuntimeError) for Vulkan faults, KeyboardInterrupt for an interrupt; each with the CLI's message
// and its exit code as `exit_code`.
struct LibraryError {
  Error error;
};
[[noreturn]] inline void raise(const Error& error) { throw LibraryError{error}; }
inline void check(const Status& status) {
  if (!status) raise(status.error());
}
template <typename T>
T take(Result<T> result) {
  if (!result) raise(result.error());
  return std::move(*result);
}

// Whether Ctrl-C is Python's to handle here: this is the main thread (the one Python runs signal
// handlers in) and SIGINT has a Python handler (default_int_handler's KeyboardInterrupt, or the
// program's own); not when the process ignores SIGINT (SIG_IGN, as a background job of a script
// does) or leaves it to the system (SIG_DFL).
bool catchesSigint();

// After the work stopped for a SIGINT: Python's handler runs as for any SIGINT (KeyboardInterrupt,
// or what the program's handler raises). One that returns still gets KeyboardInterrupt: the call
// was cut short and has no result.
[[noreturn]] void raiseInterrupt();

// Runs `work` with the GIL released, so other Python threads run. Where Python handles Ctrl-C
// (catchesSigint), SIGINT is caught while it runs (core/interrupt.h's InterruptScope): the work
// stops as the CLI's does, leaving no output, and Python's handler runs once it has
// (raiseInterrupt: KeyboardInterrupt by default).
template <typename Work>
auto released(Work&& work) {
  std::optional<InterruptScope> scope;
  if (catchesSigint()) scope.emplace();
  std::optional<decltype(work())> result;
  {
    py::gil_scoped_release release;
    result.emplace(work());
  }
  const bool interrupted = scope && scope->caught();
  scope.reset();
  if (interrupted) raiseInterrupt();
  return std::move(*result);
}

// A set that a call reads with the GIL released (write, info, render, sample): while it does, the
// set's colours, triangles and attributes may not change (a review finding: set_attribute from
// another thread while write ran reallocated the attributes under it and corrupted the heap).
// Made, checked and ended with the GIL held, so the GIL guards the registry.
class SetInUse {
 public:
  explicit SetInUse(const PointSet* set);
  ~SetInUse();
  SetInUse(const SetInUse&) = delete;
  SetInUse& operator=(const SetInUse&) = delete;

 private:
  const PointSet* set_;
};
// Raises RuntimeError where a call in another thread is reading `set` (SetInUse): `what` is the
// change refused.
void checkNotInUse(const PointSet& set, const std::string& what);

// What an instance of one of the module's classes holds, null for None. TypeError for anything
// else, and for an instance made by T.__new__ without __init__, which holds nothing (a review
// finding: using one read uninitialised memory). `made_by` says how one is made, for the message.
template <typename T>
std::shared_ptr<T> heldObject(const py::handle& object, const char* made_by) {
  if (object.is_none()) return nullptr;
  // The class's name for a message only: this runs at every property's read.
  const auto name = [] { return std::string(py::str(py::type::of<T>().attr("__name__"))); };
  if (!py::isinstance<T>(object))
    throw py::type_error("expected a dpoint." + name() + ", not " + Py_TYPE(object.ptr())->tp_name);
  try {
    return py::cast<std::shared_ptr<T>>(object);
  } catch (const py::cast_error&) {
    throw py::type_error("this " + name() + " holds nothing: it was made by " + name() + ".__new__ without __init__ (" +
                         made_by + ")");
  }
}
// What `self` holds (heldObject; never None).
template <typename T>
T& heldBy(const py::handle& self, const char* made_by) {
  if (self.is_none())
    throw py::type_error("expected a dpoint." + std::string(py::str(py::type::of<T>().attr("__name__"))) + ", not None");
  return *heldObject<T>(self, made_by);  // the Python object keeps it
}
// The set a dpoint.PointSet holds (heldObject), null for None.
inline std::shared_ptr<PointSet> heldSet(const py::handle& object) {
  return heldObject<PointSet>(object, "make one with dpoint.PointSet(positions)");
}
inline PointSet& setOf(const py::handle& self) { return heldBy<PointSet>(self, "make one with dpoint.PointSet(positions)"); }

// Each line a UserWarning shown at the line that called the package's function: stack level 2, as
// read, write, sample and info are called through their wrappers in dpoint/__init__.py.
void warnAtCaller(const std::vector<std::string>& lines);

// Progress lines on stderr when asked (progress=True), else none.
inline std::FILE* progressFile(bool progress) { return progress ? stderr : nullptr; }

// The parts, each registering its functions and classes.
void addPointSet(py::module_& m);
void addRender(py::module_& m);
void addCommands(py::module_& m);

}  // namespace dpoint::python
