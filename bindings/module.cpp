#include <pybind11/pybind11.h>

#include <new>
#include <stdexcept>

#include "bindings.hpp"
#include "snakehead/model.hpp"
#include "snakehead/workspace.hpp"

namespace py = pybind11;

namespace {

// snakehead.InputError (python/snakehead/_errors.py), the one type of bad input on both sides; looked up on first
// use (the package imports _errors before _core) and kept for the process's life (never released: a static
// py::object would be destroyed after the interpreter).
PyObject* input_error_type() {
  static PyObject* type = py::object(py::module_::import("snakehead._errors").attr("InputError")).release().ptr();
  return type;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() =
      "snakehead's C++ core: chain model, kinematics, TRAC-IK, workspace sweep, support polygons, box collisions, "
      "convex-shape distances (FCL), "
      "inverse dynamics, the neck's fit (Eq. 22), path checks, time-optimal path parameterization (TOPP-RA), the tracking interpolation's fit, "
      "piecewise polynomials, a timed motion's use of its limits, terrain surfaces (planes, heightfields, meshes), "
      "and the limits on what callers may ask for";
  snakehead::bindings::bind_model(m);
  snakehead::bindings::bind_trac_ik(m);
  snakehead::bindings::bind_workspace(m);
  snakehead::bindings::bind_support(m);
  snakehead::bindings::bind_shape_set(m);
  snakehead::bindings::bind_dynamics(m);
  snakehead::bindings::bind_path_check(m);
  snakehead::bindings::bind_zmp_check(m);
  snakehead::bindings::bind_topp_ra(m);
  snakehead::bindings::bind_tracking_fit(m);
  snakehead::bindings::bind_limits(m);
  snakehead::bindings::bind_core_threads(m);
  snakehead::bindings::bind_neck_fit(m);
  snakehead::bindings::bind_piecewise_polynomial(m);
  snakehead::bindings::bind_limit_ratios(m);
  snakehead::bindings::bind_terrain(m);

  // A sweep stopped because its progress callback returned False (not an error of the input).
  py::register_exception<snakehead::Cancelled>(m, "Cancelled");

  // Every C++ exception reaches Python as snakehead.InputError (snakehead::InputError: bad input, named in the
  // message), TypeError (a value pybind11 could not convert), MemoryError, Cancelled, the Python exception a
  // callback raised, or RuntimeError (any other failure of the core on valid input: a bug, never the caller's
  // fault); never an abort. This also covers exceptions raised in worker threads: the core carries them to the
  // calling thread.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const py::error_already_set&) {
      throw;  // a Python exception (from a callback): pybind11 restores it as it was
    } catch (const py::cast_error& e) {
      PyErr_SetString(PyExc_TypeError, e.what());
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own value_error, type_error, ...: already the right Python type
    } catch (const snakehead::Cancelled&) {
      throw;  // to the translator register_exception made: snakehead._core.Cancelled
    } catch (const snakehead::InputError& e) {
      PyErr_SetString(input_error_type(), e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "out of memory in snakehead's C++ core");
    } catch (const std::exception& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (...) {
      PyErr_SetString(PyExc_RuntimeError, "snakehead's C++ core failed with an exception of unknown type");
    }
  });
}
