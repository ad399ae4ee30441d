#include "bindings.hpp"
#include "core/error.hpp"
#include "core/options.hpp"

#include <pybind11/stl.h>

namespace snede::bindings {

void bind_core(py::module_& m) {
  py::register_exception<PetscException>(m, "PetscError", PyExc_RuntimeError);
  m.def("option_real", &option_real, py::arg("name"),
        "The real value of PETSc option `name` (with its '-'), or None if it is not set; a value "
        "that is not a number raises PetscError with PETSc's message.");
}

}  // namespace snede::bindings
