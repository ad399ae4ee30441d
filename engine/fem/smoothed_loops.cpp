#include "fem/smoothed_loops.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fem/constitutive.hpp"
#include "fem/linear_elastic.hpp"

namespace snede {
namespace {

template <class M>
M with_lame(M m, double mu, double lambda) {
  m.lame = Lame{lambda, mu};
  return m;
}

// The material each patch family evaluates (see the header).
template <int D, class M>
struct Parts {
  M edge, vertex;
  static constexpr bool has_vertex_part = D == 3;
};
template <int D, class M>
Parts<D, M> split(const M& m) {
  if constexpr (D == 3)
    return {with_lame(m, m.lame.mu, 0.0), with_lame(m, 0.0, m.lame.lambda)};
  else
    return {m, m};
}

template <int D>
using Entries = std::array<double, D * D>;

// H̃ per patch (D·D entries each, row-major) from a nodal array.
template <int D>
struct PatchGradients {
  std::vector<double> edge, vertex;
  std::vector<double> element;  // scratch: every element slot's |e| H_e
};

// The tensors of patches k0 … k0 + batch_width − 1 side by side (the last one repeated past n).
template <int D>
Tensor<Batch, D> load_patches(std::span<const double> entries, std::size_t k0, std::size_t n) {
  std::array<const double*, batch_width> rows;
  for (int lane = 0; lane < batch_width; ++lane) rows[lane] = entries.data() + std::min(k0 + lane, n - 1) * D * D;
  Tensor<Batch, D> t;
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) t(i, j) = Batch::from_lanes([&](int lane) { return rows[lane][i * D + j]; });
  return t;
}

template <int D>
Tensor<double, D> tensor_at(std::span<const double> entries, std::size_t k) {
  Tensor<double, D> t;
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) t(i, j) = entries[k * D * D + i * D + j];
  return t;
}

// Pass 1 into `sums` (its vectors reused from call to call: no allocation once warm). Appends
// the live elements with det(I + H_e) ≤ 0 to `inverted` if given. First every element's |e| H_e,
// stored in element order (the block loop, flattened as the P1 loops are: fem/elastic_body.cpp),
// then each patch gathers its elements' (fem/strain_patches.hpp's lists): adding into the
// patches element by element instead was a chain of scalar read-modify-writes scattered over
// the patch arrays, 44 % of a smoothed tangent product's time.
template <int D>
[[gnu::flatten]] void average_gradients(const ElementStream<D>& stream, const StrainPatches<D>& patches, bool vertex_part,
                                        std::span<const double> nodal, std::vector<ElementId>* inverted,
                                        PatchGradients<D>& sums) {
  using Patches = StrainPatches<D>;
  std::vector<double>& weighted = sums.element;
  weighted.resize(static_cast<std::size_t>(stream.capacity()) * D * D);
  const std::span<const ElementBlock<D>> blocks = stream.blocks();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    prefetch_ahead<D>(blocks, b);
    const ElementBlock<D>& block = blocks[b];
    const LaneMask live = ElementStream<D>::live_lanes(block);
    const Tensor<Batch, D> H = gather_differences<D>(nodal, block) * block.reference.Z_inv;
    if (inverted) {
      const LaneMask flat = live & non_positive_lanes((identity<Batch, D>() + H).determinant());
      for (int lane = 0; lane < batch_width; ++lane)
        if (flat >> lane & 1) inverted->push_back(static_cast<ElementId>(b * batch_width + lane));
    }
    const Tensor<Batch, D> scaled = block.reference.measure * H;  // a free slot's measure is 0
    double* out = weighted.data() + b * batch_width * D * D;
    for (int lane = 0; lane < batch_width; ++lane)
      for (int i = 0; i < D; ++i)
        for (int j = 0; j < D; ++j) out[(lane * D + i) * D + j] = scaled(i, j)[lane];
  }
  auto gather = [&](std::vector<double>& entries, std::size_t n, std::span<const double> measure, double share,
                    auto&& elements_of) {
    entries.resize(n * D * D);
    for (std::size_t k = 0; k < n; ++k) {
      Entries<D> sum{};
      for (ElementId e : elements_of(k)) {
        const double* h = weighted.data() + static_cast<std::size_t>(e) * D * D;
        for (int m = 0; m < D * D; ++m) sum[m] += h[m];
      }
      const double scale = measure[k] > 0 ? share / measure[k] : 0.0;
      for (int m = 0; m < D * D; ++m) entries[k * D * D + m] = scale * sum[m];
    }
  };
  gather(sums.edge, patches.n_edges(), patches.edge_measure(), Patches::edge_share,
         [&](std::size_t k) { return patches.edge_elements(k); });
  if (vertex_part)
    gather(sums.vertex, patches.n_vertices(), patches.vertex_measure(), Patches::vertex_share,
           [&](std::size_t v) { return patches.vertex_elements(static_cast<VertexId>(v)); });
}

// Scratch arrays kept per thread between calls (the loops run once per CG iteration), and the
// patch gradients of the last state a tangent was applied at: a Krylov solve applies the
// tangent at one u many times, and an exact comparison of u (a copy, memcmp) is cheaper than
// averaging it again.
template <int D>
struct Workspace {
  PatchGradients<D> H, dH;
  std::array<std::vector<double>, 2> tensors;
  PatchGradients<D> tangent_H;
  std::vector<double> tangent_u;
  std::vector<ElementId> tangent_inverted;
  std::uint64_t tangent_generation = 0;
};
template <int D>
Workspace<D>& workspace() {
  thread_local Workspace<D> w;
  return w;
}

// Pass 2 over one patch family: out[k] = kernel(F̃_k as a batch, H̃_k, …) for batch_width patches
// per call. Patches of zero measure (vertices no element uses) give 0. A patch with det F̃ ≤ 0
// under a material that forbids inversion, or with a non-finite result, gives 0 and its first
// element is reported.
template <int D, class M, class FirstElement, class Kernel>
[[gnu::flatten]] void evaluate_patches(const M&, std::span<const double> H, std::span<const double> measure,
                                       const FirstElement& first_element, std::vector<double>& out,
                                       EvaluationReport& report, const Kernel& kernel) {
  const std::size_t n = measure.size();
  out.assign(n * D * D, 0.0);
  for (std::size_t k0 = 0; k0 < n; k0 += batch_width) {
    const Tensor<Batch, D> Hb = load_patches<D>(H, k0, n);
    const Tensor<Batch, D> R = kernel(Hb, k0);
    const LaneMask inverted = M::forbids_inversion ? non_positive_lanes((identity<Batch, D>() + Hb).determinant()) : 0;
    const LaneMask finite = finite_lanes(R);
    for (int lane = 0; lane < batch_width && k0 + lane < n; ++lane) {
      const std::size_t k = k0 + lane;
      if (!(measure[k] > 0)) continue;
      if (inverted >> lane & 1) {
        report.inverted.push_back(first_element(k));
        continue;
      }
      if (!(finite >> lane & 1)) {
        report.domain_errors.push_back(first_element(k));
        continue;
      }
      for (int i = 0; i < D; ++i)
        for (int j = 0; j < D; ++j) out[k * D * D + i * D + j] = R(i, j)[lane];
    }
  }
}

// Pass 3: out += sign · |e| P_e Z⁻ᵀ as node columns, P_e = Σ shares of the patch tensors.
template <int D>
[[gnu::flatten]] void scatter_to_nodes(const ElementStream<D>& stream, const StrainPatches<D>& patches, std::span<const double> edge,
                      std::span<const double> vertex, double sign, std::span<double> out) {
  using Patches = StrainPatches<D>;
  std::fill(out.begin(), out.end(), 0.0);
  const std::span<const ElementBlock<D>> blocks = stream.blocks();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    prefetch_ahead<D>(blocks, b);
    const ElementBlock<D>& block = blocks[b];
    const LaneMask live = ElementStream<D>::live_lanes(block);
    if (!live) continue;
    std::array<Entries<D>, batch_width> P{};
    for (int lane = 0; lane < batch_width; ++lane) {
      if (!(live >> lane & 1)) continue;
      const ElementId e = static_cast<ElementId>(b * batch_width + lane);
      for (std::int32_t k : patches.element_edges(e)) {
        const double* t = edge.data() + static_cast<std::size_t>(k) * D * D;
        for (int m = 0; m < D * D; ++m) P[lane][m] += Patches::edge_share * t[m];
      }
      if (!vertex.empty())
        for (int a = 0; a <= D; ++a) {
          const double* t = vertex.data() + static_cast<std::size_t>(block.rows[a][lane] / D) * D * D;
          for (int m = 0; m < D * D; ++m) P[lane][m] += Patches::vertex_share * t[m];
        }
    }
    Tensor<Batch, D> Pb;
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) Pb(i, j) = Batch::from_lanes([&](int lane) { return P[lane][i * D + j]; });
    const Tensor<Batch, D> G = (Batch(sign) * block.reference.measure) * Pb * block.reference.Z_inv.transpose();
    scatter_columns<D>(out, block, G, live);
  }
}

template <int D, class M>
Tensor<Batch, D> patch_stress(const M& m, const Tensor<Batch, D>& H) {
  if constexpr (is_linear_elastic<M>)
    return m.template stress_of_gradient<Batch, D>(H);
  else
    return first_piola<Batch, D>(m, Tensor<Batch, D>(identity<Batch, D>() + H));
}

template <int D, class M>
Tensor<Batch, D> patch_stress_derivative(const M& m, const Tensor<Batch, D>& H, const Tensor<Batch, D>& dH) {
  if constexpr (is_linear_elastic<M>)
    return m.template stress_of_gradient<Batch, D>(dH);
  else
    return first_piola_derivative<Batch, D>(m, Tensor<Batch, D>(identity<Batch, D>() + H), dH);
}

// A patch's first element, for reports.
template <int D>
auto first_of_edge(const StrainPatches<D>& patches) {
  return [&patches](std::size_t k) { return patches.edge_elements(k).front(); };
}
template <int D>
auto first_of_vertex(const StrainPatches<D>& patches) {
  return [&patches](std::size_t v) { return patches.vertex_elements(static_cast<VertexId>(v)).front(); };
}

// The tensors of both patch families into `tensors`: per-patch kernel(part material, H̃ batch,
// family, first patch).
template <int D, class M, class Kernel>
std::array<std::vector<double>, 2>& evaluate_both(const Parts<D, M>& parts, const StrainPatches<D>& patches,
                                                  const PatchGradients<D>& H, EvaluationReport& report,
                                                  std::array<std::vector<double>, 2>& tensors, const Kernel& kernel) {
  evaluate_patches<D>(parts.edge, H.edge, patches.edge_measure(), first_of_edge(patches), tensors[0], report,
                      [&](const Tensor<Batch, D>& Hb, std::size_t k0) { return kernel(parts.edge, Hb, 0, k0); });
  if (Parts<D, M>::has_vertex_part)
    evaluate_patches<D>(parts.vertex, H.vertex, patches.vertex_measure(), first_of_vertex(patches), tensors[1], report,
                        [&](const Tensor<Batch, D>& Hb, std::size_t k0) { return kernel(parts.vertex, Hb, 1, k0); });
  else
    tensors[1].clear();
  return tensors;
}

// Each element once in each list: an element heads or belongs to several patches.
void keep_each_element_once(EvaluationReport& report) {
  for (std::vector<ElementId>* list : {&report.inverted, &report.domain_errors}) {
    std::sort(list->begin(), list->end());
    list->erase(std::unique(list->begin(), list->end()), list->end());
  }
}

template <class Function>
decltype(auto) with_material(const Material& material, Function&& function) {
  return std::visit([&](const auto& m) { return function(m); }, material);
}

}  // namespace

template <int D>
double smoothed_energy(const ElementStream<D>& stream, const StrainPatches<D>& patches, const Material& material,
                       std::span<const double> u, EvaluationReport& report) {
  return with_material(material, [&](const auto& m) {
    using M = std::decay_t<decltype(m)>;
    const Parts<D, M> parts = split<D>(m);
    std::vector<ElementId> inverted;
    PatchGradients<D>& H = workspace<D>().H;
    average_gradients<D>(stream, patches, parts.has_vertex_part, u, &inverted, H);
    report.inverted.insert(report.inverted.end(), inverted.begin(), inverted.end());
    double total = 0;
    bool infinite = M::forbids_inversion && !inverted.empty();
    auto family = [&](const M& part, std::span<const double> Hk, std::span<const double> measure, const auto& first) {
      for (std::size_t k = 0; k < measure.size(); ++k) {
        if (!(measure[k] > 0)) continue;
        const Tensor<double, D> Hd = tensor_at<D>(Hk, k);
        double w;
        if constexpr (is_linear_elastic<M>) {
          w = part.template energy_of_gradient<double, D>(Hd);
        } else {
          const Tensor<double, D> F = identity<double, D>() + Hd;
          if (M::forbids_inversion && F.determinant() <= 0) {
            report.inverted.push_back(first(k));
            infinite = true;
            continue;
          }
          w = energy_density<double, D>(part, F);
        }
        if (!std::isfinite(w)) {
          report.domain_errors.push_back(first(k));
          continue;
        }
        total += measure[k] * w;
      }
    };
    family(parts.edge, H.edge, patches.edge_measure(), first_of_edge(patches));
    if (parts.has_vertex_part) family(parts.vertex, H.vertex, patches.vertex_measure(), first_of_vertex(patches));
    keep_each_element_once(report);
    return infinite ? std::numeric_limits<double>::infinity() : total;
  });
}

template <int D>
void smoothed_internal_forces(const ElementStream<D>& stream, const StrainPatches<D>& patches, const Material& material,
                              std::span<const double> u, std::span<double> f, EvaluationReport& report) {
  with_material(material, [&](const auto& m) {
    using M = std::decay_t<decltype(m)>;
    const Parts<D, M> parts = split<D>(m);
    Workspace<D>& w = workspace<D>();
    average_gradients<D>(stream, patches, parts.has_vertex_part, u, &report.inverted, w.H);
    const auto& P = evaluate_both<D>(parts, patches, w.H, report, w.tensors, [](const M& part, const Tensor<Batch, D>& Hb, int, std::size_t) {
      return patch_stress<D>(part, Hb);
    });
    scatter_to_nodes<D>(stream, patches, P[0], P[1], -1.0, f);
    keep_each_element_once(report);
  });
}

template <int D>
void smoothed_tangent_apply(const ElementStream<D>& stream, const StrainPatches<D>& patches, const Material& material,
                            std::span<const double> u, std::span<const double> d, std::span<double> out,
                            EvaluationReport& report) {
  with_material(material, [&](const auto& m) {
    using M = std::decay_t<decltype(m)>;
    const Parts<D, M> parts = split<D>(m);
    Workspace<D>& w = workspace<D>();
    average_gradients<D>(stream, patches, parts.has_vertex_part, d, nullptr, w.dH);
    if constexpr (!is_linear_elastic<M>) {
      const bool same_state = w.tangent_generation == patches.generation() && w.tangent_u.size() == u.size() &&
                              std::equal(u.begin(), u.end(), w.tangent_u.begin());
      if (!same_state) {
        w.tangent_inverted.clear();
        average_gradients<D>(stream, patches, parts.has_vertex_part, u, &w.tangent_inverted, w.tangent_H);
        w.tangent_u.assign(u.begin(), u.end());
        w.tangent_generation = patches.generation();
      }
      report.inverted.insert(report.inverted.end(), w.tangent_inverted.begin(), w.tangent_inverted.end());
    }
    const std::array<const std::vector<double>*, 2> directions{&w.dH.edge, &w.dH.vertex};
    const PatchGradients<D>& at = is_linear_elastic<M> ? w.dH : w.tangent_H;
    const auto& dP = evaluate_both<D>(parts, patches, at, report, w.tensors, [&](const M& part, const Tensor<Batch, D>& Hb, int family, std::size_t k0) {
      const std::vector<double>& direction = *directions[family];
      return patch_stress_derivative<D>(part, Hb, load_patches<D>(direction, k0, direction.size() / (D * D)));
    });
    scatter_to_nodes<D>(stream, patches, dP[0], dP[1], 1.0, out);
    keep_each_element_once(report);
  });
}

template <int D>
std::vector<double> smoothed_element_stress(const ElementStream<D>& stream, const StrainPatches<D>& patches,
                                            const Material& material, std::span<const double> u) {
  using Patches = StrainPatches<D>;
  return with_material(material, [&](const auto& m) {
    using M = std::decay_t<decltype(m)>;
    const Parts<D, M> parts = split<D>(m);
    Workspace<D>& w = workspace<D>();
    average_gradients<D>(stream, patches, parts.has_vertex_part, u, nullptr, w.H);
    EvaluationReport ignored;
    const auto& S = evaluate_both<D>(parts, patches, w.H, ignored, w.tensors, [](const M& part, const Tensor<Batch, D>& Hb, int, std::size_t) {
      if constexpr (is_linear_elastic<M>)
        return part.template stress_of_gradient<Batch, D>(Hb);
      else
        return second_piola<Batch, D>(part, Tensor<Batch, D>(identity<Batch, D>() + Hb));
    });
    std::vector<double> stress;
    for (ElementId e = 0; e < stream.capacity(); ++e) {
      if (!stream.is_live(e)) continue;
      Entries<D> sum{};
      for (std::int32_t k : patches.element_edges(e))
        for (int i = 0; i < D * D; ++i) sum[i] += Patches::edge_share * S[0][static_cast<std::size_t>(k) * D * D + i];
      if (parts.has_vertex_part)
        for (VertexId v : stream.vertices(e))
          for (int i = 0; i < D * D; ++i) sum[i] += Patches::vertex_share * S[1][static_cast<std::size_t>(v) * D * D + i];
      stress.insert(stress.end(), sum.begin(), sum.end());
    }
    return stress;
  });
}

template <int D>
void smoothed_for_each_patch_stiffness(const ElementStream<D>& stream, const StrainPatches<D>& patches,
                                       const Material& material, std::span<const double> u,
                                       const PatchStiffnessVisitor& visit) {
  using Patches = StrainPatches<D>;
  with_material(material, [&](const auto& m) {
    using M = std::decay_t<decltype(m)>;
    const Parts<D, M> parts = split<D>(m);
    PatchGradients<D>& H = workspace<D>().H;
    average_gradients<D>(stream, patches, parts.has_vertex_part, u, nullptr, H);
    std::vector<VertexId> nodes;
    std::vector<Eigen::Matrix<double, D, 1>> b;  // ∂F̃/∂u_node = e_r ⊗ b_node
    std::vector<double> K;
    std::vector<Eigen::Matrix<double, D * D, D>> T;
    // One patch: its nodes (sorted), their smoothed shape gradients, then K column by column.
    auto patch = [&](const M& part, std::span<const ElementId> elements, double share, double measure,
                     const Tensor<double, D>& Hk) {
      if (!(measure > 0) || elements.empty()) return;
      const Tensor<double, D> F = identity<double, D>() + Hk;
      if (M::forbids_inversion && F.determinant() <= 0) return;
      nodes.clear();
      for (ElementId e : elements)
        for (VertexId v : stream.vertices(e)) nodes.push_back(v);
      std::sort(nodes.begin(), nodes.end());
      nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
      b.assign(nodes.size(), Eigen::Matrix<double, D, 1>::Zero());
      for (ElementId e : elements) {
        const ElementReference<D> ref = stream.reference(e);
        const auto vertices = stream.vertices(e);
        const double weight = share * ref.measure / measure;
        Eigen::Matrix<double, D, 1> corner0 = Eigen::Matrix<double, D, 1>::Zero();
        for (int j = 1; j <= D; ++j) {
          const Eigen::Matrix<double, D, 1> gradient = ref.Z_inv.row(j - 1).transpose();
          corner0 -= gradient;
          b[std::lower_bound(nodes.begin(), nodes.end(), vertices[j]) - nodes.begin()] += weight * gradient;
        }
        b[std::lower_bound(nodes.begin(), nodes.end(), vertices[0]) - nodes.begin()] += weight * corner0;
      }
      // The material's tangent A[(r, c), (s, d)] = ∂P_rc/∂F_sd at F̃, D² derivatives once per
      // patch from one FirstPiolaTangent; then T_b[(r, c), s] = Σ_d A[(r, c), (s, d)] b_b[d] per
      // node and K[(a, r), (b, s)] = |k| Σ_c b_a[c] T_b[(r, c), s] per pair (not one derivative
      // per column).
      const FirstPiolaTangent<double, D, M, D> dP_of(part, F);
      Eigen::Matrix<double, D * D, D * D> A;
      for (int sd = 0; sd < D * D; ++sd) {
        Tensor<double, D> dF = Tensor<double, D>::Zero();
        dF(sd / D, sd % D) = 1;
        const Tensor<double, D> dP = dP_of(dF);
        for (int rc = 0; rc < D * D; ++rc) A(rc, sd) = dP(rc / D, rc % D);
      }
      const int count = static_cast<int>(nodes.size()), n = count * D;
      T.resize(nodes.size());
      for (int node = 0; node < count; ++node)
        for (int rc = 0; rc < D * D; ++rc)
          for (int s = 0; s < D; ++s) {
            double sum = 0;
            for (int d = 0; d < D; ++d) sum += A(rc, s * D + d) * b[node][d];
            T[node](rc, s) = measure * sum;
          }
      K.resize(static_cast<std::size_t>(n) * n);
      for (int a = 0; a < count; ++a)
        for (int c = 0; c < count; ++c)
          for (int r = 0; r < D; ++r)
            for (int s = 0; s < D; ++s) {
              double sum = 0;
              for (int q = 0; q < D; ++q) sum += b[a][q] * T[c](r * D + q, s);
              K[static_cast<std::size_t>(a * D + r) * n + c * D + s] = sum;
            }
      visit(elements.front(), nodes, K);
    };
    for (std::size_t k = 0; k < patches.n_edges(); ++k)
      patch(parts.edge, patches.edge_elements(k), Patches::edge_share, patches.edge_measure()[k], tensor_at<D>(H.edge, k));
    if (parts.has_vertex_part)
      for (VertexId v = 0; v < static_cast<VertexId>(patches.n_vertices()); ++v)
        patch(parts.vertex, patches.vertex_elements(v), Patches::vertex_share, patches.vertex_measure()[v],
              tensor_at<D>(H.vertex, v));
  });
}

#define SNEDE_SMOOTHED_LOOPS(D)                                                                                      \
  template double smoothed_energy<D>(const ElementStream<D>&, const StrainPatches<D>&, const Material&,             \
                                     std::span<const double>, EvaluationReport&);                                   \
  template void smoothed_internal_forces<D>(const ElementStream<D>&, const StrainPatches<D>&, const Material&,      \
                                            std::span<const double>, std::span<double>, EvaluationReport&);         \
  template void smoothed_tangent_apply<D>(const ElementStream<D>&, const StrainPatches<D>&, const Material&,        \
                                          std::span<const double>, std::span<const double>, std::span<double>,      \
                                          EvaluationReport&);                                                       \
  template std::vector<double> smoothed_element_stress<D>(const ElementStream<D>&, const StrainPatches<D>&,         \
                                                          const Material&, std::span<const double>);                \
  template void smoothed_for_each_patch_stiffness<D>(const ElementStream<D>&, const StrainPatches<D>&,              \
                                                     const Material&, std::span<const double>,                      \
                                                     const PatchStiffnessVisitor&);
SNEDE_SMOOTHED_LOOPS(2)
SNEDE_SMOOTHED_LOOPS(3)
#undef SNEDE_SMOOTHED_LOOPS

}  // namespace snede
