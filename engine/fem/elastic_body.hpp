// Matrix-free evaluation over a whole mesh (§2.3, §4.3): total energy, internal forces,
// tangent action, lumped mass and gravity, for one material. It is a connectivity watcher:
// per-element reference data (Z⁻¹, |τ|) is recomputed only for elements a change reports,
// in an ElementStream the loops read batch_width elements at a time (fem/element_stream.hpp).
//
// On a surface mesh in 3D the body is a membrane (fem/membrane_kernel.hpp): triangles under
// plane stress on a 3 × 2 F, kept one element at a time (fem/membrane_loops.hpp) rather than
// in the streams; "inverted" then means collapsed to zero area.
//
// Under the smoothed formulation (fem/formulation.hpp) the loops are fem/smoothed_loops.hpp's,
// over strain patches rebuilt after each change (fem/strain_patches.hpp); the per-element
// data and the conventions are the same.
//
// Conventions: displacement and force arrays are (n_points, dim) row-major; internal forces
// are −∂Π_int/∂u; the tangent action is ∂²Π_int/∂u² · d.
#pragma once

#include <array>
#include <functional>
#include <span>
#include <stdexcept>
#include <vector>

#include "fem/element_stream.hpp"
#include "fem/evaluation.hpp"
#include "fem/formulation.hpp"
#include "fem/material.hpp"
#include "fem/membrane_elements.hpp"
#include "fem/strain_patches.hpp"
#include "mesh/mesh.hpp"

namespace snede {

class ElasticBody : public ConnectivityWatcher {
 public:
  // thickness: required (> 0) for 2D meshes (plane stress) and surface meshes (membranes),
  // must be 0 for tetrahedra. A membrane takes only Formulation::p1 (plane stress: no locking).
  ElasticBody(Mesh& mesh, Material material, double density, double thickness,
              Formulation formulation = Formulation::p1);
  ~ElasticBody() override;
  ElasticBody(const ElasticBody&) = delete;
  ElasticBody& operator=(const ElasticBody&) = delete;

  const Mesh& mesh() const { return mesh_; }
  Mesh& mesh() { return mesh_; }
  const Material& material() const { return material_; }
  double density() const { return density_; }
  double thickness() const { return thickness_; }
  Formulation formulation() const { return formulation_; }
  int dim() const { return mesh_.dim(); }
  bool is_membrane() const { return mesh_.is_surface(); }
  std::size_t n_dofs() const { return static_cast<std::size_t>(mesh_.n_points()) * dim(); }

  // Π_int(u). +∞ if an element is inverted under a material that forbids inversion.
  double energy(std::span<const double> u, EvaluationReport& report) const;
  // f = −∂Π_int/∂u; inverted elements of a material that forbids inversion contribute nothing.
  void internal_forces(std::span<const double> u, std::span<double> f, EvaluationReport& report) const;
  // out = K(u) d, K = ∂²Π_int/∂u²; inverted elements as for the forces. LinearElastic's K
  // does not depend on u, which it does not read: report.inverted stays empty (inversion is
  // reported by energy, internal_forces and inverted_elements, which the solvers consult).
  void tangent_apply(std::span<const double> u, std::span<const double> d, std::span<double> out,
                     EvaluationReport& report) const;
  // Ids of the elements with det F ≤ floor at u (0: inverted or flat; a membrane's: collapsed,
  // whatever the floor).
  std::vector<ElementId> inverted_elements(std::span<const double> u, double floor = 0.0) const;
  // Second Piola-Kirchhoff stress per live element (σ for LinearElastic): (n_cells, dim, dim);
  // for a membrane the in-plane (n_cells, 2, 2), in each element's reference tangent frame
  // (t₁ along its first oriented edge, t₂ = n × t₁).
  std::vector<double> element_stress(std::span<const double> u) const;
  // Stiffness matrix of element e at u: ((corners)·dim)², rows and columns ordered by the
  // element's oriented vertices, then by component. For comparison and preconditioning only.
  // P1 only: a smoothed body's stiffness is a sum over patches (for_each_element_stiffness).
  std::vector<double> element_stiffness(ElementId e, std::span<const double> u) const;
  // Calls visit(e, vertices, K) for every live element with its stiffness at u, as
  // element_stiffness gives it, computed for a block of elements per kernel call (for
  // assembling J and its diagonal). Inverted elements of a material that forbids inversion
  // are left out, as the tangent action leaves them out. Under the smoothed formulation the
  // visits are the strain patches' matrices (any number of vertices, increasing; e is the
  // patch's first element): J is their sum all the same.
  using StiffnessVisitor = std::function<void(ElementId, std::span<const VertexId>, std::span<const double>)>;
  void for_each_element_stiffness(std::span<const double> u, const StiffnessVisitor& visit) const;
  // The same for the live P1 elements `elements` only (volume or membrane; each once): an edited
  // mesh's few changed cells (tangent_assembly.hpp). Throws
  // std::invalid_argument for a dead element or a smoothed formulation.
  void for_each_element_stiffness(std::span<const double> u, std::span<const ElementId> elements,
                                  const StiffnessVisitor& visit) const;
  // Whether K(u) depends on u: for every material but LinearElastic, and on membranes (whose
  // kinematics are nonlinear whatever the material).
  bool tangent_depends_on_state() const {
    return is_membrane() || !std::holds_alternative<LinearElastic>(material_);
  }
  // Lumped mass per vertex: an equal share of each incident element's mass (§2.5).
  std::vector<double> lumped_mass() const;
  // Consistent gravity load for linear elements: ρ|τ|g/(corners) per vertex and element.
  std::vector<double> gravity_forces(std::span<const double> g) const;
  KernelFlops flops_per_element() const { return flops_; }

  void init(const Connectivity& connectivity) override;
  void on_change(const Connectivity& connectivity, const ConnectivityChange& change) override;

 private:
  template <int D>
  const ElementStream<D>& stream() const;
  // The strain patches of the current mesh, rebuilt on first use after a change.
  template <int D>
  const StrainPatches<D>& patches() const;
  void reserve_ids(ElementId capacity);
  void compute_reference(const Connectivity& connectivity, ElementId e);
  void release(ElementId e);
  void check_size(const char* what, std::span<const double> a) const;

  Mesh& mesh_;
  Material material_;
  double density_;
  double thickness_;
  Formulation formulation_;
  ElementStream<2> stream_2d_;
  ElementStream<3> stream_3d_;
  MembraneElements membranes_;
  KernelFlops flops_;
  mutable StrainPatches<2> patches_2d_;
  mutable StrainPatches<3> patches_3d_;
  mutable bool patches_stale_ = true;
};

}  // namespace snede
