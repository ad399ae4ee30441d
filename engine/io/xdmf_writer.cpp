#include "io/xdmf_writer.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <stdexcept>

#include "core/error.hpp"
#include "mesh/distributed_mesh.hpp"

#ifndef H5_HAVE_PARALLEL
#error "XdmfWriter needs the MPI build of HDF5 (Debian's libhdf5-openmpi-dev)"
#endif

namespace snede {

// How this rank's data of a step maps to the file's rows. A serial mesh is written whole, in
// its own order; a distributed part writes its owned vertices and its cells.
struct XdmfWriter::Layout {
  const DistributedMesh* part = nullptr;  // nullptr: a serial mesh
  Rows points, cells;
  std::vector<std::int64_t> point_rows;     // the local point written at each of this rank's point rows
  std::vector<std::int64_t> point_numbers;  // each local point's row in the file (for the cells)
  std::vector<PointField> mesh_point_fields;  // one value per local point, stored with the mesh
  std::string problem;                        // "" when the layout is usable
};

namespace {

void check_hdf5(herr_t status, const std::string& what) {
  if (status < 0) throw FileError("HDF5 failed to " + what);
}

// An HDF5 identifier closed when it goes out of scope.
struct Hdf5Id {
  hid_t id;
  herr_t (*close)(hid_t);
  ~Hdf5Id() {
    if (id >= 0) close(id);
  }
  operator hid_t() const { return id; }
};

void broadcast(std::string& text, int root, MPI_Comm comm) {
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, root, comm);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, root, comm);
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

// The code point whose UTF-8 encoding starts at text[at], and the number of bytes it takes;
// 0 bytes when text[at] does not start one (a stray byte, a cut, overlong or surrogate form).
struct CodePoint {
  char32_t value = 0;
  std::size_t length = 0;
};

CodePoint utf8_code_point(const std::string& text, std::size_t at) {
  const auto lead = static_cast<unsigned char>(text[at]);
  if (lead < 0x80) return {lead, 1};
  const std::size_t length = lead >= 0xF0 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC0 ? 2 : 0;
  if (length == 0 || at + length > text.size()) return {};
  char32_t value = lead & (0x7F >> length);
  for (std::size_t k = 1; k < length; ++k) {
    const auto next = static_cast<unsigned char>(text[at + k]);
    if ((next & 0xC0) != 0x80) return {};
    value = (value << 6) | (next & 0x3F);
  }
  static constexpr char32_t smallest[] = {0, 0, 0x80, 0x800, 0x10000};
  if (value < smallest[length] || value > 0x10FFFF || (value >= 0xD800 && value <= 0xDFFF)) return {};
  return {value, length};
}

// Control characters: not in XML 1.0 at all, or (tab, newline, carriage return) read back
// by an XML parser as a space or a newline.
bool is_control(char32_t c) { return c < 0x20; }
// Code points XML 1.0 excludes besides the control characters.
bool is_xml_excluded(char32_t c) { return c == 0xFFFE || c == 0xFFFF; }

// A field name as a message shows it: what would not print (or is not text) escaped.
std::string shown(const std::string& name) {
  static const char digits[] = "0123456789abcdef";
  std::string out;
  for (std::size_t at = 0; at < name.size();) {
    const CodePoint c = utf8_code_point(name, at);
    if (c.length == 0 || is_control(c.value)) {
      const auto byte = static_cast<unsigned char>(name[at]);
      out += std::string("\\x") + digits[byte >> 4] + digits[byte & 0xF];
      ++at;
    } else if (is_xml_excluded(c.value)) {
      out += c.value == 0xFFFE ? "\\ufffe" : "\\uffff";
      at += c.length;
    } else {
      out += name.substr(at, c.length);
      at += c.length;
    }
  }
  return out;
}

std::string code_point_name(char32_t c) {
  char text[16];
  std::snprintf(text, sizeof text, "U+%04X", static_cast<unsigned>(c));
  return text;
}

// Why `name` cannot be a field's ("" if it can): the name is both an HDF5 dataset's (no '/',
// no NUL, not "." or "..") and text in the XDMF file, which must read it back unchanged:
// UTF-8, only XML characters, none that XML turns into spaces, and no space at the end, where
// readers trim the path to the dataset.
std::string field_name_problem(const std::string& name) {
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
    return "give a non-empty name without '/', other than '.' and '..'";
  for (std::size_t at = 0; at < name.size();) {
    const CodePoint c = utf8_code_point(name, at);
    if (c.length == 0) return "it is not UTF-8 text (byte " + std::to_string(at) + ")";
    if (is_control(c.value))
      return "it holds the control character " + code_point_name(c.value) +
             ", which an XDMF (XML) file cannot hold or reads back as a space";
    if (is_xml_excluded(c.value))
      return "it holds " + code_point_name(c.value) + ", which is not an XML character";
    at += c.length;
  }
  if (name.back() == ' ') return "it ends with a space, which readers trim from the path to its data";
  return "";
}

// What is wrong with the fields ("" if nothing): each must have a name that the step's HDF5
// dataset and the XDMF file keep as it is, not a name taken, and hold one value per cell or
// point; `taken` collects the names.
template <class Field>
std::string field_problem(const std::vector<Field>& fields, const char* kind, std::int64_t n, const char* what,
                          std::vector<std::string>& taken) {
  for (const Field& field : fields) {
    const std::string& name = field.name;
    if (const std::string problem = field_name_problem(name); !problem.empty())
      return "field name '" + shown(name) + "' is not usable: " + problem;
    if (std::find(taken.begin(), taken.end(), name) != taken.end())
      return "field name '" + name + "' is used twice in one step";
    taken.push_back(name);
    if (field.values.size() != static_cast<std::size_t>(n))
      return std::string(kind) + " field '" + name + "' has " + std::to_string(field.values.size()) + " values for " +
             std::to_string(n) + " " + what;
  }
  return "";
}

// The rows `rows` of a (n, columns) array, each padded with zeros to `width` columns.
std::vector<double> rows_of(std::span<const double> values, int columns, int width,
                            const std::vector<std::int64_t>& rows) {
  std::vector<double> out(rows.size() * static_cast<std::size_t>(width), 0.0);
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (int k = 0; k < columns; ++k) out[i * width + k] = values[static_cast<std::size_t>(rows[i]) * columns + k];
  return out;
}

std::string file_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

XdmfWriter::XdmfWriter(std::string base, MPI_Comm comm)
    : base_(std::move(base)), comm_(comm), shared_(comm != MPI_COMM_SELF) {
  if (shared_) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &n_ranks_);
  }
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported as exceptions, not printed
  const hid_t file = open_file(true);
  // Creating a shared file is collective: it fails on every rank alike.
  if (file < 0) throw FileError("cannot create " + h5_path() + " (does the folder exist and is it writable?)");
  H5Fclose(file);
  publish_xdmf();
}

XdmfWriter::~XdmfWriter() = default;

hid_t XdmfWriter::open_file(bool create) const {
  const Hdf5Id access{H5Pcreate(H5P_FILE_ACCESS), H5Pclose};
  if (shared_) H5Pset_fapl_mpio(access, comm_, MPI_INFO_NULL);
  return create ? H5Fcreate(h5_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access)
                : H5Fopen(h5_path().c_str(), H5F_ACC_RDWR, access);
}

// The problem of the lowest rank that found one ("" if none found any), the same text on
// every rank, so that all throw it and none is left waiting in a collective call.
std::string XdmfWriter::agreed(const std::string& problem) const {
  if (!shared_) return problem;
  const int mine = problem.empty() ? n_ranks_ : rank_;
  int first = n_ranks_;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm_);
  if (first == n_ranks_) return "";
  std::string text = n_ranks_ > 1 ? "rank " + std::to_string(first) + ": " + problem : problem;
  broadcast(text, first, comm_);
  return text;
}

void XdmfWriter::write_rows(const std::string& path, const void* data, hid_t type, Rows rows, hsize_t columns) {
  const int rank = columns ? 2 : 1;
  const hsize_t dims[2] = {static_cast<hsize_t>(rows.total), columns};
  const hsize_t start[2] = {static_cast<hsize_t>(rows.first), 0};
  const hsize_t count[2] = {static_cast<hsize_t>(rows.count), columns};
  const Hdf5Id links{H5Pcreate(H5P_LINK_CREATE), H5Pclose};
  H5Pset_create_intermediate_group(links, 1);
  const Hdf5Id file_space{H5Screate_simple(rank, dims, nullptr), H5Sclose};
  const Hdf5Id memory_space{H5Screate_simple(rank, count, nullptr), H5Sclose};
  const Hdf5Id set{H5Dcreate2(file_, path.c_str(), type, file_space, links, H5P_DEFAULT, H5P_DEFAULT), H5Dclose};
  if (set < 0) throw FileError("HDF5 failed to create " + path + " in " + h5_path());
  if (rows.count) {
    check_hdf5(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, count, nullptr), "select rows of " + path);
  } else {  // a rank with no rows still takes part in the collective write
    H5Sselect_none(file_space);
    H5Sselect_none(memory_space);
  }
  const Hdf5Id transfer{H5Pcreate(H5P_DATASET_XFER), H5Pclose};
  if (shared_) H5Pset_dxpl_mpio(transfer, H5FD_MPIO_COLLECTIVE);
  static const double nothing = 0.0;  // HDF5 wants a buffer even for no rows
  check_hdf5(H5Dwrite(set, type, memory_space, file_space, transfer, data ? data : &nothing), "write " + path);
}

void XdmfWriter::write_step(double time, const Mesh& mesh, std::span<const double> displacement,
                            const std::vector<CellField>& cell_fields, const std::vector<PointField>& point_fields) {
  if (n_ranks_ > 1)
    throw std::invalid_argument("write_step writes a serial mesh, but this writer is shared by " +
                                std::to_string(n_ranks_) +
                                " ranks: write each rank's part of a distributed mesh instead");
  const auto n_points = static_cast<std::int64_t>(mesh.n_points());
  const auto n_cells = static_cast<std::int64_t>(mesh.n_cells());
  Layout layout;
  layout.points = {n_points, 0, n_points};
  layout.cells = {n_cells, 0, n_cells};
  layout.point_rows.resize(static_cast<std::size_t>(n_points));
  std::iota(layout.point_rows.begin(), layout.point_rows.end(), std::int64_t{0});
  layout.point_numbers = layout.point_rows;
  write(time, mesh, layout, displacement, cell_fields, point_fields);
}

void XdmfWriter::write_distributed_step(double time, const DistributedMesh& part,
                                        std::span<const double> local_displacement,
                                        const std::vector<CellField>& cell_fields,
                                        const std::vector<PointField>& point_fields) {
  int relation = MPI_UNEQUAL;
  MPI_Comm_compare(part.comm, comm_, &relation);
  // Every rank compares the same two groups, so all throw or none.
  if (relation != MPI_IDENT && relation != MPI_CONGRUENT)
    throw std::invalid_argument("write_distributed_step: the part is distributed over other ranks than the writer's; "
                                "give the writer the part's communicator");
  const Mesh& mesh = *part.local;
  const auto n_local = static_cast<std::size_t>(mesh.n_points());
  const auto n_owned = static_cast<std::int64_t>(std::count(part.owned.begin(), part.owned.end(), 1));
  const std::int64_t mine[2] = {n_owned, static_cast<std::int64_t>(mesh.n_cells())};
  std::vector<std::int64_t> counts(2 * static_cast<std::size_t>(n_ranks_));
  MPI_Allgather(mine, 2, MPI_INT64_T, counts.data(), 2, MPI_INT64_T, comm_);
  Layout layout;
  layout.part = &part;
  layout.points.count = mine[0];
  layout.cells.count = mine[1];
  for (int r = 0; r < n_ranks_; ++r) {
    if (r < rank_) layout.points.first += counts[2 * r], layout.cells.first += counts[2 * r + 1];
    layout.points.total += counts[2 * r];
    layout.cells.total += counts[2 * r + 1];
  }
  if (layout.points.total != part.n_global_vertices || layout.cells.total != part.n_global_cells)
    layout.problem = "write_distributed_step: the parts hold " + std::to_string(layout.points.total) + " vertices and " +
                     std::to_string(layout.cells.total) + " cells, the distributed mesh has " +
                     std::to_string(part.n_global_vertices) + " and " + std::to_string(part.n_global_cells);
  // PETSc numbers each rank's owned vertices contiguously, in rank order: they are this
  // rank's block of rows.
  layout.point_rows.assign(static_cast<std::size_t>(n_owned), -1);
  for (std::size_t v = 0; v < n_local; ++v) {
    if (!part.owned[v]) continue;
    const std::int64_t row = part.global_number[v] - layout.points.first;
    if (row < 0 || row >= n_owned || layout.point_rows[row] >= 0) {
      layout.problem = "write_distributed_step: the owned vertices are not numbered " +
                       std::to_string(layout.points.first) + " to " + std::to_string(layout.points.first + n_owned - 1);
      break;
    }
    layout.point_rows[row] = static_cast<std::int64_t>(v);
  }
  layout.point_numbers = part.global_number;
  layout.mesh_point_fields.push_back({"serial_vertex", {part.global_vertex.begin(), part.global_vertex.end()}});
  write(time, mesh, layout, local_displacement, cell_fields, point_fields);
}

void XdmfWriter::write(double time, const Mesh& mesh, const Layout& layout, std::span<const double> displacement,
                       const std::vector<CellField>& cell_fields, const std::vector<PointField>& point_fields) {
  const int dim = mesh.dim();
  const auto n_points = static_cast<std::int64_t>(mesh.n_points());
  const auto n_cells = static_cast<std::int64_t>(mesh.n_cells());
  std::string problem = layout.problem;
  if (problem.empty() && displacement.size() != static_cast<std::size_t>(n_points * dim))
    problem = "displacement has " + std::to_string(displacement.size()) + " values, expected " +
              std::to_string(n_points * dim);
  std::vector<std::string> names{"displacement"};
  for (const PointField& field : layout.mesh_point_fields) names.push_back(field.name);
  if (problem.empty()) problem = field_problem(cell_fields, "cell", n_cells, "cells", names);
  if (problem.empty()) problem = field_problem(point_fields, "point", n_points, "points", names);
  if (shared_) {  // every rank must create the same datasets
    std::string fields;
    for (const CellField& field : cell_fields) fields += " cell '" + field.name + "'";
    for (const PointField& field : point_fields) fields += " point '" + field.name + "'";
    std::string first_fields = fields;
    broadcast(first_fields, 0, comm_);
    if (problem.empty() && fields != first_fields)
      problem = "the fields differ from rank 0's (here:" + fields + "; on rank 0:" + first_fields + ")";
  }
  if (problem = agreed(problem); !problem.empty()) throw std::invalid_argument(problem);

  int new_mesh = last_mesh_ != &mesh || last_part_ != layout.part || mesh.connectivity().revision() != last_revision_ ||
                 mesh.n_points() != last_n_points_ || n_meshes_ == 0;
  if (shared_) MPI_Allreduce(MPI_IN_PLACE, &new_mesh, 1, MPI_INT, MPI_LOR, comm_);
  // The file is open only while a step is written, so readers (ParaView, h5py) can open it
  // between steps.
  file_ = open_file(false);
  if (file_ < 0) throw FileError("cannot open " + h5_path() + " for writing (was its folder removed?)");
  struct CloseOnExit {
    hid_t& file;
    ~CloseOnExit() {
      H5Fclose(file);
      file = -1;
    }
  } close_on_exit{file_};
  if (new_mesh) {
    const std::string group = "/mesh/" + std::to_string(n_meshes_);
    write_rows(group + "/points", rows_of(mesh.points(), dim, 3, layout.point_rows).data(), H5T_NATIVE_DOUBLE,
               layout.points, 3);
    std::vector<std::int64_t> cells;
    for (VertexId v : mesh.cells()) cells.push_back(layout.point_numbers[static_cast<std::size_t>(v)]);
    write_rows(group + "/cells", cells.data(), H5T_NATIVE_INT64, layout.cells, mesh.cell_dim() + 1);
    for (const PointField& field : layout.mesh_point_fields)
      write_rows(group + "/" + field.name, rows_of(field.values, 1, 1, layout.point_rows).data(), H5T_NATIVE_DOUBLE,
                 layout.points, 0);
    ++n_meshes_;
    last_mesh_ = &mesh;
    last_part_ = layout.part;
    last_revision_ = mesh.connectivity().revision();
    last_n_points_ = mesh.n_points();
  }
  const std::string group = "/step/" + std::to_string(steps_.size());
  write_rows(group + "/displacement", rows_of(displacement, dim, 3, layout.point_rows).data(), H5T_NATIVE_DOUBLE,
             layout.points, 3);
  Step step{time, n_meshes_ - 1, layout.points.total, layout.cells.total, dim, mesh.cell_dim(), {}, {}, {}};
  for (const CellField& field : cell_fields) {
    write_rows(group + "/" + field.name, field.values.data(), H5T_NATIVE_DOUBLE, layout.cells, 0);
    step.fields.push_back(field.name);
  }
  for (const PointField& field : point_fields) {
    write_rows(group + "/" + field.name, rows_of(field.values, 1, 1, layout.point_rows).data(), H5T_NATIVE_DOUBLE,
               layout.points, 0);
    step.point_fields.push_back(field.name);
  }
  for (const PointField& field : layout.mesh_point_fields) step.mesh_point_fields.push_back(field.name);
  steps_.push_back(std::move(step));
  publish_xdmf();
}

// Rank 0 writes the XDMF file; when it cannot, every rank throws.
void XdmfWriter::publish_xdmf() const {
  std::string problem;
  if (rank_ == 0) {
    try {
      write_xdmf();
    } catch (const FileError& error) {
      problem = error.what();
    }
  }
  if (problem = agreed(problem); !problem.empty()) throw FileError(problem);
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
        << "  <Information Name=\"dimension\" Value=\"" << s.dim << "\"/>\n"
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
    auto scalar = [&](const std::string& group, const std::string& field, const char* center, std::int64_t n) {
      out << "  <Attribute Name=\"" << xml_escaped(field) << "\" AttributeType=\"Scalar\" Center=\"" << center
          << "\">\n   <DataItem Dimensions=\"" << n << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << h5
          << ":" << group << "/" << xml_escaped(field) << "</DataItem>\n  </Attribute>\n";
    };
    for (const std::string& field : s.fields) scalar(step, field, "Cell", s.n_cells);
    for (const std::string& field : s.point_fields) scalar(step, field, "Node", s.n_points);
    for (const std::string& field : s.mesh_point_fields) scalar(mesh, field, "Node", s.n_points);
    out << " </Grid>\n";
  }
  out << "</Grid>\n</Domain>\n</Xdmf>\n";
}

}  // namespace snede
