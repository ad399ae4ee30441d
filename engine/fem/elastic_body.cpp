#include "fem/elastic_body.hpp"

#include <petsclog.h>

#include <bit>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/counted.hpp"
#include "core/error.hpp"
#include "core/log_event.hpp"
#include "fem/block_stiffness.hpp"
#include "fem/linear_elastic_kernel.hpp"
#include "fem/local_dofs.hpp"
#include "fem/membrane_loops.hpp"
#include "fem/smoothed_loops.hpp"

namespace snede {
namespace {

// The kernels the loops run, on double, Counted or Batch: §3.1's for LinearElastic (no F, a
// tangent independent of the state), the general F/P/dP ones (§2.3, §4.3) otherwise.
template <class T, int D, class M, class S>
T energy_kernel(const M& m, const ElementReference<D, S>& ref, const Tensor<T, D>& U) {
  if constexpr (is_linear_elastic<M>)
    return linear_energy<T, D>(m, ref, U);
  else
    return element_energy<T, D>(m, ref, U);
}

template <class T, int D, class M, class S>
Tensor<T, D> force_kernel(const M& m, const ElementReference<D, S>& ref, const Tensor<T, D>& U) {
  if constexpr (is_linear_elastic<M>)
    return -linear_stiffness_columns<T, D>(m, ref, U);
  else
    return element_force_columns<T, D>(m, ref, U);
}

template <class T, int D, class M, class S>
Tensor<T, D> tangent_kernel(const M& m, const ElementReference<D, S>& ref, const Tensor<T, D>& U, const Tensor<T, D>& dU) {
  if constexpr (is_linear_elastic<M>)
    return linear_stiffness_columns<T, D>(m, ref, dU);
  else
    return element_tangent_columns<T, D>(m, ref, U, dU);
}

// Calls function(material alternative, std::integral_constant<int, D>).
template <class Function>
decltype(auto) with_material_and_dimension(const Material& material, int dim, Function&& function) {
  return std::visit(
      [&](const auto& m) {
        return dim == 2 ? function(m, std::integral_constant<int, 2>{}) : function(m, std::integral_constant<int, 3>{});
      },
      material);
}

// Calls visit(e, vertices, reference) for every live element, one at a time (the loops that
// are not hot: stresses, masses).
template <int D, class Visit>
void for_each_live_element(const ElementStream<D>& stream, Visit&& visit) {
  for (ElementId e = 0; e < stream.capacity(); ++e)
    if (stream.is_live(e)) visit(e, stream.vertices(e), stream.reference(e));
}

// The lanes of one block that count, as the element-by-element loop always decided: a live
// element with det F ≤ 0 is reported as inverted and left out if the material forbids
// inversion; the others are evaluated, and a non-finite result is reported and left out.
struct CountedLanes {
  LaneMask evaluated = 0, kept = 0;
};

// Lane by lane, for the blocks with a free slot, an inverted element or a non-finite result.
[[gnu::noinline]] CountedLanes count_exceptional_lanes(LaneMask live, LaneMask inverted, LaneMask finite,
                                                       bool forbids_inversion, ElementId first, EvaluationReport& report) {
  CountedLanes lanes;
  for (int lane = 0; lane < batch_width; ++lane) {
    const LaneMask bit = LaneMask{1} << lane;
    if (!(live & bit)) continue;
    if (inverted & bit) {
      report.inverted.push_back(first + lane);
      if (forbids_inversion) continue;
    }
    lanes.evaluated |= bit;
    if (!(finite & bit)) {
      report.domain_errors.push_back(first + lane);
      continue;
    }
    lanes.kept |= bit;
  }
  return lanes;
}

CountedLanes count_lanes(LaneMask live, LaneMask inverted, LaneMask finite, bool forbids_inversion, ElementId first,
                         EvaluationReport& report) {
  if (live == all_lanes && inverted == 0 && finite == all_lanes) return {all_lanes, all_lanes};
  return count_exceptional_lanes(live, inverted, finite, forbids_inversion, first, report);
}

// Lanes with det F ≤ floor (x − 0.0 folds to x in the flattened loops that pass no floor).
template <int D>
LaneMask inverted_lanes(const ElementBlock<D>& block, const Tensor<Batch, D>& U, double floor = 0.0) {
  return non_positive_lanes(deformation_gradient<Batch, D>(block.reference, U).determinant() - floor);
}

// The block loops are flattened: every kernel, Eigen expression and Batch operation inlined
// into one loop body, so batches stay in registers (GCC's inliner, left alone, calls Eigen's
// per-coefficient assignments on a custom scalar out of line).
//
// Adds every block's columns into `out` (zeroed first). kernel(block, U) gives the columns;
// U is gathered from u, and inversion checked, only if reads_state; each block's results are
// checked for non-finite values only if checks_results. The kernel (with the material it
// holds) and the block range are local copies: stores into `out` cannot change them, so they
// stay in registers.
template <bool reads_state, bool checks_results, int D, class Kernel>
[[gnu::flatten]] std::size_t accumulate_blocks(const ElementStream<D>& stream, bool forbids_inversion,
                                               std::span<const double> u, std::span<double> out,
                                               EvaluationReport& report, const Kernel& kernel) {
  std::fill(out.begin(), out.end(), 0.0);
  std::size_t n_evaluated = 0;
  const Kernel evaluate = kernel;
  const std::span<const ElementBlock<D>> blocks = stream.blocks();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    prefetch_ahead<D>(blocks, b);
    const ElementBlock<D>& block = blocks[b];
    Tensor<Batch, D> U;
    LaneMask inverted = 0;
    if constexpr (reads_state) {
      U = gather_differences<D>(u, block);
      inverted = inverted_lanes<D>(block, U);
    }
    const Tensor<Batch, D> G = evaluate(block, U);
    const LaneMask finite = checks_results ? finite_lanes(G) : all_lanes;
    const CountedLanes lanes = count_lanes(ElementStream<D>::live_lanes(block), inverted, finite, forbids_inversion,
                                           static_cast<ElementId>(b * batch_width), report);
    n_evaluated += std::popcount(lanes.evaluated);
    scatter_columns<D>(out, block, G, lanes.kept);
  }
  return n_evaluated;
}

// accumulate_blocks with its results checked once, on `out`: a non-finite element result
// makes `out` non-finite (so does a sum that overflows, for which the second pass then finds
// no element). Only then does the loop run again, checking every block, to report and leave
// out the non-finite elements as an element-by-element loop does.
template <bool reads_state, int D, class Kernel>
std::size_t accumulate(const ElementStream<D>& stream, bool forbids_inversion, std::span<const double> u,
                       std::span<double> out, EvaluationReport& report, const Kernel& kernel) {
  EvaluationReport first_pass;
  const std::size_t n = accumulate_blocks<reads_state, false, D>(stream, forbids_inversion, u, out, first_pass, kernel);
  if (!all_finite(out)) return accumulate_blocks<reads_state, true, D>(stream, forbids_inversion, u, out, report, kernel);
  report.inverted.insert(report.inverted.end(), first_pass.inverted.begin(), first_pass.inverted.end());
  return n;
}

// Π_int: the energies of the blocks' lanes that count, summed lane by lane and then across.
template <int D, class M>
[[gnu::flatten]] double sum_energy(const ElementStream<D>& stream, const M& material, std::span<const double> u,
                                   EvaluationReport& report, std::size_t& n_evaluated) {
  const M m = material;  // a local copy, as in accumulate_blocks
  const std::span<const ElementBlock<D>> blocks = stream.blocks();
  Batch sums = 0.0;
  bool infinite = false;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    prefetch_ahead<D>(blocks, b);
    const ElementBlock<D>& block = blocks[b];
    const Tensor<Batch, D> U = gather_differences<D>(u, block);
    const LaneMask live = ElementStream<D>::live_lanes(block), inverted = inverted_lanes<D>(block, U);
    const Batch values = energy_kernel<Batch, D>(m, block.reference, U);
    const CountedLanes lanes = count_lanes(live, inverted, finite_lanes(values), M::forbids_inversion,
                                           static_cast<ElementId>(b * batch_width), report);
    // +∞ for an inverted element of a material that forbids inversion.
    if (M::forbids_inversion && (live & inverted)) infinite = true;
    n_evaluated += std::popcount(lanes.evaluated);
    sums += lanes.kept == all_lanes ? values : Batch::from_lanes([&](int lane) { return lanes.kept >> lane & 1 ? values[lane] : 0.0; });
  }
  double total = 0;
  for (int lane = 0; lane < batch_width; ++lane) total += sums[lane];
  return infinite ? std::numeric_limits<double>::infinity() : total;
}

// Calls visit(e, vertices, K_e) for every live element with its stiffness at u
// (fem/block_stiffness.hpp), leaving out inverted elements of a material that forbids
// inversion. Flattened like the loops above: the block's kernels inlined into one body.
// `wanted`, if given, holds one mask of wanted lanes per block (the others are not computed).
template <int D, class M>
[[gnu::flatten]] void visit_block_stiffness(const ElementStream<D>& stream, const M& material, std::span<const double> u,
                                            const ElasticBody::StiffnessVisitor& visit,
                                            const std::vector<LaneMask>* wanted = nullptr) {
  const M m = material;  // a local copy, as in accumulate_blocks
  const std::span<const ElementBlock<D>> blocks = stream.blocks();
  LaneStiffness<D> K;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    if (wanted && !(*wanted)[b]) continue;
    prefetch_ahead<D>(blocks, b);
    const ElementBlock<D>& block = blocks[b];
    LaneMask lanes = ElementStream<D>::live_lanes(block);
    if (wanted) lanes &= (*wanted)[b];
    Tensor<Batch, D> U;
    if constexpr (!is_linear_elastic<M>) U = gather_differences<D>(u, block);
    if constexpr (M::forbids_inversion) lanes &= ~inverted_lanes<D>(block, U);
    if (!lanes) continue;
    block_stiffness<D>(m, block, U, K);
    for (int lane = 0; lane < batch_width; ++lane) {
      if (!(lanes >> lane & 1)) continue;
      const ElementId e = static_cast<ElementId>(b * batch_width + lane);
      const auto vertices = stream.vertices(e);
      visit(e, std::span<const VertexId>(vertices.data(), D + 1), std::span<const double>(K[lane]));
    }
  }
}

template <int D>
[[gnu::flatten]] std::vector<ElementId> find_inverted(const ElementStream<D>& stream, std::span<const double> u,
                                                      double floor) {
  std::vector<ElementId> inverted;
  const std::span<const ElementBlock<D>> blocks = stream.blocks();
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    prefetch_ahead<D>(blocks, b);
    const ElementBlock<D>& block = blocks[b];
    const LaneMask lanes =
        ElementStream<D>::live_lanes(block) & inverted_lanes<D>(block, gather_differences<D>(u, block), floor);
    for (int lane = 0; lane < batch_width; ++lane)
      if (lanes >> lane & 1) inverted.push_back(static_cast<ElementId>(b * batch_width + lane));
  }
  return inverted;
}

template <int D, class M>
KernelFlops count_flops(const M& m) {
  ElementReference<D> ref;
  ref.Z_inv = Tensor<double, D>::Identity();
  ref.measure = 1;
  const auto differences = flop_count_differences<D, D>();
  const auto &U = differences[0], &dU = differences[1];
  return count_kernel_flops([&] { energy_kernel<Counted, D>(m, ref, U); }, [&] { force_kernel<Counted, D>(m, ref, U); },
                            [&] { tangent_kernel<Counted, D>(m, ref, U, dU); });
}

void log_flops(std::int64_t per_element, std::size_t n_elements) {
  SNEDE_PETSC(PetscLogFlops(static_cast<PetscLogDouble>(per_element) * static_cast<PetscLogDouble>(n_elements)));
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

ElasticBody::ElasticBody(Mesh& mesh, Material material, double density, double thickness, Formulation formulation)
    : mesh_(mesh), material_(std::move(material)), density_(density), thickness_(thickness), formulation_(formulation) {
  require_positive("density", density);
  if (is_membrane()) {
    if (formulation != Formulation::p1)
      throw std::invalid_argument("formulation '" + std::string(name_of(formulation)) +
                                  "' is for tetrahedra and plane triangles; a membrane takes 'p1' (in plane stress it "
                                  "does not lock)");
    require_positive("thickness (required for a membrane on a surface mesh)", thickness);
    flops_ = membrane_kernel_flops(material_);
  } else {
    if (mesh.dim() == 2)
      require_positive("thickness (required for a 2D, plane-stress body)", thickness);
    else if (thickness != 0)
      throw std::invalid_argument("thickness is only for 2D (plane-stress) bodies and membranes; this mesh is 3D");
    flops_ = with_material_and_dimension(material_, mesh.dim(), [](const auto& m, auto dimension) {
      return count_flops<decltype(dimension)::value>(m);
    });
  }
  mesh_.connectivity().add_watcher(this);
}

ElasticBody::~ElasticBody() { mesh_.connectivity().remove_watcher(this); }

template <>
const ElementStream<2>& ElasticBody::stream<2>() const {
  return stream_2d_;
}
template <>
const ElementStream<3>& ElasticBody::stream<3>() const {
  return stream_3d_;
}

template <>
const StrainPatches<2>& ElasticBody::patches<2>() const {
  if (patches_stale_) patches_2d_.build(stream_2d_, mesh_.n_points());
  patches_stale_ = false;
  return patches_2d_;
}
template <>
const StrainPatches<3>& ElasticBody::patches<3>() const {
  if (patches_stale_) patches_3d_.build(stream_3d_, mesh_.n_points());
  patches_stale_ = false;
  return patches_3d_;
}

void ElasticBody::reserve_ids(ElementId capacity) {
  if (is_membrane())
    membranes_.reserve_ids(capacity);
  else
    dim() == 2 ? stream_2d_.reserve_ids(capacity) : stream_3d_.reserve_ids(capacity);
}

void ElasticBody::release(ElementId e) {
  if (is_membrane())
    membranes_.release(e);
  else
    dim() == 2 ? stream_2d_.release(e) : stream_3d_.release(e);
}

void ElasticBody::compute_reference(const Connectivity& connectivity, ElementId e) {
  const auto oriented = connectivity.element(e).simplex.oriented_vertices();
  if (is_membrane()) {
    const MembraneElements::Vertices v{oriented[0], oriented[1], oriented[2]};
    auto corner = [&](int j) { return Eigen::Vector3d(mesh_.point(v[j]).data()); };
    membranes_.store(e, v, membrane_reference(corner(0), corner(1), corner(2), thickness_));
    return;
  }
  auto fill = [&](auto& stream, auto dimension) {
    constexpr int D = decltype(dimension)::value;
    typename ElementStream<D>::Vertices v;
    std::copy_n(oriented.begin(), D + 1, v.begin());
    Tensor<double, D> Z;
    for (int j = 1; j <= D; ++j)
      for (int k = 0; k < D; ++k) Z(k, j - 1) = mesh_.point(v[j])[k] - mesh_.point(v[0])[k];
    const ElementReference<D> reference{Z.inverse(), Z.determinant() / (D == 2 ? 2.0 : 6.0) * (D == 2 ? thickness_ : 1.0)};
    stream.store(e, v, reference);
  };
  if (dim() == 2)
    fill(stream_2d_, std::integral_constant<int, 2>{});
  else
    fill(stream_3d_, std::integral_constant<int, 3>{});
}

void ElasticBody::init(const Connectivity& connectivity) {
  stream_2d_ = {};
  stream_3d_ = {};
  membranes_ = {};
  reserve_ids(connectivity.element_capacity());
  for (ElementId e : connectivity.element_ids()) compute_reference(connectivity, e);
  patches_stale_ = true;
}

void ElasticBody::on_change(const Connectivity& connectivity, const ConnectivityChange& change) {
  // Only the slots of the elements that changed are touched (§7.4): O(size of the change).
  // A removed id may come back among the added ones (the free list reuses it).
  reserve_ids(connectivity.element_capacity());
  for (const auto& entry : change.removed_elements)
    if (!connectivity.is_element(entry.first)) release(entry.first);
  for (ElementId e : change.added_elements) compute_reference(connectivity, e);
  for (const auto& entry : change.changed_elements) compute_reference(connectivity, entry.first);
  for (ElementId e : change.reshaped_elements) compute_reference(connectivity, e);  // a corner moved
  patches_stale_ = true;  // vertices may have been added too: the patches' arrays are per vertex
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
  if (is_membrane()) {
    std::size_t n_evaluated = 0;
    const double total = membrane_energy(membranes_, material_, u, report, n_evaluated);
    log_flops(flops_.energy, n_evaluated);
    return total;
  }
  if (formulation_ == Formulation::smoothed)
    return dim() == 2 ? smoothed_energy<2>(stream_2d_, patches<2>(), material_, u, report)
                      : smoothed_energy<3>(stream_3d_, patches<3>(), material_, u, report);
  return with_material_and_dimension(material_, dim(), [&](const auto& m, auto dimension) {
    constexpr int D = decltype(dimension)::value;
    std::size_t n_evaluated = 0;
    const double total = sum_energy<D>(stream<D>(), m, u, report, n_evaluated);
    log_flops(flops_.energy, n_evaluated);
    return total;
  });
}

void ElasticBody::internal_forces(std::span<const double> u, std::span<double> f, EvaluationReport& report) const {
  static const PetscLogEvent event = log_event("SnedeForces");
  ScopedEvent logged(event);
  check_size("displacement", u);
  check_size("force", f);
  if (is_membrane()) {
    log_flops(flops_.force, membrane_internal_forces(membranes_, material_, u, f, report));
    return;
  }
  if (formulation_ == Formulation::smoothed) {
    dim() == 2 ? smoothed_internal_forces<2>(stream_2d_, patches<2>(), material_, u, f, report)
               : smoothed_internal_forces<3>(stream_3d_, patches<3>(), material_, u, f, report);
    return;
  }
  with_material_and_dimension(material_, dim(), [&](const auto& m, auto dimension) {
    constexpr int D = decltype(dimension)::value;
    const std::size_t n = accumulate<true, D>(stream<D>(), forbids_inversion(material_), u, f, report, [m](const ElementBlock<D>& block, const Tensor<Batch, D>& U) {
      return force_kernel<Batch, D>(m, block.reference, U);
    });
    log_flops(flops_.force, n);
  });
}

void ElasticBody::tangent_apply(std::span<const double> u, std::span<const double> d, std::span<double> out,
                                EvaluationReport& report) const {
  static const PetscLogEvent event = log_event("SnedeTangentApply");
  ScopedEvent logged(event);
  check_size("displacement", u);
  check_size("direction", d);
  check_size("result", out);
  if (is_membrane()) {
    log_flops(flops_.tangent, membrane_tangent_apply(membranes_, material_, u, d, out, report));
    return;
  }
  if (formulation_ == Formulation::smoothed) {
    dim() == 2 ? smoothed_tangent_apply<2>(stream_2d_, patches<2>(), material_, u, d, out, report)
               : smoothed_tangent_apply<3>(stream_3d_, patches<3>(), material_, u, d, out, report);
    return;
  }
  with_material_and_dimension(material_, dim(), [&](const auto& m, auto dimension) {
    constexpr int D = decltype(dimension)::value;
    constexpr bool reads_state = !is_linear_elastic<std::decay_t<decltype(m)>>;
    const std::size_t n = accumulate<reads_state, D>(stream<D>(), forbids_inversion(material_), u, out, report, [m, d](const ElementBlock<D>& block, const Tensor<Batch, D>& U) {
      return tangent_kernel<Batch, D>(m, block.reference, U, gather_differences<D>(d, block));
    });
    log_flops(flops_.tangent, n);
  });
}

std::vector<ElementId> ElasticBody::inverted_elements(std::span<const double> u, double floor) const {
  check_size("displacement", u);
  if (is_membrane()) return membrane_collapsed_elements(membranes_, u);
  return dim() == 2 ? find_inverted<2>(stream<2>(), u, floor) : find_inverted<3>(stream<3>(), u, floor);
}

std::vector<double> ElasticBody::element_stress(std::span<const double> u) const {
  check_size("displacement", u);
  if (is_membrane()) return membrane_element_stress(membranes_, material_, u);
  if (formulation_ == Formulation::smoothed)
    return dim() == 2 ? smoothed_element_stress<2>(stream_2d_, patches<2>(), material_, u)
                      : smoothed_element_stress<3>(stream_3d_, patches<3>(), material_, u);
  std::vector<double> stress;
  with_material_and_dimension(material_, dim(), [&](const auto& m, auto dimension) {
    constexpr int D = decltype(dimension)::value;
    for_each_live_element<D>(stream<D>(), [&](ElementId, const auto& v, const ElementReference<D>& ref) {
      const Tensor<double, D> S = second_piola<double, D>(m, deformation_gradient<double, D>(ref, gather_differences<D>(u, v)));
      for (int i = 0; i < D; ++i)
        for (int j = 0; j < D; ++j) stress.push_back(S(i, j));
    });
  });
  return stress;
}

std::vector<double> ElasticBody::element_stiffness(ElementId e, std::span<const double> u) const {
  check_size("displacement", u);
  if (!mesh_.connectivity().is_element(e)) throw std::invalid_argument("element " + std::to_string(e) + " does not exist");
  if (is_membrane()) return membrane_element_stiffness(membranes_, material_, e, u);
  if (formulation_ != Formulation::p1)
    throw std::invalid_argument("element_stiffness is a P1 element's; under formulation '" +
                                std::string(name_of(formulation_)) + "' stiffness belongs to strain patches (assemble the tangent)");
  const int n = (dim() + 1) * dim();
  std::vector<double> K(static_cast<std::size_t>(n) * n);
  with_material_and_dimension(material_, dim(), [&](const auto& m, auto dimension) {
    constexpr int D = decltype(dimension)::value;
    const ElementReference<D> ref = stream<D>().reference(e);
    const Tensor<double, D> U = gather_differences<D>(u, stream<D>().vertices(e));
    for (int column = 0; column < n; ++column)
      store_stiffness_column(element_tangent_columns<double, D>(m, ref, U, unit_differences<double, D, D>(column)), column, K);
  });
  return K;
}

void ElasticBody::for_each_element_stiffness(std::span<const double> u, const StiffnessVisitor& visit) const {
  check_size("displacement", u);
  if (is_membrane()) return membrane_for_each_element_stiffness(membranes_, material_, u, visit);
  if (formulation_ == Formulation::smoothed)
    return dim() == 2 ? smoothed_for_each_patch_stiffness<2>(stream_2d_, patches<2>(), material_, u, visit)
                      : smoothed_for_each_patch_stiffness<3>(stream_3d_, patches<3>(), material_, u, visit);
  with_material_and_dimension(material_, dim(), [&](const auto& m, auto dimension) {
    visit_block_stiffness<decltype(dimension)::value>(stream<decltype(dimension)::value>(), m, u, visit);
  });
}

void ElasticBody::for_each_element_stiffness(std::span<const double> u, std::span<const ElementId> elements,
                                             const StiffnessVisitor& visit) const {
  check_size("displacement", u);
  if (formulation_ != Formulation::p1)
    throw std::invalid_argument("the stiffness of chosen elements is a P1 element's; under formulation '" +
                                std::string(name_of(formulation_)) + "' stiffness belongs to strain patches");
  const Connectivity& c = mesh_.connectivity();
  for (ElementId e : elements)
    if (!c.is_element(e)) throw std::invalid_argument("element " + std::to_string(e) + " does not exist");
  if (is_membrane()) {
    const std::vector<ElementId> only(elements.begin(), elements.end());
    return membrane_for_each_element_stiffness(membranes_, material_, u, visit, &only);
  }
  // The blocks' kernels compute batch_width elements at once: only blocks holding a chosen one.
  const auto capacity = static_cast<std::size_t>(c.element_capacity());
  std::vector<LaneMask> wanted((capacity + batch_width - 1) / batch_width, 0);
  for (ElementId e : elements) wanted[e / batch_width] |= LaneMask{1} << (e % batch_width);
  with_material_and_dimension(material_, dim(), [&](const auto& m, auto dimension) {
    constexpr int D = decltype(dimension)::value;
    wanted.resize(stream<D>().blocks().size(), 0);
    visit_block_stiffness<D>(stream<D>(), m, u, visit, &wanted);
  });
}

std::vector<double> ElasticBody::lumped_mass() const {
  std::vector<double> mass(mesh_.n_points(), 0.0);
  if (is_membrane()) {
    membranes_.for_each_live([&](ElementId, const MembraneElements::Vertices& v, const MembraneReference& ref) {
      for (VertexId vertex : v) mass[vertex] += density_ * ref.measure / 3;
    });
    return mass;
  }
  auto loop = [&](auto dimension) {
    constexpr int D = decltype(dimension)::value;
    for_each_live_element<D>(stream<D>(), [&](ElementId, const auto& v, const ElementReference<D>& ref) {
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
