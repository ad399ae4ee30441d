#include "bindings.hpp"
#include "core/error.hpp"
#include "core/options.hpp"
#include "core/petsc_util.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {

void bind_core(py::module_& m) {
  py::register_exception<PetscException>(m, "PetscError", PyExc_RuntimeError);
  // A Python callback run by PETSc (a petsc4py monitor) that raised makes PETSc fail with
  // petsc4py's PETSC_ERR_PYTHON while that exception is still set: it, with its type and
  // message (a KeyboardInterrupt too), is what the caller gets, not "PETSc error -1".
  // (Translators registered later are tried first; rethrowing passes to the next one.)
  py::register_exception_translator([](std::exception_ptr thrown) {
    constexpr PetscErrorCode petsc4py_python_error = -1;  // PETSC_ERR_PYTHON in petsc4py.h
    try {
      std::rethrow_exception(thrown);
    } catch (const PetscException& e) {
      if (e.code() == petsc4py_python_error && PyErr_Occurred()) return;
      throw;
    }
  });
  m.def("petsc_allocated_bytes", &petsc_allocated_bytes,
        "Bytes currently allocated by PETSc (tracked only with -malloc_debug or -malloc_view).");
  m.def("option_real", &option_real, py::arg("name"),
        "The real value of PETSc option `name` (with its '-'), or None if it is not set; a value "
        "that is not a number raises PetscError with PETSc's message.");
  m.def("option_used", &option_used, py::arg("name"),
        "Whether a PETSc object has read option `name` (without its '-') from the global database.");
}

}  // namespace snede::bindings
