// petsc4py's C API. Its header keeps the API pointers in static variables of each
// translation unit, so every use lives in petsc4py_interop.cpp.
#pragma once

#include <petscvec.h>
#include <pybind11/pybind11.h>

namespace snede::bindings {

// Loads petsc4py's C API (PETSc must already be initialised by petsc4py).
void import_petsc4py_api();
// A petsc4py.PETSc.Vec sharing `v`; the caller keeps (and must destroy) its own reference.
pybind11::object to_petsc4py(Vec v);

}  // namespace snede::bindings
