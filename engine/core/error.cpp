#include "core/error.hpp"

#include <sstream>

namespace snede {

void check_petsc(PetscErrorCode code, const char* call, const char* file, int line) {
  if (code == 0) return;
  const char* generic = nullptr;
  char* specific = nullptr;
  PetscErrorMessage(code, &generic, &specific);
  std::ostringstream message;
  message << "PETSc error " << static_cast<int>(code);
  if (generic) message << " (" << generic << ")";
  if (specific && specific[0]) message << ": " << specific;
  message << " [in " << call << " at " << file << ":" << line << "]";
  throw PetscException(code, message.str());
}

}  // namespace snede
