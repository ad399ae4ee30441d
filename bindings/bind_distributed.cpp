#include "bindings.hpp"
#include "mesh/distributed_mesh.hpp"

namespace snede::bindings {

void bind_distributed(py::module_& m) {
  py::class_<DistributedMesh>(m, "DistributedMesh")
      .def_property_readonly(
          "local", [](DistributedMesh& d) -> Mesh& { return *d.local; }, py::return_value_policy::reference_internal)
      .def_property_readonly("global_vertex", [](const DistributedMesh& d) { return to_array(d.global_vertex, 1); })
      .def_property_readonly("owned", [](const DistributedMesh& d) { return to_array(d.owned, 1); })
      .def_readonly("n_global_vertices", &DistributedMesh::n_global_vertices)
      .def_readonly("n_global_cells", &DistributedMesh::n_global_cells);
  // `comm` is the communicator's Fortran handle (mpi4py's Comm.py2f()).
  m.def(
      "distribute_mesh",
      [](std::int64_t comm, const Mesh* serial) {
        return distribute_mesh(MPI_Comm_f2c(static_cast<MPI_Fint>(comm)), serial);
      },
      py::arg("comm"), py::arg("serial").none(true));
}

}  // namespace snede::bindings
