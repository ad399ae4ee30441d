#include "petsc4py_interop.hpp"

#include <petsc4py/petsc4py.h>

namespace snede::bindings {

void import_petsc4py_api() {
  if (import_petsc4py() < 0) throw pybind11::error_already_set();
}

namespace {
pybind11::object steal(PyObject* wrapped) {
  if (!wrapped) throw pybind11::error_already_set();
  return pybind11::reinterpret_steal<pybind11::object>(wrapped);
}
}  // namespace

// Each New takes its own reference to the PETSc object.
pybind11::object to_petsc4py(Vec v) { return steal(PyPetscVec_New(v)); }
pybind11::object to_petsc4py(Mat m) { return steal(PyPetscMat_New(m)); }
pybind11::object to_petsc4py(KSP ksp) { return steal(PyPetscKSP_New(ksp)); }
pybind11::object to_petsc4py(SNES snes) { return steal(PyPetscSNES_New(snes)); }
pybind11::object to_petsc4py(TS ts) { return steal(PyPetscTS_New(ts)); }

}  // namespace snede::bindings
