#include "petsc4py_interop.hpp"

#include <petsc4py/petsc4py.h>

namespace snede::bindings {

void import_petsc4py_api() {
  if (import_petsc4py() < 0) throw pybind11::error_already_set();
}

pybind11::object to_petsc4py(Vec v) {
  PyObject* wrapped = PyPetscVec_New(v);  // takes its own reference
  if (!wrapped) throw pybind11::error_already_set();
  return pybind11::reinterpret_steal<pybind11::object>(wrapped);
}

}  // namespace snede::bindings
