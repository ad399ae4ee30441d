// The three meshes the tests of structures that follow edits (tangent, grid levels, pieces) edit
// at random: a jittered square, a shuffled jittered cube and a bumpy membrane, with the names
// their parameterised tests take.
#pragma once

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "topology/edit_checks.hpp"
#include "topology/refinement_checks.hpp"

namespace snede::testing {

enum class EditedShape { square, cube, membrane };

// plane_divisions: the square's and the membrane's cells per side; cube_divisions: the cube's.
inline Mesh edited_shape_mesh(EditedShape shape, int plane_divisions, int cube_divisions) {
  switch (shape) {
    case EditedShape::square: return jittered_square(plane_divisions, 0.2, 3);
    case EditedShape::cube: return shuffled_jittered_cube(cube_divisions, 0.2, 5);
    case EditedShape::membrane: return bumpy_surface(plane_divisions, 0.1, 0.2, 7);
  }
  throw std::logic_error("unknown shape");
}

inline std::string edited_shape_name(const ::testing::TestParamInfo<EditedShape>& info) {
  return info.param == EditedShape::square ? "square" : info.param == EditedShape::cube ? "cube" : "membrane";
}

inline auto all_edited_shapes() {
  return ::testing::Values(EditedShape::square, EditedShape::cube, EditedShape::membrane);
}

}  // namespace snede::testing
