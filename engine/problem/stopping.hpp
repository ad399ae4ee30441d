// Stopping criteria of §6.6: (6.8) ‖r‖ ≤ ε‖f_ext‖, and (6.9), which also counts reaction
// forces as external forces and adds a round-off floor so that a body loaded only by
// prescribed displacements can converge:
//   ‖r‖ ≤ ε √(‖f_ext‖² + ‖f_react‖²) + (E·dH/√n) ε_round   (dH → H² in 3D);
// and PETSc's relative test ‖r‖ ≤ ε ‖r(u₀)‖ from the solve's starting state, with (6.9)'s
// round-off floor (a tight ε is otherwise below what the recomputed residual can show).
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/enum_names.hpp"

namespace snede {

// E·H² (volumes) or E·t·H (sheets and membranes, which carry force through their thickness t):
// the force that strains a body of diameter H by one, the scale of (6.9)'s round-off floor.
inline double force_scale(double young_modulus, int cell_dim, double thickness, double diameter) {
  return cell_dim == 3 ? young_modulus * diameter * diameter : young_modulus * thickness * diameter;
}

enum class StoppingCriterion { load_relative /* (6.8) */, with_reactions /* (6.9) */, relative /* ε‖r(u₀)‖ */ };

// Every criterion with the name users give it (criterion=): the one list both directions read.
inline constexpr std::array stopping_criterion_names{
    named(StoppingCriterion::load_relative, "6.8"),
    named(StoppingCriterion::with_reactions, "6.9"),
    named(StoppingCriterion::relative, "relative"),
};
// The bindings find a field's names here: Python reads and writes the criterion by name.
constexpr const auto& enum_names(StoppingCriterion) { return stopping_criterion_names; }

// A name of stopping_criterion_names; anything else is a std::invalid_argument naming the value.
inline StoppingCriterion stopping_criterion(const std::string& name) {
  return enum_value(stopping_criterion_names, "criterion", name);
}
inline std::string criterion_name(StoppingCriterion criterion) {
  return enum_name(stopping_criterion_names, criterion);
}

struct StoppingRule {
  StoppingCriterion criterion = StoppingCriterion::with_reactions;
  double rtol = 1e-6;             // ε
  double round_tolerance = 1e-12; // ε_round
  double force_scale = 0;         // E·dH (2D) or E·H² (3D)
  double n_dofs = 1;
  double initial_residual_norm = 0;  // ‖r(u₀)‖, for "relative"

  double tolerance(double external_norm, double reaction_norm) const {
    if (criterion == StoppingCriterion::load_relative) return rtol * external_norm;
    const double reference =
        criterion == StoppingCriterion::relative ? initial_residual_norm : std::hypot(external_norm, reaction_norm);
    return rtol * reference + force_scale / std::sqrt(n_dofs) * round_tolerance;
  }
};

}  // namespace snede
