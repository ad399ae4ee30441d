#include "core/options.hpp"

#include "core/error.hpp"

namespace snede {

std::optional<double> option_real(const std::string& name) {
  PetscReal value = 0;
  PetscBool set = PETSC_FALSE;
  SNEDE_PETSC(PetscOptionsGetReal(nullptr, nullptr, name.c_str(), &value, &set));
  if (!set) return std::nullopt;
  return static_cast<double>(value);
}

bool option_used(const std::string& name) {
  PetscBool used = PETSC_FALSE;
  SNEDE_PETSC(PetscOptionsUsed(nullptr, name.c_str(), &used));
  return used == PETSC_TRUE;
}

}  // namespace snede
