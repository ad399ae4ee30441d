// An element's local dofs (§2.3), one element at a time: the kernels take a nodal field as
// differences to corner 0 (columns: corners 1, 2, …) and give forces and tangent actions
// as columns on corners 1, 2, … (corner 0: minus their sum); an element stiffness orders
// its rows and columns corner by corner, then by component.
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "fem/tensor.hpp"
#include "mesh/connectivity_watcher.hpp"

namespace snede {

// U of `nodal` ((n_points, Components) row-major) over the element's corners v.
template <int Components, std::size_t Corners>
Gradient<double, Components, static_cast<int>(Corners) - 1> gather_differences(std::span<const double> nodal,
                                                                                const std::array<VertexId, Corners>& v) {
  constexpr int columns = static_cast<int>(Corners) - 1;
  Gradient<double, Components, columns> U;
  for (int j = 1; j <= columns; ++j)
    for (int k = 0; k < Components; ++k)
      U(k, j - 1) = nodal[static_cast<std::size_t>(v[j]) * Components + k] - nodal[static_cast<std::size_t>(v[0]) * Components + k];
  return U;
}

// The unit direction on local dof `column` (corner column / Components, component
// column % Components) as differences (corner 0 moves every column the other way).
template <class T, int Components, int Columns>
Gradient<T, Components, Columns> unit_differences(int column) {
  Gradient<T, Components, Columns> dU = Gradient<T, Components, Columns>::Zero();
  const int corner = column / Components, component = column % Components;
  if (corner == 0)
    dU.row(component).setConstant(T(-1.0));
  else
    dU(component, corner - 1) = T(1.0);
  return dU;
}

// Column `column` of an element stiffness K (n × n row-major) from the tangent columns G
// of that column's unit direction.
template <class Columns>
void store_stiffness_column(const Columns& G, int column, std::span<double> K) {
  const int components = static_cast<int>(G.rows()), corners = static_cast<int>(G.cols()) + 1, n = components * corners;
  for (int k = 0; k < components; ++k) {
    double corner_0 = 0;
    for (int j = 1; j < corners; ++j) {
      K[static_cast<std::size_t>(j * components + k) * n + column] = G(k, j - 1);
      corner_0 -= G(k, j - 1);
    }
    K[static_cast<std::size_t>(k) * n + column] = corner_0;
  }
}

}  // namespace snede
