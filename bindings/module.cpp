#include "bindings.hpp"
#include "petsc4py_interop.hpp"

PYBIND11_MODULE(_snede, m) {
  m.doc() = "snede engine (C++); use the snede package, not this module directly";
  // PETSc was initialised by petsc4py when snede was imported; load petsc4py's C API so the
  // engine can hand PETSc objects to Python.
  snede::bindings::import_petsc4py_api();
  snede::bindings::bind_core(m);
  snede::bindings::bind_mesh(m);
  snede::bindings::bind_fem(m);
  snede::bindings::bind_solve(m);
  snede::bindings::bind_dynamics(m);
  snede::bindings::bind_io(m);
  snede::bindings::bind_topology(m);
  snede::bindings::bind_edits(m);
  snede::bindings::bind_needle(m);
  snede::bindings::bind_cutting(m);
  snede::bindings::bind_planar_cutting(m);
  snede::bindings::bind_surface_cutting(m);
  snede::bindings::bind_distributed(m);
}
