#include "needle/friction_profile.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace snede {

FrictionProfile::FrictionProfile(std::vector<double> distances, std::vector<double> force_per_length)
    : distances_(std::move(distances)), values_(std::move(force_per_length)) {
  if (distances_.empty() || distances_.size() != values_.size())
    throw std::invalid_argument("friction profile: need as many force values as distances (got " +
                                std::to_string(distances_.size()) + " distances and " +
                                std::to_string(values_.size()) + " values), at least one");
  if (distances_[0] != 0.0)
    throw std::invalid_argument("friction profile: the first distance must be 0 (the tip), got " +
                                std::to_string(distances_[0]));
  for (std::size_t i = 0; i < distances_.size(); ++i) {
    if (!std::isfinite(distances_[i]) || (i > 0 && !(distances_[i] > distances_[i - 1])))
      throw std::invalid_argument("friction profile: distances must be finite and increasing; entry " +
                                  std::to_string(i) + " is " + std::to_string(distances_[i]));
    if (!std::isfinite(values_[i]) || values_[i] < 0)
      throw std::invalid_argument("friction profile: force per length must be finite and non-negative; entry " +
                                  std::to_string(i) + " is " + std::to_string(values_[i]));
  }
  cumulative_.assign(distances_.size(), 0.0);
  for (std::size_t i = 1; i < distances_.size(); ++i)
    cumulative_[i] = cumulative_[i - 1] + 0.5 * (values_[i] + values_[i - 1]) * (distances_[i] - distances_[i - 1]);
}

FrictionProfile FrictionProfile::uniform(double force_per_length) { return FrictionProfile({0.0}, {force_per_length}); }

double FrictionProfile::at(double d) const {
  if (d >= distances_.back()) return values_.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(distances_.begin(), distances_.end(), d) -
                                                 distances_.begin());
  if (i == 0) return values_[0];
  const double t = (d - distances_[i - 1]) / (distances_[i] - distances_[i - 1]);
  return values_[i - 1] + t * (values_[i] - values_[i - 1]);
}

double FrictionProfile::cumulative(double d) const {
  if (d <= 0) return 0.0;
  if (d >= distances_.back()) return cumulative_.back() + values_.back() * (d - distances_.back());
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(distances_.begin(), distances_.end(), d) -
                                                 distances_.begin());
  const double left = distances_[i - 1];
  return cumulative_[i - 1] + 0.5 * (values_[i - 1] + at(d)) * (d - left);
}

double FrictionProfile::integral(double a, double b) const { return cumulative(b) - cumulative(a); }

}  // namespace snede
