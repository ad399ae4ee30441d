// The friction profile of §6.3.2 (Figure 6.4): friction force per unit shaft length as a
// function of the distance from the needle tip, measured along the shaft in deformed
// coordinates. Piecewise linear between samples, constant beyond the last one.
#pragma once

#include <span>
#include <vector>

namespace snede {

class FrictionProfile {
 public:
  // distances: increasing, starting at 0 (the tip), finite; force_per_length: as many values,
  // non-negative and finite (N/m; for a plane-stress sheet, per metre of shaft across the
  // whole thickness). Throws std::invalid_argument naming the offending entry.
  FrictionProfile(std::vector<double> distances, std::vector<double> force_per_length);
  // A profile of constant force per length.
  static FrictionProfile uniform(double force_per_length);

  const std::vector<double>& distances() const { return distances_; }
  const std::vector<double>& force_per_length() const { return values_; }
  // Force per length at distance d ≥ 0 from the tip.
  double at(double d) const;
  // ∫_a^b of the profile (exact for the piecewise-linear profile), 0 ≤ a ≤ b.
  double integral(double a, double b) const;

 private:
  // ∫_0^d of the profile.
  double cumulative(double d) const;

  std::vector<double> distances_;
  std::vector<double> values_;
  std::vector<double> cumulative_;  // ∫_0^distances_[i]
};

}  // namespace snede
