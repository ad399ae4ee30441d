#include "bindings.hpp"
#include "io/xdmf_writer.hpp"
#include "mesh/distributed_mesh.hpp"

#include <pybind11/stl.h>

#include <optional>

namespace snede::bindings {
namespace {

template <class Field>
std::vector<Field> fields_of(const std::map<std::string, DoubleArray>& arrays) {
  std::vector<Field> fields;
  for (const auto& [name, values] : arrays)
    fields.push_back({name, std::vector<double>(values.data(), values.data() + values.size())});
  return fields;
}

void write_step(XdmfWriter& writer, double time, const Mesh& mesh, const DoubleArray& displacement,
                const std::map<std::string, DoubleArray>& cell_fields,
                const std::map<std::string, DoubleArray>& point_fields) {
  writer.write_step(time, mesh, {displacement.data(), static_cast<std::size_t>(displacement.size())},
                    fields_of<CellField>(cell_fields), fields_of<PointField>(point_fields));
}

void write_distributed_step(XdmfWriter& writer, double time, const DistributedMesh& part,
                            const DoubleArray& local_displacement, const std::map<std::string, DoubleArray>& cell_fields,
                            const std::map<std::string, DoubleArray>& point_fields) {
  writer.write_distributed_step(time, part, view(local_displacement), fields_of<CellField>(cell_fields),
                                fields_of<PointField>(point_fields));
}

}  // namespace

void bind_io(py::module_& m) {
  py::class_<XdmfWriter>(m, "XdmfWriter")
      // `comm`: a communicator's Fortran handle (mpi4py's Comm.py2f()); None writes serially.
      .def(py::init([](std::string base, std::optional<std::int64_t> comm) {
             return std::make_unique<XdmfWriter>(
                 std::move(base), comm ? MPI_Comm_f2c(static_cast<MPI_Fint>(*comm)) : MPI_COMM_SELF);
           }),
           py::arg("base"), py::arg("comm") = py::none())
      .def("write_step", &write_step, py::arg("time"), py::arg("mesh"), py::arg("displacement"),
           py::arg("cell_fields"), py::arg("point_fields") = std::map<std::string, DoubleArray>{})
      .def("write_distributed_step", &write_distributed_step, py::arg("time"), py::arg("part"),
           py::arg("local_displacement"), py::arg("cell_fields"),
           py::arg("point_fields") = std::map<std::string, DoubleArray>{})
      .def_property_readonly("n_steps", &XdmfWriter::n_steps)
      .def_property_readonly("n_meshes", &XdmfWriter::n_meshes)
      .def_property_readonly("xdmf_path", &XdmfWriter::xdmf_path)
      .def_property_readonly("h5_path", &XdmfWriter::h5_path);
}

}  // namespace snede::bindings
