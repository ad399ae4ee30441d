#include "cutting/cut_thresholds.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/error.hpp"

namespace snede {

CutThresholds resolved_thresholds(const char* cutter, const Mesh& mesh, CutThresholds given) {
  for (const auto& [name, value] : {std::pair{"eps_edge", given.eps_edge}, std::pair{"eps_entry", given.eps_entry},
                                    std::pair{"eps_exit", given.eps_exit}})
    require(value >= 0 && std::isfinite(value), std::string(cutter) + ": " + name, "finite and positive (0: the default)",
            value);
  double total = 0;
  std::size_t edges = 0;
  const Connectivity& c = mesh.connectivity();
  for (FaceId f = 0; f < c.face_capacity(); ++f) {
    if (!c.is_face(f) || (c.face(f).mate != no_id && c.face(f).mate < f)) continue;  // each edge once
    const auto a = mesh.point(c.face(f).simplex.vertex(0)), b = mesh.point(c.face(f).simplex.vertex(1));
    double squared = 0;
    for (std::size_t k = 0; k < a.size(); ++k) squared += (a[k] - b[k]) * (a[k] - b[k]);
    total += std::sqrt(squared);
    ++edges;
  }
  if (edges == 0) throw std::invalid_argument(std::string(cutter) + ": the mesh has no edges");
  const double mean = total / static_cast<double>(edges);
  if (given.eps_edge == 0) given.eps_edge = mean / 3;
  if (given.eps_entry == 0) given.eps_entry = mean / 6;
  if (given.eps_exit == 0) given.eps_exit = mean / 6;
  return given;
}

}  // namespace snede
