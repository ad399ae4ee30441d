// A Model as the cutters see it (cutting/cut_body.hpp): the scalpel meets its deformed body,
// its constrained vertices stay where the user put them, and a piece a cut frees from every
// support is fixed where it is (§3.3). A null model is a bare mesh: the cutters get nothing.
#pragma once

#include <string>

#include "cutting/cut_body.hpp"
#include "problem/model.hpp"

namespace snede {

// The model's displacement, read through a PETSc view open for as long as each read lives.
// Throws std::invalid_argument, naming `cutter`, when the model's body is not on `mesh`.
DisplacementSource displacement_of(Model* model, const Mesh& mesh, const std::string& cutter);

// As displacement_of, with the constrained vertices as supports and the pieces the
// constraints do not hold as free pieces (PieceHolding, the static solver's own check: a piece
// with one fixed vertex left on it still turns about that vertex), each fixed on the given
// face at its displacement now.
CutBody cut_body_of(Model* model, const Mesh& mesh, const std::string& cutter);

}  // namespace snede
