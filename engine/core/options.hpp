// Reading PETSc options (command line, PETSC_OPTIONS, petsc4py.PETSc.Options) from the engine.
#pragma once

#include <optional>
#include <string>

namespace snede {

// The real value of option `name` (with its leading '-'), or nullopt if it is not set.
// A value that is not a number raises PetscException carrying PETSc's message.
std::optional<double> option_real(const std::string& name);

// Whether some PETSc object has read option `name` (without its leading '-') from the global
// database, as -options_left reports at exit.
bool option_used(const std::string& name);

}  // namespace snede
