// The PETSc options database of one solver. By default a PETSc object reads PETSc's global
// database, which every solver with the same prefix shares: options a script gives one
// solver (petsc_options=, a line search) written there would reach the next solver too.
// Each solver therefore reads a private database holding its own options under its prefix,
// then a copy of the global database (command line, PETSC_OPTIONS, petsc4py's
// PETSc.Options) inserted over them, so that the command line still wins.
#pragma once

#include <petscksp.h>
#include <petscsys.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/petsc_handle.hpp"

namespace snede {

// PETSc options as (name, value): the name without the solver's prefix (leading '-' are
// ignored), the value empty for a flag.
using OptionList = std::vector<std::pair<std::string, std::string>>;

class SolverOptions {
 public:
  // Throws std::invalid_argument naming an option name that is empty or holds white space.
  SolverOptions(const std::string& prefix, const OptionList& options);
  ~SolverOptions();
  SolverOptions(const SolverOptions&) = delete;
  SolverOptions& operator=(const SolverOptions&) = delete;

  // Makes `object` read this database; call it before anything reads the object's options.
  // The object keeps the database alive, since a petsc4py handle may outlive the solver.
  // Of the children PETSc 3.18 creates, the KSP of a SNES, the PC of a KSP and the SNES of a
  // TS take their parent's database; a SNES's line search and a TS's adaptor do not, so
  // every object a solver configures is passed here.
  void use_for(PetscObject object) const;
  template <class Object>
  void use_for(Object object) const {
    use_for(reinterpret_cast<PetscObject>(object));
  }
  template <class Object, PetscErrorCode (*destroy)(Object*)>
  void use_for(const PetscHandle<Object, destroy>& handle) const {
    use_for(handle.get());
  }

  // The value of option `name` (with its prefix, without '-') in this database, if set.
  std::optional<std::string> string_option(const std::string& name) const;
  // The value of the logical option `name` as PETSc spells it (given without a value: true;
  // 1/0, true/false, yes/no, on/off in any case), or `fallback` if it is not set;
  // std::invalid_argument naming the option for any other value.
  bool bool_option(const std::string& name, bool fallback) const;
  // The value of the numeric option `name`, or `fallback` if it is not set; std::invalid_argument
  // naming the option for a value that is not a number.
  double number_option(const std::string& name, double fallback) const;
  // Sets option `name` (with its prefix, without '-') in this database only.
  void set_string_option(const std::string& name, const std::string& value);

  // KSPReset and SNESReset keep a KSP's initial-guess object (-<prefix>ksp_guess_type fischer
  // or pod) with the vectors of the mesh before a change: the first solve after a needle's
  // refinement failed with PETSc error 75 ("Incompatible vector local lengths"). Replaces it by
  // an empty guess of the same type read from this database (nothing without such an option).
  void renew_initial_guess(KSP ksp) const;
  // Marks the global options this solver has read as used in the global database, so that
  // -options_left lists only the options that no solver read.
  void mark_read_options_used() const;

 private:
  ContainerHandle holder_;  // owns the database; every object using it holds a reference
  PetscOptions database_ = nullptr;
  std::vector<std::string> global_names_;  // the copied global options, without '-'
};

}  // namespace snede
