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

namespace {
// petsc4py does not destroy a handle Python drops: it parks the object in PETSc's garbage until
// PETSc.garbage_cleanup(comm) (a destroy there could be collective). A loop that drops the Mat
// of body.assemble_tangent() grew by its size at every call. Before handing out a new handle,
// snede frees what was dropped on PETSC_COMM_SELF: collective on one rank, so never a hang.
// Handles on a communicator of several ranks stay for the user's own collective cleanup.
void free_dropped_handles() {
  const pybind11::module_ petsc = pybind11::module_::import("petsc4py.PETSc");
  petsc.attr("garbage_cleanup")(petsc.attr("COMM_SELF"));
}

template <class Handle>
pybind11::object wrapped(PyObject* (*make)(Handle), Handle handle) {
  free_dropped_handles();
  return steal(make(handle));
}
}  // namespace

// Each New takes its own reference to the PETSc object.
pybind11::object to_petsc4py(Vec v) { return wrapped(PyPetscVec_New, v); }
pybind11::object to_petsc4py(Mat m) { return wrapped(PyPetscMat_New, m); }
pybind11::object to_petsc4py(KSP ksp) { return wrapped(PyPetscKSP_New, ksp); }
pybind11::object to_petsc4py(SNES snes) { return wrapped(PyPetscSNES_New, snes); }
pybind11::object to_petsc4py(TS ts) { return wrapped(PyPetscTS_New, ts); }

}  // namespace snede::bindings
