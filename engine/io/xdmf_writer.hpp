// Time series for ParaView: one HDF5 file with the heavy data and an XDMF file describing
// it. A mesh is written again only when the connectivity or the number of points changed
// since the last step, so a simulation whose topology changes (cuts, bisection) gives a
// series in which each step points to the mesh it had.
//
// A writer over a communicator other than MPI_COMM_SELF writes one series from the parts of
// a distributed mesh (issue 18): every rank writes its own rows into the shared HDF5 file
// through MPI-IO, and rank 0 writes the XDMF file, in the format of a serial series.
#pragma once

#include <hdf5.h>
#include <mpi.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace snede {

struct DistributedMesh;

struct CellField {
  std::string name;
  std::vector<double> values;  // one per row of mesh.cells()
};

struct PointField {
  std::string name;
  std::vector<double> values;  // one per mesh point (row of the coordinates)
};

class XdmfWriter {
 public:
  // Writes `<base>.h5` and `<base>.xdmf` (overwriting them). With a communicator other than
  // MPI_COMM_SELF, the constructor and every step are collective on it; it must outlive the
  // writer, and `base`'s folder must exist for every rank.
  explicit XdmfWriter(std::string base, MPI_Comm comm = MPI_COMM_SELF);
  ~XdmfWriter();
  XdmfWriter(const XdmfWriter&) = delete;
  XdmfWriter& operator=(const XdmfWriter&) = delete;

  // A serial mesh (on a writer of one rank). displacement: (n_points, dim); written as
  // 3-component vectors (z = 0 in 2D), so each step says its dimension in an <Information
  // Name="dimension">. Field names must be distinct, not "displacement", and read back
  // unchanged from HDF5 and XML: UTF-8 with no control character, no '/' and no final space.
  // A step with a bad field throws std::invalid_argument before writing anything.
  void write_step(double time, const Mesh& mesh, std::span<const double> displacement,
                  const std::vector<CellField>& cell_fields, const std::vector<PointField>& point_fields = {});

  // Collective: one step of a part distributed over the writer's communicator, every
  // argument this rank's: local_displacement (n_local_vertices, dim), cell fields one value
  // per local cell, point fields one per local vertex. The file holds the whole mesh: points
  // in PETSc's global vertex order (each rank's owned vertices), with the point field
  // "serial_vertex" giving each point's id in the serial mesh; cells in rank order. The part's
  // mesh is written at its first step only. Bad input raises the same std::invalid_argument
  // on every rank before anything is written.
  void write_distributed_step(double time, const DistributedMesh& part, std::span<const double> local_displacement,
                              const std::vector<CellField>& cell_fields,
                              const std::vector<PointField>& point_fields = {});

  int n_steps() const { return static_cast<int>(steps_.size()); }
  int n_meshes() const { return n_meshes_; }
  std::string xdmf_path() const { return base_ + ".xdmf"; }
  std::string h5_path() const { return base_ + ".h5"; }

 private:
  struct Step {
    double time;
    int mesh;
    std::int64_t n_points, n_cells;
    int dim;       // of the coordinates: 2 (written with z = 0) or 3
    int cell_dim;  // 2: triangles (2D or a surface), 3: tetrahedra
    std::vector<std::string> fields;        // cell fields
    std::vector<std::string> point_fields;
    std::vector<std::string> mesh_point_fields;  // point fields stored with the mesh
  };
  // This rank's block of a dataset's rows: [first, first + count) of total.
  struct Rows {
    std::int64_t total = 0, first = 0, count = 0;
  };
  struct Layout;
  void write(double time, const Mesh& mesh, const Layout& layout, std::span<const double> displacement,
             const std::vector<CellField>& cell_fields, const std::vector<PointField>& point_fields);
  void write_rows(const std::string& path, const void* data, hid_t type, Rows rows, hsize_t columns);
  hid_t open_file(bool create) const;
  std::string agreed(const std::string& problem) const;
  void publish_xdmf() const;
  void write_xdmf() const;

  std::string base_;
  MPI_Comm comm_;
  bool shared_;  // the file is written by the ranks of comm_ through MPI-IO
  int rank_ = 0, n_ranks_ = 1;
  hid_t file_ = -1;
  std::vector<Step> steps_;
  int n_meshes_ = 0;
  std::uint64_t last_revision_ = 0;
  VertexId last_n_points_ = -1;
  const Mesh* last_mesh_ = nullptr;
  const DistributedMesh* last_part_ = nullptr;
};

}  // namespace snede
