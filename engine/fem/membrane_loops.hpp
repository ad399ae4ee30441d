// The element loops of an ElasticBody on a surface mesh in 3D (fem/membrane_kernel.hpp),
// one element at a time, with the volume loops' conventions (fem/elastic_body.hpp): nodal
// arrays (n_points, 3); a collapsed element (zero area, the membrane's inversion) is
// reported in report.inverted and left out if the material forbids inversion, where the
// energy is then +∞; a non-finite element result is reported in report.domain_errors and
// left out. Each returns (or counts in n_evaluated) the elements it evaluated.
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "fem/evaluation.hpp"
#include "fem/material.hpp"
#include "fem/membrane_elements.hpp"

namespace snede {

double membrane_energy(const MembraneElements& elements, const Material& material, std::span<const double> u,
                       EvaluationReport& report, std::size_t& n_evaluated);
std::size_t membrane_internal_forces(const MembraneElements& elements, const Material& material,
                                     std::span<const double> u, std::span<double> f, EvaluationReport& report);
// LinearElastic's tangent does not read u (nor report collapse), as for volume bodies.
std::size_t membrane_tangent_apply(const MembraneElements& elements, const Material& material,
                                   std::span<const double> u, std::span<const double> d, std::span<double> out,
                                   EvaluationReport& report);
std::vector<ElementId> membrane_collapsed_elements(const MembraneElements& elements, std::span<const double> u);
// The 2 × 2 in-plane stress of every live element in its reference frame (t₁ along its
// first edge, t₂ = n × t₁): (n_cells, 2, 2) row-major.
std::vector<double> membrane_element_stress(const MembraneElements& elements, const Material& material,
                                            std::span<const double> u);
// Element e's 9 × 9 stiffness at u (corners in oriented order, then x, y, z).
std::vector<double> membrane_element_stiffness(const MembraneElements& elements, const Material& material,
                                               ElementId e, std::span<const double> u);
// visit(e, vertices, K) for every live element (or, given `only`, for those live elements) but
// the collapsed ones of a material that forbids inversion.
void membrane_for_each_element_stiffness(
    const MembraneElements& elements, const Material& material, std::span<const double> u,
    const std::function<void(ElementId, std::span<const VertexId>, std::span<const double>)>& visit,
    const std::vector<ElementId>* only = nullptr);
KernelFlops membrane_kernel_flops(const Material& material);

}  // namespace snede
