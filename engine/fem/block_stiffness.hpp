// The stiffness matrices of a block's batch_width elements at once (§2.3, §4.3), for
// assembling J: K_e = ∂²(energy)/∂u_e², n × n with n = (D + 1)·D, rows and columns ordered by
// the element's oriented corners, then by component (fem/local_dofs.hpp's order), as
// ElasticBody::element_stiffness gives one.
//
// What depends on the state — F, C, S and the material's ∂S/∂C at C — is formed once per
// block (FirstPiolaTangent); each of the D² columns of corners 1..D is then one application
// of that linear map to a unit direction's gradient, and corner 0's columns are minus the sums of the other corners'
// columns of the same component (a translation has no stiffness). Applying the whole
// tangent kernel to each of the n unit directions instead repeated the state's work n times
// (C⁻¹, √det C, Veronda-Westmann's exponential and plane stress's c₃₃ per column).
#pragma once

#include <array>
#include <utility>

#include "fem/element_stream.hpp"
#include "fem/linear_elastic_kernel.hpp"

namespace snede {

template <int D>
inline constexpr int stiffness_size = (D + 1) * D;

// One n × n matrix (row-major) per lane.
template <int D>
using LaneStiffness = std::array<std::array<double, stiffness_size<D> * stiffness_size<D>>, batch_width>;

// Writes the stiffness of every lane of `block` at displacement differences U into K
// (LinearElastic: the same at every state; U is not read).
template <int D, class M>
void block_stiffness(const M& m, const ElementBlock<D>& block, const Tensor<Batch, D>& U, LaneStiffness<D>& K) {
  constexpr int n = stiffness_size<D>;
  // Column `column` of every lane's K from the tangent columns G of its unit direction: rows
  // of corners 1..D from G, corner 0's rows minus their sum.
  auto store_column = [&K](const Tensor<Batch, D>& G, int column) {
    for (int k = 0; k < D; ++k) {
      Batch corner_0 = 0.0;
      for (int j = 1; j <= D; ++j) {
        corner_0 -= G(k, j - 1);
        for (int lane = 0; lane < batch_width; ++lane) K[lane][(j * D + k) * n + column] = G(k, j - 1)[lane];
      }
      for (int lane = 0; lane < batch_width; ++lane) K[lane][k * n + column] = corner_0[lane];
    }
  };
  // Column (corner b ≥ 1, component k) is the unit direction whose gradient dF has Z⁻¹'s row
  // b − 1 in row k; the columns are unrolled so that each dF is placed at compile time.
  auto store_corner_columns = [&](auto&& columns_of_gradient) {
    [&]<int... column>(std::integer_sequence<int, column...>) {
      ([&] {
        constexpr int b = (column + D) / D, k = column % D;
        Tensor<Batch, D> dF = Tensor<Batch, D>::Zero();
        dF.row(k) = block.reference.Z_inv.row(b - 1);
        store_column(columns_of_gradient(dF), column + D);
      }(), ...);
    }(std::make_integer_sequence<int, D * D>{});
  };
  if constexpr (is_linear_elastic<M>) {
    store_corner_columns([&](const Tensor<Batch, D>& dF) {
      return linear_stiffness_columns_of_gradient<Batch, D>(m, block.reference, dF);
    });
  } else {
    const FirstPiolaTangent<Batch, D, M, D> dP_of(m, deformation_gradient<Batch, D>(block.reference, U));
    store_corner_columns([&](const Tensor<Batch, D>& dF) {
      return tangent_columns_of_gradient<Batch, D>(dP_of, block.reference, dF);
    });
  }
  for (auto& matrix : K)
    for (int row = 0; row < n; ++row)
      for (int k = 0; k < D; ++k) {
        double sum = 0;
        for (int j = 1; j <= D; ++j) sum += matrix[row * n + j * D + k];
        matrix[row * n + k] = -sum;
      }
}

}  // namespace snede
