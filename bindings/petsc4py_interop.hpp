// petsc4py's C API. Its header keeps the API pointers in static variables of each
// translation unit, so every use lives in petsc4py_interop.cpp.
#pragma once

#include <petscksp.h>
#include <petscsnes.h>
#include <petscts.h>
#include <petscvec.h>
#include <pybind11/pybind11.h>

namespace snede::bindings {

// Loads petsc4py's C API (PETSc must already be initialised by petsc4py).
void import_petsc4py_api();
// A petsc4py.PETSc.Vec sharing `v`; the caller keeps (and must destroy) its own reference.
pybind11::object to_petsc4py(Vec v);
pybind11::object to_petsc4py(Mat m);
pybind11::object to_petsc4py(KSP ksp);
pybind11::object to_petsc4py(SNES snes);
pybind11::object to_petsc4py(TS ts);

}  // namespace snede::bindings
