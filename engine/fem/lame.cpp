#include "fem/lame.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace snede {

void require_positive(const char* what, double value) {
  if (std::isfinite(value) && value > 0) return;
  std::ostringstream message;
  message << what << " must be positive and finite, got " << value;
  throw std::invalid_argument(message.str());
}

Lame lame_from_young_poisson(double young, double poisson) {
  require_positive("Young's modulus E", young);
  if (!(std::isfinite(poisson) && poisson > -1 && poisson < 0.5)) {
    std::ostringstream message;
    message << "Poisson's ratio nu must lie in (-1, 0.5), got " << poisson;
    throw std::invalid_argument(message.str());
  }
  return {young * poisson / ((1 + poisson) * (1 - 2 * poisson)), young / (2 * (1 + poisson))};
}

}  // namespace snede
