// Would moving one corner spoil an element? The geometric half of every edit that moves or
// places a vertex (edge split, edge collapse, §3.2 node snapping): the edit computes the new
// position once, in the doubles the mesh will store (Mesh::interpolated), and asks here before
// it touches the mesh.
//
// Volume meshes are decided exactly (orientation_2d / orientation_3d on those doubles). A
// surface triangle is flat when its corners are collinear (exact, collinear_3d) and flipped
// when its normal turns by more than 90° (n_old · n_new ≤ 0, evaluated in floating point:
// there is no exact predicate for it, and a turn near 90° is a bad edit either way).
// An element of exactly positive orientation still counts as flat when its measure is below
// the mesh's zero-volume tolerance (has_zero_volume): the mesh would refuse it, and its
// rounded measure may even be ≤ 0.
#pragma once

#include <span>
#include <string>

#include "mesh/mesh.hpp"

namespace snede {

enum class MovedShape { positive, flat, inverted };

// The shape of element e if its corner `corner` were at x (space_dim coordinates).
MovedShape shape_with_corner_at(const Mesh& mesh, ElementId e, VertexId corner, std::span<const double> x);

// Why moving `corner` to x would spoil one of `elements` (each must contain `corner`),
// naming the first such element; empty when every one stays positive.
std::string spoiled_by_move(const Mesh& mesh, std::span<const ElementId> elements, VertexId corner,
                            std::span<const double> x);

}  // namespace snede
