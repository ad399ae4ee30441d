// Stopping criteria of §6.6: (6.8) ‖r‖ ≤ ε‖f_ext‖, and (6.9), which also counts reaction
// forces as external forces and adds a round-off floor so that a body loaded only by
// prescribed displacements can converge:
//   ‖r‖ ≤ ε √(‖f_ext‖² + ‖f_react‖²) + (E·dH/√n) ε_round   (dH → H² in 3D).
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

namespace snede {

// E·H² (volumes) or E·t·H (sheets and membranes, which carry force through their thickness t):
// the force that strains a body of diameter H by one, the scale of (6.9)'s round-off floor.
inline double force_scale(double young_modulus, int cell_dim, double thickness, double diameter) {
  return cell_dim == 3 ? young_modulus * diameter * diameter : young_modulus * thickness * diameter;
}

enum class StoppingCriterion { load_relative /* (6.8) */, with_reactions /* (6.9) */ };

// "6.8" or "6.9"; anything else is a std::invalid_argument naming the value.
inline StoppingCriterion stopping_criterion(const std::string& name) {
  if (name == "6.9") return StoppingCriterion::with_reactions;
  if (name == "6.8") return StoppingCriterion::load_relative;
  throw std::invalid_argument("criterion must be '6.8' or '6.9', got '" + name + "'");
}

struct StoppingRule {
  StoppingCriterion criterion = StoppingCriterion::with_reactions;
  double rtol = 1e-6;             // ε
  double round_tolerance = 1e-12; // ε_round
  double force_scale = 0;         // E·dH (2D) or E·H² (3D)
  double n_dofs = 1;

  double tolerance(double external_norm, double reaction_norm) const {
    if (criterion == StoppingCriterion::load_relative) return rtol * external_norm;
    return rtol * std::hypot(external_norm, reaction_norm) +
           force_scale / std::sqrt(n_dofs) * round_tolerance;
  }
};

}  // namespace snede
