// The loops of an ElasticBody under the smoothed formulation (fem/formulation.hpp), with the
// P1 loops' conventions (fem/elastic_body.hpp). In three passes:
//   1. every simplex's displacement gradient H_e = U Z⁻¹ (2.34), added with its share of the
//      simplex's measure into its edge and vertex patches (fem/strain_patches.hpp), then
//      divided by the patches' measures: H̃_k;
//   2. the material at F̃_k = I + H̃_k, patch by patch (batch_width patches per kernel call);
//   3. back to the simplices: since Π = Σ_k |k| W(F̃_k) and ∂F̃_k/∂u = Σ_{e∈k} (share |e|/|k|) ∂F_e/∂u,
//      the forces are the P1 ones with P_e = Σ_{k∋e} share · P̃_k (2.38); the tangent action
//      the same with dP̃_k = dP(F̃_k)[dF̃_k].
// In 3D the edge patches carry the material's shear part (its Lamé λ set to 0) and the vertex
// patches its bulk part (μ set to 0): every material of §4.3 is linear in (λ, μ), so the parts
// add up to it. In 2D (plane stress, which does not lock) the edge patches carry the whole
// material.
//
// Inversion: an element with det F ≤ 0 is reported as P1 reports it, and under a material that
// forbids inversion the energy is +∞; a patch with det F̃ ≤ 0 is left out of forces and tangent
// actions under such a material (its first element reported), and a patch with a non-finite
// result is reported in domain_errors and left out.
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "fem/element_stream.hpp"
#include "fem/evaluation.hpp"
#include "fem/material.hpp"
#include "fem/strain_patches.hpp"

namespace snede {

template <int D>
double smoothed_energy(const ElementStream<D>& stream, const StrainPatches<D>& patches, const Material& material,
                       std::span<const double> u, EvaluationReport& report);
template <int D>
void smoothed_internal_forces(const ElementStream<D>& stream, const StrainPatches<D>& patches, const Material& material,
                              std::span<const double> u, std::span<double> f, EvaluationReport& report);
// As for P1, LinearElastic's tangent reads neither u nor reports inversion.
template <int D>
void smoothed_tangent_apply(const ElementStream<D>& stream, const StrainPatches<D>& patches, const Material& material,
                            std::span<const double> u, std::span<const double> d, std::span<double> out,
                            EvaluationReport& report);
// Per live element, the share-weighted mean of its patches' second Piola-Kirchhoff stresses
// (σ for LinearElastic): the stress the formulation sees there, (n_cells, D, D).
template <int D>
std::vector<double> smoothed_element_stress(const ElementStream<D>& stream, const StrainPatches<D>& patches,
                                            const Material& material, std::span<const double> u);
// visit(first element, vertices, K) for every patch with its stiffness at u (patch vertices in
// increasing order, then components): the exact tangent, as a sum of patch matrices. Patches
// left out of the tangent action are left out here.
using PatchStiffnessVisitor = std::function<void(ElementId, std::span<const VertexId>, std::span<const double>)>;
template <int D>
void smoothed_for_each_patch_stiffness(const ElementStream<D>& stream, const StrainPatches<D>& patches,
                                       const Material& material, std::span<const double> u,
                                       const PatchStiffnessVisitor& visit);

}  // namespace snede
