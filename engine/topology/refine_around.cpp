#include "topology/refine_around.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace snede {
namespace {

std::string point_text(std::span<const double> x) {
  std::ostringstream text;
  text << "(";
  for (std::size_t k = 0; k < x.size(); ++k) text << (k ? ", " : "") << x[k];
  text << ")";
  return text.str();
}

}  // namespace

std::size_t refine_around(Bisection& bisection, std::span<const double> x, double h) {
  const Mesh& mesh = bisection.mesh();
  if (!(std::isfinite(h) && h > 0))
    throw std::invalid_argument("refine_around: h must be positive and finite, got " + std::to_string(h));
  if (x.size() != static_cast<std::size_t>(mesh.dim()))
    throw std::invalid_argument("refine_around: the point has " + std::to_string(x.size()) +
                                " coordinates, the mesh is " + std::to_string(mesh.dim()) + "-D");
  // The roots containing x do not change while refining: find them once.
  const std::vector<NodeId> roots = bisection.hierarchy().roots_containing(x);
  if (roots.empty()) throw std::invalid_argument("refine_around: point " + point_text(x) + " is outside the mesh");
  bool size_checked = false;
  ChangeBatch batch(bisection.mesh().connectivity());  // one change for the watchers (§7.4)
  std::size_t n_split = 0;
  for (;;) {
    ElementId too_long = no_id;
    for (ElementId e : bisection.hierarchy().locate_all(x, roots)) {
      const double longest = longest_edge(mesh.dim(), mesh.corners(e));
      if (!size_checked && h < 1e-12 * longest) {
        std::ostringstream message;
        message << "refine_around: h = " << h << " is below round-off for edges of " << longest << " at "
                << point_text(x);
        throw std::invalid_argument(message.str());
      }
      size_checked = true;
      if (longest > h) {
        too_long = e;
        break;
      }
    }
    if (too_long == no_id) return n_split;
    n_split += bisection.bisect(too_long);
  }
}

}  // namespace snede
