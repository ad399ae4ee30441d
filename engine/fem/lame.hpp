// Lamé parameters from Young's modulus and Poisson's ratio, with the user-facing checks.
#pragma once

namespace snede {

struct Lame {
  double lambda;
  double mu;
};

// Throws std::invalid_argument naming the value for E ≤ 0, ν outside (−1, ½) or a
// non-finite value.
Lame lame_from_young_poisson(double young, double poisson);

// Throws std::invalid_argument naming `what` unless value is finite and > 0.
void require_positive(const char* what, double value);

}  // namespace snede
