#include "core/solver_options.hpp"

#include <cctype>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"

namespace snede {
namespace {

// The name without its leading '-'; throws if nothing usable is left.
std::string bare_option_name(const std::string& name) {
  const std::size_t start = name.find_first_not_of('-');
  if (start == std::string::npos || name.find_first_of(" \t\n\r\f\v") != std::string::npos)
    throw std::invalid_argument("PETSc option names must be non-empty and without white space, got '" + name + "'");
  return name.substr(start);
}

PetscErrorCode destroy_database(void* database) {
  auto options = static_cast<PetscOptions>(database);
  return PetscOptionsDestroy(&options);
}

}  // namespace

SolverOptions::SolverOptions(const std::string& prefix, const OptionList& options) {
  OptionList own;
  for (const auto& [name, value] : options) own.emplace_back("-" + prefix + bare_option_name(name), value);
  SNEDE_PETSC(PetscContainerCreate(PETSC_COMM_SELF, holder_.out()));
  try {
    SNEDE_PETSC(PetscContainerSetUserDestroy(holder_, destroy_database));
    SNEDE_PETSC(PetscOptionsCreate(&database_));
    SNEDE_PETSC(PetscContainerSetPointer(holder_, database_));
    for (const auto& [name, value] : own)
      SNEDE_PETSC(PetscOptionsSetValue(database_, name.c_str(), value.empty() ? nullptr : value.c_str()));
    // The global database as text ("-name value -flag ..."), inserted last so that it wins.
    char* text = nullptr;
    SNEDE_PETSC(PetscOptionsGetAll(nullptr, &text));
    const std::string global = text;
    SNEDE_PETSC(PetscFree(text));
    SNEDE_PETSC(PetscOptionsInsertString(database_, global.c_str()));
    std::istringstream tokens(global);
    for (std::string token; tokens >> token;) {
      PetscBool is_name = PETSC_FALSE;
      SNEDE_PETSC(PetscOptionsValidKey(token.c_str(), &is_name));
      if (is_name) global_names_.push_back(token.substr(1));
    }
  } catch (...) {
    holder_.reset();
    throw;
  }
}

SolverOptions::~SolverOptions() = default;

void SolverOptions::use_for(PetscObject object) const {
  SNEDE_PETSC(PetscObjectSetOptions(object, database_));
  SNEDE_PETSC(PetscObjectCompose(object, "snede_solver_options", reinterpret_cast<PetscObject>(holder_.get())));
}

std::optional<std::string> SolverOptions::string_option(const std::string& name) const {
  char value[256] = {};
  PetscBool set = PETSC_FALSE;
  SNEDE_PETSC(PetscOptionsGetString(database_, nullptr, ("-" + name).c_str(), value, sizeof value, &set));
  if (!set) return std::nullopt;
  return std::string(value);
}

bool SolverOptions::bool_option(const std::string& name, bool fallback) const {
  const std::optional<std::string> text = string_option(name);
  if (!text) return fallback;
  std::string value = *text;
  for (char& c : value) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (value.empty() || value == "1" || value == "true" || value == "yes" || value == "on") return true;
  if (value == "0" || value == "false" || value == "no" || value == "off") return false;
  throw std::invalid_argument("-" + name + " must be true or false (1/0, yes/no, on/off), got '" + *text + "'");
}

double SolverOptions::number_option(const std::string& name, double fallback) const {
  const std::optional<std::string> text = string_option(name);
  if (!text) return fallback;
  try {
    std::size_t used = 0;
    const double value = std::stod(*text, &used);
    if (used != text->size()) throw std::invalid_argument(*text);
    return value;
  } catch (const std::exception&) {
    throw std::invalid_argument("-" + name + " must be a number, got '" + *text + "'");
  }
}

void SolverOptions::renew_initial_guess(KSP ksp) const {
  const char* prefix = nullptr;
  SNEDE_PETSC(KSPGetOptionsPrefix(ksp, &prefix));
  // KSPGetGuess would give a KSP without one an empty guess, which KSPSolve then consults.
  if (!string_option(std::string(prefix ? prefix : "") + "ksp_guess_type")) return;
  KSPGuess kept = nullptr;
  SNEDE_PETSC(KSPGetGuess(ksp, &kept));
  KSPGuessType type = nullptr;
  SNEDE_PETSC(KSPGuessGetType(kept, &type));
  if (!type) return;
  const std::string kept_type = type;
  KSPGuess fresh = nullptr;
  SNEDE_PETSC(KSPGuessCreate(PetscObjectComm(reinterpret_cast<PetscObject>(ksp)), &fresh));
  use_for(fresh);
  SNEDE_PETSC(PetscObjectSetOptionsPrefix(reinterpret_cast<PetscObject>(fresh), prefix));
  SNEDE_PETSC(KSPGuessSetType(fresh, kept_type.c_str()));
  SNEDE_PETSC(KSPGuessSetFromOptions(fresh));
  SNEDE_PETSC(KSPSetGuess(ksp, fresh));  // the KSP holds its own reference
  SNEDE_PETSC(KSPGuessDestroy(&fresh));
}

void SolverOptions::set_string_option(const std::string& name, const std::string& value) {
  SNEDE_PETSC(PetscOptionsSetValue(database_, ("-" + name).c_str(), value.c_str()));
}

void SolverOptions::mark_read_options_used() const {
  for (const std::string& name : global_names_) {
    PetscBool read = PETSC_FALSE, set = PETSC_FALSE;
    SNEDE_PETSC(PetscOptionsUsed(database_, name.c_str(), &read));
    // Looking an option up is what marks it used.
    if (read) SNEDE_PETSC(PetscOptionsHasName(nullptr, nullptr, ("-" + name).c_str(), &set));
  }
}

}  // namespace snede
