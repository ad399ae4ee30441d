#include "fem/membrane_loops.hpp"

#include <cmath>
#include <limits>

#include "fem/local_dofs.hpp"

namespace snede {
namespace {

using Vertices = MembraneElements::Vertices;

bool is_finite(double value) { return std::isfinite(value); }
bool is_finite(const MembraneColumns<double>& G) { return G.allFinite(); }

// Calls keep(vertices, result) with result = kernel(reference, U, vertices) for every live
// element that counts (the reporting rules of membrane_loops.hpp); U is gathered from u, and
// collapse checked, only if reads_state. Returns how many elements were evaluated.
template <class Kernel, class Keep>
std::size_t evaluate_counted(const MembraneElements& elements, bool reads_state, bool forbids_inversion,
                             std::span<const double> u, EvaluationReport& report, Kernel&& kernel, Keep&& keep) {
  std::size_t n_evaluated = 0;
  elements.for_each_live([&](ElementId e, const Vertices& v, const MembraneReference& ref) {
    MembraneColumns<double> U = MembraneColumns<double>::Zero();
    if (reads_state) {
      U = gather_differences<3>(u, v);
      if (membrane_collapsed(ref, U)) {
        report.inverted.push_back(e);
        if (forbids_inversion) return;
      }
    }
    ++n_evaluated;
    const auto result = kernel(ref, U, v);
    if (!is_finite(result)) {
      report.domain_errors.push_back(e);
      return;
    }
    keep(v, result);
  });
  return n_evaluated;
}

// Adds columns G to corners 1, 2 and minus their sum to corner 0.
void scatter_columns(std::span<double> out, const Vertices& v, const MembraneColumns<double>& G) {
  for (int k = 0; k < 3; ++k) {
    out[static_cast<std::size_t>(v[0]) * 3 + k] -= G(k, 0) + G(k, 1);
    for (int j = 1; j <= 2; ++j) out[static_cast<std::size_t>(v[j]) * 3 + k] += G(k, j - 1);
  }
}

template <class Kernel>
std::size_t accumulate(const MembraneElements& elements, bool reads_state, bool forbids_inversion,
                       std::span<const double> u, std::span<double> out, EvaluationReport& report, Kernel&& kernel) {
  std::fill(out.begin(), out.end(), 0.0);
  return evaluate_counted(elements, reads_state, forbids_inversion, u, report, kernel,
                          [&](const Vertices& v, const MembraneColumns<double>& G) { scatter_columns(out, v, G); });
}

template <class M>
void fill_stiffness(const M& m, const MembraneReference& ref, const MembraneColumns<double>& U, std::span<double> K) {
  for (int column = 0; column < 9; ++column)
    store_stiffness_column(membrane_tangent_columns<double>(m, ref, U, unit_differences<double, 3, 2>(column)), column, K);
}

}  // namespace

double membrane_energy(const MembraneElements& elements, const Material& material, std::span<const double> u,
                       EvaluationReport& report, std::size_t& n_evaluated) {
  return std::visit(
      [&](const auto& m) {
        double total = 0;
        const std::size_t n_collapsed = report.inverted.size();
        n_evaluated += evaluate_counted(
            elements, true, m.forbids_inversion, u, report,
            [&](const MembraneReference& ref, const MembraneColumns<double>& U, const Vertices&) {
              return membrane_energy<double>(m, ref, U);
            },
            [&](const Vertices&, double value) { total += value; });
        // +∞ for a collapsed element of a material that forbids inversion.
        if (m.forbids_inversion && report.inverted.size() > n_collapsed) return std::numeric_limits<double>::infinity();
        return total;
      },
      material);
}

std::size_t membrane_internal_forces(const MembraneElements& elements, const Material& material,
                                     std::span<const double> u, std::span<double> f, EvaluationReport& report) {
  return std::visit(
      [&](const auto& m) {
        return accumulate(elements, true, m.forbids_inversion, u, f, report,
                          [&](const MembraneReference& ref, const MembraneColumns<double>& U, const Vertices&) {
                            return membrane_force_columns<double>(m, ref, U);
                          });
      },
      material);
}

std::size_t membrane_tangent_apply(const MembraneElements& elements, const Material& material,
                                   std::span<const double> u, std::span<const double> d, std::span<double> out,
                                   EvaluationReport& report) {
  return std::visit(
      [&](const auto& m) {
        constexpr bool reads_state = !is_linear_elastic<std::decay_t<decltype(m)>>;
        return accumulate(elements, reads_state, m.forbids_inversion, u, out, report,
                          [&](const MembraneReference& ref, const MembraneColumns<double>& U, const Vertices& v) {
                            return membrane_tangent_columns<double>(m, ref, U, gather_differences<3>(d, v));
                          });
      },
      material);
}

std::vector<ElementId> membrane_collapsed_elements(const MembraneElements& elements, std::span<const double> u) {
  std::vector<ElementId> collapsed;
  elements.for_each_live([&](ElementId e, const Vertices& v, const MembraneReference& ref) {
    if (membrane_collapsed(ref, gather_differences<3>(u, v))) collapsed.push_back(e);
  });
  return collapsed;
}

std::vector<double> membrane_element_stress(const MembraneElements& elements, const Material& material,
                                            std::span<const double> u) {
  std::vector<double> stress;
  std::visit(
      [&](const auto& m) {
        elements.for_each_live([&](ElementId, const Vertices& v, const MembraneReference& ref) {
          const Tensor<double, 2> S = membrane_stress<double>(m, ref, gather_differences<3>(u, v));
          for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) stress.push_back(S(i, j));
        });
      },
      material);
  return stress;
}

std::vector<double> membrane_element_stiffness(const MembraneElements& elements, const Material& material,
                                               ElementId e, std::span<const double> u) {
  std::vector<double> K(81);
  std::visit([&](const auto& m) { fill_stiffness(m, elements.reference(e), gather_differences<3>(u, elements.vertices(e)), K); },
             material);
  return K;
}

void membrane_for_each_element_stiffness(
    const MembraneElements& elements, const Material& material, std::span<const double> u,
    const std::function<void(ElementId, std::span<const VertexId>, std::span<const double>)>& visit,
    const std::vector<ElementId>* only) {
  std::array<double, 81> K;
  std::visit(
      [&](const auto& m) {
        auto visit_element = [&](ElementId e, const Vertices& v, const MembraneReference& ref) {
          const MembraneColumns<double> U = gather_differences<3>(u, v);
          if (m.forbids_inversion && membrane_collapsed(ref, U)) return;
          fill_stiffness(m, ref, U, K);
          visit(e, std::span<const VertexId>(v), std::span<const double>(K));
        };
        if (!only) return elements.for_each_live(visit_element);
        for (ElementId e : *only) visit_element(e, elements.vertices(e), elements.reference(e));
      },
      material);
}

KernelFlops membrane_kernel_flops(const Material& material) {
  return std::visit(
      [](const auto& m) {
        MembraneReference ref;  // the unit frame in the xy plane, Z⁻¹ = I
        ref.measure = 1;
        const auto differences = flop_count_differences<3, 2>();
        const auto &U = differences[0], &dU = differences[1];
        return count_kernel_flops([&] { membrane_energy<Counted>(m, ref, U); },
                                  [&] { membrane_force_columns<Counted>(m, ref, U); },
                                  [&] { membrane_tangent_columns<Counted>(m, ref, U, dU); });
      },
      material);
}

}  // namespace snede
