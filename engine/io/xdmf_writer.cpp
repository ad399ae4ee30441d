#include "io/xdmf_writer.hpp"

#include <fstream>
#include <stdexcept>

#include "core/error.hpp"

namespace snede {
namespace {

void check_hdf5(herr_t status, const std::string& what) {
  if (status < 0) throw FileError("HDF5 failed to " + what);
}

// Text as it may stand in an XML attribute value or element.
std::string xml_escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

// Each field must name one HDF5 dataset of the step (not empty, no '/', not a name taken)
// and hold one value per cell or point; `taken` collects the names.
template <class Field>
void check_fields(const std::vector<Field>& fields, const char* kind, std::int64_t n, const char* what,
                  std::vector<std::string>& taken) {
  for (const Field& field : fields) {
    const std::string& name = field.name;
    if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
      throw std::invalid_argument("field name '" + name + "' is not usable: give a non-empty name without '/'");
    for (const std::string& other : taken)
      if (other == name) throw std::invalid_argument("field name '" + name + "' is used twice in one step");
    taken.push_back(name);
    if (field.values.size() != static_cast<std::size_t>(n))
      throw std::invalid_argument(std::string(kind) + " field '" + name + "' has " +
                                  std::to_string(field.values.size()) + " values for " + std::to_string(n) + " " + what);
  }
}

std::string file_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

XdmfWriter::XdmfWriter(std::string base) : base_(std::move(base)) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported as exceptions, not printed
  const hid_t file = H5Fcreate(h5_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) throw FileError("cannot create " + h5_path() + " (does the folder exist and is it writable?)");
  H5Fclose(file);
  write_xdmf();
}

XdmfWriter::~XdmfWriter() = default;

void XdmfWriter::write_dataset(const std::string& path, const void* data, hid_t type, hsize_t rows, hsize_t columns) {
  const hsize_t dims[2] = {rows, columns};
  hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl, 1);
  hid_t space = H5Screate_simple(columns ? 2 : 1, dims, nullptr);
  hid_t set = H5Dcreate2(file_, path.c_str(), type, space, lcpl, H5P_DEFAULT, H5P_DEFAULT);
  if (set < 0) {
    H5Sclose(space);
    H5Pclose(lcpl);
    throw FileError("HDF5 failed to create " + path + " in " + h5_path());
  }
  const herr_t status = H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
  H5Dclose(set);
  H5Sclose(space);
  H5Pclose(lcpl);
  check_hdf5(status, "write " + path);
}

void XdmfWriter::write_step(double time, const Mesh& mesh, std::span<const double> displacement,
                            const std::vector<CellField>& cell_fields, const std::vector<PointField>& point_fields) {
  const int dim = mesh.dim();
  const auto n_points = static_cast<std::int64_t>(mesh.n_points());
  const auto n_cells = static_cast<std::int64_t>(mesh.n_cells());
  if (displacement.size() != static_cast<std::size_t>(n_points * dim))
    throw std::invalid_argument("displacement has " + std::to_string(displacement.size()) + " values, expected " +
                                std::to_string(n_points * dim));
  std::vector<std::string> names{"displacement"};
  check_fields(cell_fields, "cell", n_cells, "cells", names);
  check_fields(point_fields, "point", n_points, "points", names);
  // The file is open only while a step is written, so readers (ParaView, h5py) can open it
  // between steps.
  file_ = H5Fopen(h5_path().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  if (file_ < 0) throw FileError("cannot open " + h5_path() + " for writing (was its folder removed?)");
  struct CloseOnExit {
    hid_t& file;
    ~CloseOnExit() {
      H5Fclose(file);
      file = -1;
    }
  } close_on_exit{file_};
  const bool new_mesh = last_mesh_ != &mesh || mesh.connectivity().revision() != last_revision_ ||
                        mesh.n_points() != last_n_points_ || n_meshes_ == 0;
  if (new_mesh) {
    const std::string group = "/mesh/" + std::to_string(n_meshes_);
    std::vector<double> points(static_cast<std::size_t>(n_points) * 3, 0.0);
    for (std::int64_t v = 0; v < n_points; ++v)
      for (int k = 0; k < dim; ++k) points[v * 3 + k] = mesh.points()[v * dim + k];
    write_dataset(group + "/points", points.data(), H5T_NATIVE_DOUBLE, n_points, 3);
    const std::vector<VertexId> cells32 = mesh.cells();
    const std::vector<std::int64_t> cells(cells32.begin(), cells32.end());
    write_dataset(group + "/cells", cells.data(), H5T_NATIVE_INT64, n_cells, mesh.cell_dim() + 1);
    ++n_meshes_;
    last_mesh_ = &mesh;
    last_revision_ = mesh.connectivity().revision();
    last_n_points_ = mesh.n_points();
  }
  const std::string group = "/step/" + std::to_string(steps_.size());
  std::vector<double> u(static_cast<std::size_t>(n_points) * 3, 0.0);
  for (std::int64_t v = 0; v < n_points; ++v)
    for (int k = 0; k < dim; ++k) u[v * 3 + k] = displacement[v * dim + k];
  write_dataset(group + "/displacement", u.data(), H5T_NATIVE_DOUBLE, n_points, 3);
  Step step{time, n_meshes_ - 1, n_points, n_cells, mesh.cell_dim(), {}, {}};
  for (const CellField& field : cell_fields) {
    write_dataset(group + "/" + field.name, field.values.data(), H5T_NATIVE_DOUBLE, n_cells, 0);
    step.fields.push_back(field.name);
  }
  for (const PointField& field : point_fields) {
    write_dataset(group + "/" + field.name, field.values.data(), H5T_NATIVE_DOUBLE, n_points, 0);
    step.point_fields.push_back(field.name);
  }
  steps_.push_back(std::move(step));
  write_xdmf();
}

void XdmfWriter::write_xdmf() const {
  std::ofstream out(xdmf_path());
  if (!out) throw FileError("cannot write " + xdmf_path());
  out.precision(17);  // times read back exactly (a double's round-trip precision)
  const std::string h5 = xml_escaped(file_name(h5_path()));
  out << "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
      << "<Grid Name=\"series\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t i = 0; i < steps_.size(); ++i) {
    const Step& s = steps_[i];
    const std::string mesh = "/mesh/" + std::to_string(s.mesh);
    const std::string step = "/step/" + std::to_string(i);
    out << " <Grid Name=\"step " << i << "\" GridType=\"Uniform\">\n"
        << "  <Time Value=\"" << s.time << "\"/>\n"
        << "  <Topology TopologyType=\"" << (s.cell_dim == 3 ? "Tetrahedron" : "Triangle") << "\" NumberOfElements=\""
        << s.n_cells << "\">\n"
        << "   <DataItem Dimensions=\"" << s.n_cells << " " << s.cell_dim + 1 << "\" NumberType=\"Int\" Precision=\"8\" "
        << "Format=\"HDF\">" << h5 << ":" << mesh << "/cells</DataItem>\n  </Topology>\n"
        << "  <Geometry GeometryType=\"XYZ\">\n   <DataItem Dimensions=\"" << s.n_points
        << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << h5 << ":" << mesh
        << "/points</DataItem>\n  </Geometry>\n"
        << "  <Attribute Name=\"displacement\" AttributeType=\"Vector\" Center=\"Node\">\n   <DataItem Dimensions=\""
        << s.n_points << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << h5 << ":" << step
        << "/displacement</DataItem>\n  </Attribute>\n";
    auto scalar = [&](const std::string& field, const char* center, std::int64_t n) {
      out << "  <Attribute Name=\"" << xml_escaped(field) << "\" AttributeType=\"Scalar\" Center=\"" << center
          << "\">\n   <DataItem Dimensions=\"" << n << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << h5
          << ":" << step << "/" << xml_escaped(field) << "</DataItem>\n  </Attribute>\n";
    };
    for (const std::string& field : s.fields) scalar(field, "Cell", s.n_cells);
    for (const std::string& field : s.point_fields) scalar(field, "Node", s.n_points);
    out << " </Grid>\n";
  }
  out << "</Grid>\n</Domain>\n</Xdmf>\n";
}

}  // namespace snede
