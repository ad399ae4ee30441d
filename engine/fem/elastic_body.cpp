#include "fem/elastic_body.hpp"

#include <petsclog.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "core/counted.hpp"
#include "core/error.hpp"
#include "core/log_event.hpp"

namespace snede {
namespace {

using Vertices = std::array<VertexId, max_dimension + 1>;

template <int D>
Tensor<double, D> gather_differences(std::span<const double> u, const Vertices& v) {
  Tensor<double, D> U;
  for (int j = 1; j <= D; ++j)
    for (int k = 0; k < D; ++k)
      U(k, j - 1) = u[static_cast<std::size_t>(v[j]) * D + k] - u[static_cast<std::size_t>(v[0]) * D + k];
  return U;
}

// Adds columns to nodes 1..D and minus their sum to node 0.
template <int D>
void scatter_columns(std::span<double> out, const Vertices& v, const Tensor<double, D>& G) {
  for (int j = 1; j <= D; ++j)
    for (int k = 0; k < D; ++k) {
      out[static_cast<std::size_t>(v[j]) * D + k] += G(k, j - 1);
      out[static_cast<std::size_t>(v[0]) * D + k] -= G(k, j - 1);
    }
}

// Calls visit(e, oriented vertices, reference) for every live element.
template <int D, class Visit>
void for_each_element(const Connectivity& c, const std::vector<ElementReference<D>>& refs, Visit&& visit) {
  for (ElementId e = 0; e < c.element_capacity(); ++e) {
    if (!c.is_element(e)) continue;
    visit(e, c.element(e).simplex.oriented_vertices(), refs[e]);
  }
}

template <class Function>
decltype(auto) with_material(const Material& material, Function&& function) {
  return std::visit(std::forward<Function>(function), material);
}

template <int D, class M>
KernelFlops count_flops(const M& m) {
  ElementReference<D> ref;
  ref.Z_inv = Tensor<double, D>::Identity();
  ref.measure = 1;
  Tensor<Counted, D> U, dU;
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) {
      U(i, j) = Counted(0.01 * (i + 2 * j + 1));
      dU(i, j) = Counted(0.1 * (2 * i + j + 1));
    }
  KernelFlops flops;
  auto run = [](auto&& kernel) {
    flop_tally() = {};
    kernel();
    return flop_tally();
  };
  flops.energy = run([&] { element_energy<Counted, D>(m, ref, U); }).arithmetic;
  const FlopTally force = run([&] { element_force_columns<Counted, D>(m, ref, U); });
  flops.force = force.arithmetic;
  flops.functions = force.functions;
  flops.tangent = run([&] { element_tangent_columns<Counted, D>(m, ref, U, dU); }).arithmetic;
  return flops;
}

void log_flops(std::int64_t per_element, std::size_t n_elements) {
  SNEDE_PETSC(PetscLogFlops(static_cast<PetscLogDouble>(per_element) * static_cast<PetscLogDouble>(n_elements)));
}

template <class M>
constexpr bool forbids_inversion(const M&) {
  return M::forbids_inversion;
}

}  // namespace

void throw_if_domain_error(const EvaluationReport& report) {
  if (report.domain_errors.empty()) return;
  std::ostringstream message;
  message << report.domain_errors.size() << " element(s) gave a non-finite result (overflow: the deformation is "
          << "too large for this material's nonlinearity, or the values beyond double range), e.g. element";
  for (std::size_t i = 0; i < std::min<std::size_t>(5, report.domain_errors.size()); ++i)
    message << " " << report.domain_errors[i];
  throw DomainError(message.str());
}

ElasticBody::ElasticBody(Mesh& mesh, Material material, double density, double thickness)
    : mesh_(mesh), material_(std::move(material)), density_(density), thickness_(thickness) {
  require_positive("density", density);
  if (mesh.is_surface())
    throw std::invalid_argument("an elastic body needs a volume mesh (triangles in 2D or tetrahedra); membranes on "
                                "surface meshes are not implemented");
  if (mesh.dim() == 2) {
    require_positive("thickness (required for a 2D, plane-stress body)", thickness);
  } else if (thickness != 0) {
    throw std::invalid_argument("thickness is only for 2D (plane-stress) bodies; this mesh is 3D");
  }
  flops_ = with_material(material_, [&](const auto& m) {
    return mesh.dim() == 2 ? count_flops<2>(m) : count_flops<3>(m);
  });
  mesh_.connectivity().add_watcher(this);
}

ElasticBody::~ElasticBody() { mesh_.connectivity().remove_watcher(this); }

template <>
const std::vector<ElementReference<2>>& ElasticBody::references<2>() const {
  return references_2d_;
}
template <>
const std::vector<ElementReference<3>>& ElasticBody::references<3>() const {
  return references_3d_;
}

void ElasticBody::compute_reference(ElementId e) {
  const std::vector<double> x = mesh_.corners(e);  // positively oriented
  auto fill = [&](auto& refs, auto dimension) {
    constexpr int D = decltype(dimension)::value;
    if (refs.size() <= static_cast<std::size_t>(e)) refs.resize(mesh_.connectivity().element_capacity());
    Tensor<double, D> Z;
    for (int j = 1; j <= D; ++j)
      for (int k = 0; k < D; ++k) Z(k, j - 1) = x[j * D + k] - x[k];
    refs[e].Z_inv = Z.inverse();
    refs[e].measure = Z.determinant() / (D == 2 ? 2.0 : 6.0) * (D == 2 ? thickness_ : 1.0);
  };
  if (dim() == 2)
    fill(references_2d_, std::integral_constant<int, 2>{});
  else
    fill(references_3d_, std::integral_constant<int, 3>{});
}

void ElasticBody::init(const Connectivity& connectivity) {
  references_2d_.assign(dim() == 2 ? connectivity.element_capacity() : 0, {});
  references_3d_.assign(dim() == 3 ? connectivity.element_capacity() : 0, {});
  for (ElementId e : connectivity.element_ids()) compute_reference(e);
}

void ElasticBody::on_change(const Connectivity&, const ConnectivityChange& change) {
  // Only the elements that changed get new reference data (§7.4).
  for (ElementId e : change.added_elements) compute_reference(e);
  for (const auto& entry : change.changed_elements) compute_reference(entry.first);
  for (ElementId e : change.reshaped_elements) compute_reference(e);  // a corner moved
}

void ElasticBody::check_size(const char* what, std::span<const double> a) const {
  if (a.size() != n_dofs())
    throw std::invalid_argument(std::string(what) + " has " + std::to_string(a.size()) + " entries, expected " +
                                std::to_string(n_dofs()) + " (n_points × dim)");
}

double ElasticBody::energy(std::span<const double> u, EvaluationReport& report) const {
  static const PetscLogEvent event = log_event("SnedeEnergy");
  ScopedEvent logged(event);
  check_size("displacement", u);
  return with_material(material_, [&](const auto& m) {
    auto loop = [&](auto dimension) {
      constexpr int D = decltype(dimension)::value;
      double total = 0;
      std::size_t n = 0;
      for_each_element<D>(mesh_.connectivity(), references<D>(), [&](ElementId e, const Vertices& v, const auto& ref) {
        const Tensor<double, D> U = gather_differences<D>(u, v);
        if (deformation_gradient<double, D>(ref, U).determinant() <= 0) {
          report.inverted.push_back(e);
          if (forbids_inversion(m)) {
            total = std::numeric_limits<double>::infinity();
            return;
          }
        }
        const double value = element_energy<double, D>(m, ref, U);
        ++n;
        if (!std::isfinite(value)) {
          report.domain_errors.push_back(e);
          return;
        }
        total += value;
      });
      log_flops(flops_.energy, n);
      return total;
    };
    return dim() == 2 ? loop(std::integral_constant<int, 2>{}) : loop(std::integral_constant<int, 3>{});
  });
}

// Adds each element's columns (from `kernel`) into `out`, skipping and reporting inverted
// elements of materials that forbid inversion and non-finite results.
template <class Kernel>
void ElasticBody::accumulate(std::span<const double> u, std::span<double> out, EvaluationReport& report,
                             std::int64_t flops_per_element, Kernel&& kernel) const {
  std::fill(out.begin(), out.end(), 0.0);
  with_material(material_, [&](const auto& m) {
    auto loop = [&](auto dimension) {
      constexpr int D = decltype(dimension)::value;
      std::size_t n = 0;
      for_each_element<D>(mesh_.connectivity(), references<D>(), [&](ElementId e, const Vertices& v, const auto& ref) {
        const Tensor<double, D> U = gather_differences<D>(u, v);
        if (deformation_gradient<double, D>(ref, U).determinant() <= 0) {
          report.inverted.push_back(e);
          if (forbids_inversion(m)) return;
        }
        const Tensor<double, D> G = kernel(m, ref, U, v);
        ++n;
        if (!G.allFinite()) {
          report.domain_errors.push_back(e);
          return;
        }
        scatter_columns<D>(out, v, G);
      });
      log_flops(flops_per_element, n);
    };
    dim() == 2 ? loop(std::integral_constant<int, 2>{}) : loop(std::integral_constant<int, 3>{});
  });
}

void ElasticBody::internal_forces(std::span<const double> u, std::span<double> f, EvaluationReport& report) const {
  static const PetscLogEvent event = log_event("SnedeForces");
  ScopedEvent logged(event);
  check_size("displacement", u);
  check_size("force", f);
  accumulate(u, f, report, flops_.force, [](const auto& m, const auto& ref, const auto& U, const Vertices&) {
    constexpr int D = std::decay_t<decltype(U)>::RowsAtCompileTime;
    return element_force_columns<double, D>(m, ref, U);
  });
}

void ElasticBody::tangent_apply(std::span<const double> u, std::span<const double> d, std::span<double> out,
                                EvaluationReport& report) const {
  static const PetscLogEvent event = log_event("SnedeTangentApply");
  ScopedEvent logged(event);
  check_size("displacement", u);
  check_size("direction", d);
  check_size("result", out);
  accumulate(u, out, report, flops_.tangent, [d](const auto& m, const auto& ref, const auto& U, const Vertices& v) {
    constexpr int D = std::decay_t<decltype(U)>::RowsAtCompileTime;
    return element_tangent_columns<double, D>(m, ref, U, gather_differences<D>(d, v));
  });
}

std::vector<ElementId> ElasticBody::inverted_elements(std::span<const double> u) const {
  check_size("displacement", u);
  std::vector<ElementId> inverted;
  auto loop = [&](auto dimension) {
    constexpr int D = decltype(dimension)::value;
    for_each_element<D>(mesh_.connectivity(), references<D>(), [&](ElementId e, const Vertices& v, const auto& ref) {
      if (deformation_gradient<double, D>(ref, gather_differences<D>(u, v)).determinant() <= 0) inverted.push_back(e);
    });
  };
  dim() == 2 ? loop(std::integral_constant<int, 2>{}) : loop(std::integral_constant<int, 3>{});
  return inverted;
}

std::vector<double> ElasticBody::element_stress(std::span<const double> u) const {
  check_size("displacement", u);
  std::vector<double> stress;
  with_material(material_, [&](const auto& m) {
    auto loop = [&](auto dimension) {
      constexpr int D = decltype(dimension)::value;
      for_each_element<D>(mesh_.connectivity(), references<D>(), [&](ElementId, const Vertices& v, const auto& ref) {
        const Tensor<double, D> S = second_piola<double, D>(m, deformation_gradient<double, D>(ref, gather_differences<D>(u, v)));
        for (int i = 0; i < D; ++i)
          for (int j = 0; j < D; ++j) stress.push_back(S(i, j));
      });
    };
    dim() == 2 ? loop(std::integral_constant<int, 2>{}) : loop(std::integral_constant<int, 3>{});
  });
  return stress;
}

std::vector<double> ElasticBody::element_stiffness(ElementId e, std::span<const double> u) const {
  check_size("displacement", u);
  if (!mesh_.connectivity().is_element(e)) throw std::invalid_argument("element " + std::to_string(e) + " does not exist");
  const Vertices v = mesh_.connectivity().element(e).simplex.oriented_vertices();
  const int n = (dim() + 1) * dim();
  std::vector<double> K(static_cast<std::size_t>(n) * n);
  with_material(material_, [&](const auto& m) {
    auto columns = [&](auto dimension) {
      constexpr int D = decltype(dimension)::value;
      const auto& ref = references<D>()[e];
      const Tensor<double, D> U = gather_differences<D>(u, v);
      for (int column = 0; column < n; ++column) {
        // unit direction on (node column / D, component column % D), as local differences
        Tensor<double, D> dU = Tensor<double, D>::Zero();
        const int node = column / D, component = column % D;
        if (node == 0)
          dU.row(component).setConstant(-1.0);
        else
          dU(component, node - 1) = 1.0;
        const Tensor<double, D> G = element_tangent_columns<double, D>(m, ref, U, dU);
        for (int j = 1; j <= D; ++j)
          for (int k = 0; k < D; ++k) {
            K[static_cast<std::size_t>(j * D + k) * n + column] = G(k, j - 1);
            K[static_cast<std::size_t>(k) * n + column] -= G(k, j - 1);
          }
      }
    };
    dim() == 2 ? columns(std::integral_constant<int, 2>{}) : columns(std::integral_constant<int, 3>{});
  });
  return K;
}

std::vector<double> ElasticBody::lumped_mass() const {
  std::vector<double> mass(mesh_.n_points(), 0.0);
  auto loop = [&](auto dimension) {
    constexpr int D = decltype(dimension)::value;
    for_each_element<D>(mesh_.connectivity(), references<D>(), [&](ElementId, const Vertices& v, const auto& ref) {
      for (int j = 0; j <= D; ++j) mass[v[j]] += density_ * ref.measure / (D + 1);
    });
  };
  dim() == 2 ? loop(std::integral_constant<int, 2>{}) : loop(std::integral_constant<int, 3>{});
  return mass;
}

std::vector<double> ElasticBody::gravity_forces(std::span<const double> g) const {
  if (g.size() != static_cast<std::size_t>(dim()))
    throw std::invalid_argument("gravity must have " + std::to_string(dim()) + " components");
  const std::vector<double> mass = lumped_mass();
  std::vector<double> f(n_dofs());
  for (std::size_t v = 0; v < mass.size(); ++v)
    for (int k = 0; k < dim(); ++k) f[v * dim() + k] = mass[v] * g[k];
  return f;
}

}  // namespace snede
