#include "bindings.hpp"
#include "core/error.hpp"
#include "core/exclusive_use.hpp"
#include "core/interrupt.hpp"
#include "core/options.hpp"
#include "core/petsc_util.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {

void bind_core(py::module_& m) {
  py::register_exception<PetscException>(m, "PetscError", error_bases(PyExc_RuntimeError));
  py::register_exception<FileError>(m, "FileError", error_bases(PyExc_OSError));
  py::register_exception<BodyInUse>(m, "BodyInUse", error_bases(PyExc_RuntimeError));
  // A solve stopped by Python — a petsc4py monitor that raised (PETSc then fails with
  // petsc4py's PETSC_ERR_PYTHON), or a Ctrl-C seen by the interrupt check below — comes back
  // as a PetscError while Python's exception is still set: that exception, with its type and
  // message (KeyboardInterrupt for Ctrl-C), is what the caller gets, not "PETSc error -1".
  // (Translators registered later are tried first; rethrowing passes to the next one.)
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      std::rethrow_exception(thrown);
    } catch (const PetscException&) {
      if (PyErr_Occurred()) return;
      throw;
    }
  });
  // The solvers ask between iterations whether to stop: Python's signal handlers run here, and a
  // SIGINT leaves a KeyboardInterrupt set and stops the solve. Long calls release the GIL (so a
  // window's thread runs during a solve, issue 37): the check takes it back first.
  set_interrupt_check([] {
    py::gil_scoped_acquire gil;
    return PyErr_CheckSignals() != 0;
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
