// The distances of Delaunay cutting (§5.4), shared by the 2D and the surface cutter: ε_edge
// (nodes closer to the active node are removed), ε_entry (an incision starts that far inside)
// and ε_exit, in the reference configuration.
#pragma once

#include "mesh/mesh.hpp"

namespace snede {

struct CutThresholds {
  double eps_edge = 0;
  double eps_entry = 0;
  double eps_exit = 0;

  // Every setting with its name: the one list that bindings read (snede.SurfaceCutterOptions).
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("eps_edge", &CutThresholds::eps_edge);
    visit("eps_entry", &CutThresholds::eps_entry);
    visit("eps_exit", &CutThresholds::eps_exit);
  }
};

// `given` checked (finite and ≥ 0; the message names `cutter`), with every 0 replaced by the
// thesis's default from the mean edge length h̄ of the triangle mesh: ε_edge = h̄/3,
// ε_entry = ε_exit = h̄/6. Throws std::invalid_argument for a bad value or a mesh without edges.
CutThresholds resolved_thresholds(const char* cutter, const Mesh& mesh, CutThresholds given);

}  // namespace snede
