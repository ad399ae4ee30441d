// ElasticBody's streamed loops (fem/element_stream.hpp: per-element data in element order,
// batch_width elements per SIMD register; the §3.1 linear kernel) against an independent
// element-by-element evaluation: reference data recomputed here from the mesh's points, the
// general kernels of element_kernel.hpp run on one element at a time, and the tangent also
// as Σ_e K_e d_e from element_stiffness. Every material, 2D (plane stress) and 3D, random
// states, inverted elements and overflowing ones, and after every step of random edits and
// uniform bisection, so that the layout is seen to follow the watcher.
//
// Tolerance: 1e-14 relative to the largest nodal sum of absolute element contributions,
// each weighted by its element's conditioning: κ₂(F)², the condition number of C = FᵀF,
// which the hyperelastic kernels invert, times κ₂(Z), that of the reference edge matrix, whose
// inverse each side computes in its own order of operations (a near-degenerate element
// amplifies any round-off by them, on either side; κ₂ ≈ 1 in the mild states, but exact-predicate flips may leave
// triangles of area 1e-18, whose F is huge), times 1 + γ ι₁ for Veronda-Westmann's
// exponential. For the energy the scale is Σ_e κ₂(F)²·(|W| + |τ| ‖P‖ ‖F‖), the size of the
// terms W is made of: at small strain μ(tr C − 3) and μ ln det C are O(|H|) and cancel to
// W = O(|H|²), so W carries an error ε·|τ|μ|H|.
// Both sides evaluate the same formulas; they differ only in rounding — the order of
// operations inside a kernel (fused multiply-adds on batches), node 0 getting minus the sum
// of the columns rather than each column in turn, the energy summed lane by lane, and the
// linear kernels' H = U Z⁻¹ where the general ones form F = I + H and subtract I again. Each
// is a few ulps of the terms summed, well below 1e-14 ≈ 45 ulps (the largest seen: 3e-15);
// an error in the layout (a stale, missing or misplaced element) shows as a whole element's
// contribution, O(1). Elements with κ₂(F)² κ₂(Z) ≥ 1/tolerance have no digits to compare: whether
// they come out inverted or non-finite may differ, so the reports are compared without them,
// and the totals only where there is none.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "fem/elastic_body.hpp"
#include "fem/material_fixtures.hpp"
#include "mesh/element_quality.hpp"
#include "topology/edit_checks.hpp"
#include "topology/random_editor.hpp"

namespace snede {
namespace {

using namespace snede::testing;

constexpr double tolerance = 1e-14;

// Everything an element-by-element loop gives, with the sums of absolute contributions that
// scale its round-off.
struct ElementByElement {
  double energy = 0, energy_scale = 0;
  std::vector<double> force, force_scale, tangent, tangent_scale;
  EvaluationReport energy_report, force_report, tangent_report;
  std::set<ElementId> unresolved;  // κ₂(F)² κ₂(Z) ≥ 1/tolerance
};

template <int D>
ElementReference<D> reference_from_points(const Mesh& mesh, const std::array<VertexId, max_dimension + 1>& v,
                                          double thickness) {
  Tensor<double, D> Z;
  for (int j = 1; j <= D; ++j)
    for (int k = 0; k < D; ++k) Z(k, j - 1) = mesh.point(v[j])[k] - mesh.point(v[0])[k];
  return {Z.inverse(), Z.determinant() / (D == 2 ? 2.0 : 6.0) * (D == 2 ? thickness : 1.0)};
}

template <int D>
Tensor<double, D> differences(std::span<const double> x, const std::array<VertexId, max_dimension + 1>& v) {
  Tensor<double, D> U;
  for (int j = 1; j <= D; ++j)
    for (int k = 0; k < D; ++k) U(k, j - 1) = x[v[j] * D + k] - x[v[0] * D + k];
  return U;
}

// Adds the columns G (and conditioning·|G| to `scale`), node 0 getting minus each column.
template <int D>
void scatter(std::vector<double>& out, std::vector<double>& scale, const std::array<VertexId, max_dimension + 1>& v,
             const Tensor<double, D>& G, double conditioning) {
  for (int j = 1; j <= D; ++j)
    for (int k = 0; k < D; ++k) {
      out[v[j] * D + k] += G(k, j - 1);
      out[v[0] * D + k] -= G(k, j - 1);
      scale[v[j] * D + k] += conditioning * std::abs(G(k, j - 1));
      scale[v[0] * D + k] += conditioning * std::abs(G(k, j - 1));
    }
}

// κ₂(A): the ratio of A's extreme singular values.
template <int D>
double condition_number(const Tensor<double, D>& A) {
  const Eigen::Matrix<double, D, 1> sigma = Eigen::JacobiSVD<Tensor<double, D>>(A).singularValues();
  return sigma(0) / sigma(D - 1);
}

// κ₂(F)² = κ₂(FᵀF), times 1 + γ ι₁ for Veronda-Westmann, whose e^{γ(ι₁−3)} turns the
// round-off ε ι₁ of ι₁ into a relative error ε γ ι₁, times κ₂(Z): the body keeps Z⁻¹ from its
// own computation and this test recomputes it, each to a relative κ₂(Z)·ε in its own order of
// operations (fused multiply-adds where the compiler's target has them), which F = I + U Z⁻¹
// carries (the portable build put a collapsed cell's forces 1.13 × the bound without it apart).
template <int D, class M>
double conditioning_of(const M& m, const Tensor<double, D>& F, const ElementReference<D>& ref) {
  double exponential = 1;
  if constexpr (std::is_same_v<M, VerondaWestmann>) exponential += m.gamma * F.squaredNorm();
  return std::pow(condition_number<D>(F), 2) * exponential * condition_number<D>(ref.Z_inv);
}

// The loop as the engine always ran it: every live element from the connectivity, the
// general F/P/dP kernels, det F ≤ 0 reported (and skipped if the material forbids inversion),
// non-finite results reported and skipped. LinearElastic's tangent reads no state and so
// reports no inverted element.
template <int D, class M>
ElementByElement element_by_element(const Mesh& mesh, const M& m, double thickness, std::span<const double> u,
                                    std::span<const double> d) {
  ElementByElement r;
  for (auto* field : {&r.force, &r.force_scale, &r.tangent, &r.tangent_scale}) field->assign(u.size(), 0.0);
  for (ElementId e : mesh.connectivity().element_ids()) {
    const auto v = mesh.connectivity().element(e).simplex.oriented_vertices();
    const ElementReference<D> ref = reference_from_points<D>(mesh, v, thickness);
    const Tensor<double, D> U = differences<D>(u, v), dU = differences<D>(d, v);
    const Tensor<double, D> F = deformation_gradient<double, D>(ref, U);
    const double conditioning = conditioning_of<D>(m, F, ref);
    if (!(conditioning < 1 / tolerance)) r.unresolved.insert(e);
    if (F.determinant() <= 0) {
      r.energy_report.inverted.push_back(e);
      r.force_report.inverted.push_back(e);
      if (!std::is_same_v<M, LinearElastic>) r.tangent_report.inverted.push_back(e);
      if (M::forbids_inversion) {
        r.energy = std::numeric_limits<double>::infinity();
        continue;
      }
    }
    const double energy = element_energy<double, D>(m, ref, U);
    if (std::isfinite(energy)) {
      r.energy += energy;
      const double terms = ref.measure * first_piola<double, D>(m, F).norm() * F.norm();
      r.energy_scale += conditioning * (std::abs(energy) + terms);
    } else {
      r.energy_report.domain_errors.push_back(e);
    }
    const Tensor<double, D> force = element_force_columns<double, D>(m, ref, U);
    if (force.allFinite())
      scatter<D>(r.force, r.force_scale, v, force, conditioning);
    else
      r.force_report.domain_errors.push_back(e);
    const Tensor<double, D> tangent = element_tangent_columns<double, D>(m, ref, U, dU);
    if (tangent.allFinite())
      scatter<D>(r.tangent, r.tangent_scale, v, tangent, conditioning);
    else
      r.tangent_report.domain_errors.push_back(e);
  }
  return r;
}

// Σ_e K_e d_e with K_e from ElasticBody::element_stiffness (the body's own reference data).
std::vector<double> stiffness_products(const ElasticBody& body, std::span<const double> u, std::span<const double> d) {
  const int D = body.dim(), n = (D + 1) * D;
  std::vector<double> out(u.size(), 0.0);
  for (ElementId e : body.mesh().cell_ids()) {
    const auto v = body.mesh().connectivity().element(e).simplex.oriented_vertices();
    const std::vector<double> K = body.element_stiffness(e, u);
    for (int row = 0; row < n; ++row)
      for (int column = 0; column < n; ++column)
        out[v[row / D] * D + row % D] += K[row * n + column] * d[v[column / D] * D + column % D];
  }
  return out;
}

void expect_close(std::span<const double> actual, std::span<const double> expected, std::span<const double> scale,
                  const std::string& what) {
  double worst = 0, largest = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    worst = std::max(worst, std::abs(actual[i] - expected[i]));
    largest = std::max(largest, scale[i]);
  }
  EXPECT_LE(worst, tolerance * largest) << what << ": largest difference " << worst << ", scale " << largest;
}

// The ids not in `unresolved`.
std::vector<ElementId> resolved(const std::vector<ElementId>& ids, const std::set<ElementId>& unresolved) {
  std::vector<ElementId> kept;
  std::ranges::copy_if(ids, std::back_inserter(kept), [&](ElementId e) { return !unresolved.count(e); });
  return kept;
}

void expect_same_report(const EvaluationReport& actual, const EvaluationReport& expected,
                        const std::set<ElementId>& unresolved, const std::string& what) {
  EXPECT_EQ(resolved(actual.inverted, unresolved), resolved(expected.inverted, unresolved)) << what << ": inverted";
  EXPECT_EQ(resolved(actual.domain_errors, unresolved), resolved(expected.domain_errors, unresolved))
      << what << ": domain errors";
}

// Energy, forces and tangent action of `body` against the element-by-element loop at (u, d).
// The totals are compared only if every element's evaluation is resolved (an unresolved one
// may be skipped as non-finite on one side and summed on the other); returns whether they were.
bool expect_matches(const ElasticBody& body, std::span<const double> u, std::span<const double> d, const std::string& where) {
  const std::string what = where + ", " + name_of(body.material());
  const ElementByElement expected = std::visit(
      [&](const auto& m) {
        return body.dim() == 2 ? element_by_element<2>(body.mesh(), m, body.thickness(), u, d)
                               : element_by_element<3>(body.mesh(), m, body.thickness(), u, d);
      },
      body.material());
  EvaluationReport energy_report, force_report, tangent_report;
  const double energy = body.energy(u, energy_report);
  std::vector<double> force(u.size()), tangent(u.size());
  body.internal_forces(u, force, force_report);
  body.tangent_apply(u, d, tangent, tangent_report);
  expect_same_report(energy_report, expected.energy_report, expected.unresolved, what + ", energy");
  expect_same_report(force_report, expected.force_report, expected.unresolved, what + ", forces");
  expect_same_report(tangent_report, expected.tangent_report, expected.unresolved, what + ", tangent action");
  EXPECT_EQ(resolved(body.inverted_elements(u), expected.unresolved), resolved(expected.force_report.inverted, expected.unresolved))
      << what;
  if (!expected.unresolved.empty()) return false;
  if (std::isinf(expected.energy))
    EXPECT_EQ(energy, expected.energy) << what;
  else
    EXPECT_LE(std::abs(energy - expected.energy), tolerance * expected.energy_scale) << what << ": energy";
  expect_close(force, expected.force, expected.force_scale, what + ", forces");
  expect_close(tangent, expected.tangent, expected.tangent_scale, what + ", tangent action");
  if (expected.tangent_report.domain_errors.empty() && expected.tangent_report.inverted.empty())
    expect_close(tangent, stiffness_products(body, u, d), expected.tangent_scale, what + ", Σ K_e d_e");
  return true;
}

// The smallest edge length over the live elements: the scale of random displacements.
double shortest_edge(const Mesh& mesh) {
  double shortest = std::numeric_limits<double>::infinity();
  for (ElementId e : mesh.cell_ids()) {
    const Simplex& s = mesh.connectivity().element(e).simplex;
    for (int i = 0; i < s.count(); ++i)
      for (int j = i + 1; j < s.count(); ++j) {
        double length2 = 0;
        for (int k = 0; k < mesh.dim(); ++k) length2 += std::pow(mesh.point(s.vertex(i))[k] - mesh.point(s.vertex(j))[k], 2);
        shortest = std::min(shortest, std::sqrt(length2));
      }
  }
  return shortest;
}

std::vector<double> random_field(const Mesh& mesh, double amplitude, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  std::vector<double> x(static_cast<std::size_t>(mesh.n_points()) * mesh.dim());
  for (double& xi : x) xi = amplitude * normal(rng);
  return x;
}

// The general tangent kernel at U = 0 for LinearElastic: K_e applied to dU.
template <int D>
Tensor<double, D> linear_columns(const LinearElastic& m, const ElementReference<D>& ref, const Tensor<double, D>& dU) {
  return element_tangent_columns<double, D>(m, ref, Tensor<double, D>::Zero().eval(), dU);
}

// K_e x_e of the linear body's element_stiffness (its reference data and vertices only)
// against the linear kernel on reference data recomputed from the points, element by
// element, relative to κ₂(Z) ‖K_e‖_F ‖x_e‖: ‖K_e‖_F ‖x_e‖ bounds every term either side sums,
// and κ₂(Z), the condition number of the element's edge matrix, the relative error of Z⁻¹,
// which the body and this test compute in their own order of operations (contracted into
// fused multiply-adds or not by the compiler for the target: -march=native on an AVX-512
// machine put a near-flat element 1.2 × ‖K_e‖ ‖x_e‖ · 1e-14 apart). A stale or misplaced
// element is O(1) off.
void expect_element_data_current(const ElasticBody& linear, std::span<const double> x, const std::string& where) {
  const Mesh& mesh = linear.mesh();
  const int D = mesh.dim(), n = (D + 1) * D;
  const std::vector<double> zero(linear.n_dofs(), 0.0);
  for (ElementId e : mesh.cell_ids()) {
    const auto v = mesh.connectivity().element(e).simplex.oriented_vertices();
    const std::vector<double> K = linear.element_stiffness(e, zero);
    Eigen::VectorXd x_e(n);
    for (int column = 0; column < n; ++column) x_e(column) = x[v[column / D] * D + column % D];
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> K_e(K.data(), n, n);
    const Eigen::VectorXd product = K_e * x_e;
    std::vector<double> expected(n, 0.0);
    double edge_conditioning = 1;
    auto columns = [&](auto dimension) {
      constexpr int d = decltype(dimension)::value;
      const ElementReference<d> ref = reference_from_points<d>(mesh, v, linear.thickness());
      edge_conditioning = condition_number<d>(ref.Z_inv);
      const Tensor<double, d> G = linear_columns<d>(std::get<LinearElastic>(linear.material()), ref, differences<d>(x, v));
      for (int j = 1; j <= d; ++j)
        for (int k = 0; k < d; ++k) {
          expected[j * d + k] = G(k, j - 1);
          expected[k] -= G(k, j - 1);
        }
    };
    D == 2 ? columns(std::integral_constant<int, 2>{}) : columns(std::integral_constant<int, 3>{});
    const std::vector<double> scale(n, edge_conditioning * K_e.norm() * x_e.norm());
    expect_close(std::span<const double>(product.data(), n), expected, scale, where + ", K_e x_e of element " + std::to_string(e));
  }
}

// Bodies of every material on one mesh, checked together at random states.
struct AllBodies {
  std::vector<std::unique_ptr<ElasticBody>> bodies;
  explicit AllBodies(Mesh& mesh) {
    for (const Material& material : all_materials())
      bodies.push_back(std::make_unique<ElasticBody>(mesh, material, 1000.0, mesh.dim() == 2 ? 0.01 : 0.0));
  }
  // A mild state (no element inverted) and a rough one (some inverted), each with a random d.
  // Returns how many (state, material) totals were compared (see expect_matches).
  int expect_all_match(const Mesh& mesh, std::mt19937& rng, const std::string& where) {
    const double h = shortest_edge(mesh);
    int n_compared = 0;
    for (double amplitude : {0.05 * h, 0.4 * h}) {
      const std::vector<double> u = random_field(mesh, amplitude, rng), d = random_field(mesh, 1.0, rng);
      for (const auto& body : bodies)
        n_compared += expect_matches(*body, u, d, where + ", |u| ~ " + std::to_string(amplitude / h) + " h");
    }
    return n_compared;
  }
  // On these meshes every evaluation is resolved: all totals are compared.
  void expect_all_compared(const Mesh& mesh, std::mt19937& rng, const std::string& where) {
    EXPECT_EQ(expect_all_match(mesh, rng, where), 2 * static_cast<int>(bodies.size())) << where;
  }
  void expect_element_data_current(const Mesh& mesh, std::mt19937& rng, const std::string& where) const {
    snede::expect_element_data_current(*bodies.front(), random_field(mesh, 1.0, rng), where);
  }
};

// Jittered meshes with shuffled vertex ids (3D) and plane stress (2D).
TEST(StreamedKernels, MatchElementByElement) {
  for (int dim : {2, 3})
    for (unsigned seed : {1u, 2u}) {
      Mesh mesh = dim == 2 ? jittered_square(5 + seed, 0.25, seed) : shuffled_jittered_cube(3 + seed, 0.25, seed);
      AllBodies bodies(mesh);
      std::mt19937 rng(seed);
      bodies.expect_all_compared(mesh, rng, std::to_string(dim) + "D, seed " + std::to_string(seed));
    }
}

// The rough states above invert elements; this checks that they do, so the reports compared
// are not all empty.
TEST(StreamedKernels, RoughStatesInvertElements) {
  Mesh mesh = shuffled_jittered_cube(3, 0.25, 1);
  const ElasticBody body(mesh, NeoHookean(3e3, 0.45), 1000.0, 0.0);
  std::mt19937 rng(1);
  const std::vector<double> u = random_field(mesh, 0.4 * shortest_edge(mesh), rng);
  const std::size_t n_inverted = body.inverted_elements(u).size();
  EXPECT_GT(n_inverted, 0u);
  EXPECT_LT(n_inverted, mesh.n_cells());
}

// inverted_elements(u, floor) lists the elements whose det F — here their deformed over their
// reference volume — is at or below the floor: the needle refuses a move that flattens cells
// (det F ≤ 1e-6) as one that inverts them. Floors midway between two elements' det F, so that
// the two ways of computing it cannot disagree at the floor.
TEST(StreamedKernels, ElementsAtOrBelowADeterminantFloor) {
  for (int dim : {2, 3}) {
    Mesh mesh = dim == 2 ? jittered_square(6, 0.25, 3) : shuffled_jittered_cube(3, 0.25, 3);
    const ElasticBody body(mesh, NeoHookean(3e3, 0.45), 1000.0, dim == 2 ? 0.01 : 0.0);
    std::mt19937 rng(3);
    const std::vector<double> u = random_field(mesh, 0.6 * shortest_edge(mesh), rng);
    const std::vector<VertexId> cells = mesh.cells();
    std::vector<double> det_f;
    for (std::size_t e = 0; e < mesh.n_cells(); ++e) {
      std::vector<double> reference, deformed;
      for (int a = 0; a <= dim; ++a)
        for (int k = 0; k < dim; ++k) {
          const std::size_t i = static_cast<std::size_t>(cells[e * (dim + 1) + a]) * dim + k;
          reference.push_back(mesh.points()[i]);
          deformed.push_back(mesh.points()[i] + u[i]);
        }
      det_f.push_back(signed_volume(dim, deformed) / signed_volume(dim, reference));
    }
    std::vector<double> sorted = det_f;
    std::sort(sorted.begin(), sorted.end());
    ASSERT_LT(sorted.front(), 0.0) << "the state should invert some elements";
    for (std::size_t k : {std::size_t{0}, sorted.size() / 4, sorted.size() / 2}) {
      ASSERT_GT(sorted[k + 1] - sorted[k], 1e-9);
      const double floor = 0.5 * (sorted[k] + sorted[k + 1]);
      std::vector<ElementId> expected;
      for (std::size_t e = 0; e < det_f.size(); ++e)
        if (det_f[e] <= floor) expected.push_back(static_cast<ElementId>(e));
      EXPECT_EQ(body.inverted_elements(u, floor), expected) << dim << "D, floor " << floor;
    }
  }
}

// Veronda-Westmann's exponential overflows around one vertex pulled far away: those elements
// are reported as domain errors and left out, the rest evaluated as usual.
TEST(StreamedKernels, OverflowingElementsAreReportedAndLeftOut) {
  for (int dim : {2, 3}) {
    Mesh mesh = dim == 2 ? jittered_square(6, 0.25, 3) : shuffled_jittered_cube(3, 0.25, 3);
    const ElasticBody body(mesh, VerondaWestmann(3e3, 0.3, 2.0), 1000.0, dim == 2 ? 0.01 : 0.0);
    std::mt19937 rng(3);
    std::vector<double> u = random_field(mesh, 0.05 * shortest_edge(mesh), rng);
    const std::vector<double> d = random_field(mesh, 1.0, rng);
    const VertexId far = mesh.connectivity().element(mesh.cell_ids()[mesh.n_cells() / 2]).simplex.vertex(0);
    u[far * dim] += 100.0;
    EvaluationReport report;
    std::vector<double> force(u.size());
    body.internal_forces(u, force, report);
    EXPECT_FALSE(report.domain_errors.empty()) << dim << "D";
    expect_matches(body, u, d, std::to_string(dim) + "D, one vertex pulled 100 m");
  }
}

// After every step of random edits (splits, collapses, snaps that move vertices, insertions,
// flips and vertex removals in 2D, dissections, bisections), the bodies attached before the
// first edit still match: the layout has followed each change, freed slots included. Flips
// may leave near-flat triangles (exact predicates accept them), whose evaluation has no
// digits to compare; the element data and the reports are checked at every step, the totals
// at the steps without one — most of them.
TEST(StreamedKernels, FollowRandomEdits) {
  for (int dim : {2, 3}) {
    Mesh mesh = dim == 2 ? jittered_square(5, 0.25, 4) : shuffled_jittered_cube(3, 0.2, 4);
    AllBodies bodies(mesh);
    RandomEditor editor(mesh, 4);
    std::mt19937 rng(4);
    const std::size_t start_cells = mesh.n_cells();
    const int n_steps = 120;
    std::array<int, n_operations> done{};
    bool had_free_slots = false;
    int n_compared = 0;
    for (int step = 0; step < n_steps; ++step) {
      const Operation operation = editor.choose(double(mesh.n_cells()) / start_cells);
      if (editor.edit(operation).done) ++done[operation];
      had_free_slots |= static_cast<std::size_t>(mesh.connectivity().element_capacity()) > mesh.n_cells();
      const std::string where = std::to_string(dim) + "D, step " + std::to_string(step) + " (" + operation_names[operation] + ")";
      bodies.expect_element_data_current(mesh, rng, where);
      n_compared += bodies.expect_all_match(mesh, rng, where);
      if (::testing::Test::HasFailure()) return;
    }
    EXPECT_TRUE(had_free_slots);
    EXPECT_GT(n_compared, n_steps * 2 * static_cast<int>(bodies.bodies.size()) / 2) << dim << "D";
    ::testing::Test::RecordProperty("compared_" + std::to_string(dim) + "d", n_compared);
    for (Operation operation : {split, collapse, snap, insertion, dissection, bisection})
      EXPECT_GT(done[operation], 0) << dim << "D " << operation_names[operation];
    if (dim == 2) EXPECT_GT(done[flip] + done[removal], 0);
  }
}

// §6.5 uniform bisection, each level one merged change (elements added and removed within it).
TEST(StreamedKernels, FollowUniformBisection) {
  for (int dim : {2, 3}) {
    Mesh mesh = dim == 2 ? right_triangle_square(3) : kuhn_cube(2);
    AllBodies bodies(mesh);
    Bisection bisection(mesh);
    std::mt19937 rng(5);
    for (int level = 1; level <= 3; ++level) {
      bisection.refine_uniform(1);
      bodies.expect_all_compared(mesh, rng, std::to_string(dim) + "D, level " + std::to_string(level));
      bodies.expect_element_data_current(mesh, rng, std::to_string(dim) + "D, level " + std::to_string(level));
    }
  }
}

}  // namespace
}  // namespace snede
