// A dynamic relaxation's settings (dynamic_relaxation.hpp): the damping η of C = η M, the time
// step, the options prefix and the solver's own PETSc options.
#pragma once

#include <optional>
#include <string>

#include "core/error.hpp"
#include "core/solver_options.hpp"
#include "solvers/ts_ss22.hpp"

namespace snede {

struct DynamicRelaxationOptions {
  double damping = 0;  // η ≥ 0 (1/s); §4.1: fastest at 2√λ₁, λ₁ the lowest eigenvalue of M⁻¹K
  // The time step (s); unset: the CFL estimate (2.61), renewed as the mesh changes size.
  std::optional<double> dt;
  std::string options_prefix = "dynamic_";
  OptionList petsc_options;  // this solver's PETSc options, without the prefix

  // Every setting with its name: the one list that bindings read.
  template <class Visit>
  static void visit_fields(Visit&& visit) {
    visit("damping", &DynamicRelaxationOptions::damping);
    visit("dt", &DynamicRelaxationOptions::dt);
    visit("options_prefix", &DynamicRelaxationOptions::options_prefix);
    visit("petsc_options", &DynamicRelaxationOptions::petsc_options);
  }

  // std::invalid_argument naming a damping or time step that is negative or not finite.
  void validate() const {
    require_valid_damping(damping);
    if (dt) require(positive_finite(*dt), "dt", "positive and finite (or unset: the CFL estimate)", *dt);
  }
};

}  // namespace snede
