// Time series for ParaView: one HDF5 file with the heavy data and an XDMF file describing
// it. A mesh is written again only when the connectivity or the number of points changed
// since the last step, so a simulation whose topology changes (cuts, bisection) gives a
// series in which each step points to the mesh it had.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace snede {

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
  // Writes `<base>.h5` and `<base>.xdmf` (overwriting them).
  explicit XdmfWriter(std::string base);
  ~XdmfWriter();
  XdmfWriter(const XdmfWriter&) = delete;
  XdmfWriter& operator=(const XdmfWriter&) = delete;

  // displacement: (n_points, dim); written as 3-component vectors (z = 0 in 2D).
  // Field names must be distinct and not "displacement".
  void write_step(double time, const Mesh& mesh, std::span<const double> displacement,
                  const std::vector<CellField>& cell_fields, const std::vector<PointField>& point_fields = {});
  int n_steps() const { return static_cast<int>(steps_.size()); }
  int n_meshes() const { return n_meshes_; }
  std::string xdmf_path() const { return base_ + ".xdmf"; }
  std::string h5_path() const { return base_ + ".h5"; }

 private:
  struct Step {
    double time;
    int mesh;
    std::int64_t n_points, n_cells;
    int cell_dim;  // 2: triangles (2D or a surface), 3: tetrahedra
    std::vector<std::string> fields;        // cell fields
    std::vector<std::string> point_fields;
  };
  void write_dataset(const std::string& path, const void* data, hid_t type, hsize_t rows, hsize_t columns);
  void write_xdmf() const;

  std::string base_;
  hid_t file_ = -1;
  std::vector<Step> steps_;
  int n_meshes_ = 0;
  std::uint64_t last_revision_ = 0;
  VertexId last_n_points_ = -1;
  const Mesh* last_mesh_ = nullptr;
};

}  // namespace snede
