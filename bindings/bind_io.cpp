#include "bindings.hpp"
#include "io/xdmf_writer.hpp"

#include <pybind11/stl.h>

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

}  // namespace

void bind_io(py::module_& m) {
  py::class_<XdmfWriter>(m, "XdmfWriter")
      .def(py::init<std::string>(), py::arg("base"))
      .def("write_step", &write_step, py::arg("time"), py::arg("mesh"), py::arg("displacement"),
           py::arg("cell_fields"), py::arg("point_fields") = std::map<std::string, DoubleArray>{})
      .def_property_readonly("n_steps", &XdmfWriter::n_steps)
      .def_property_readonly("n_meshes", &XdmfWriter::n_meshes)
      .def_property_readonly("xdmf_path", &XdmfWriter::xdmf_path)
      .def_property_readonly("h5_path", &XdmfWriter::h5_path);
}

}  // namespace snede::bindings
