// Error handling: PETSc error codes become C++ exceptions (and, through the bindings,
// Python exceptions) so that no PETSc failure aborts the process.
#pragma once

#include <petscsys.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace snede {

// A PETSc call returned a non-zero error code; what() carries PETSc's own message.
class PetscException : public std::runtime_error {
 public:
  PetscException(PetscErrorCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  PetscErrorCode code() const noexcept { return code_; }

 private:
  PetscErrorCode code_;
};

// A file could not be created, opened or written (a folder deleted or read-only, a full disk);
// Python sees it as snede.FileError, an OSError.
class FileError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws PetscException with PETSc's text for `code` if it is non-zero; `call` names the call.
void check_petsc(PetscErrorCode code, const char* call, const char* file, int line);

// Throws std::invalid_argument "<what> must be <expectation>, got <value>" unless ok.
inline void require(bool ok, const std::string& what, const char* expectation, double value) {
  if (ok) return;
  std::ostringstream message;
  message << what << " must be " << expectation << ", got " << value;
  throw std::invalid_argument(message.str());
}

inline bool positive_finite(double x) { return x > 0 && std::isfinite(x); }

// Throws std::invalid_argument "<what>: <point_name> i coordinate k is x, not finite" for the
// first non-finite number of `coordinates`, read as points of `dim` coordinates each.
inline void require_finite_points(const double* coordinates, std::size_t size, int dim, const std::string& what,
                                  const char* point_name) {
  for (std::size_t i = 0; i < size; ++i) {
    if (std::isfinite(coordinates[i])) continue;
    std::ostringstream message;
    message << what << ": " << point_name << " " << i / dim << " coordinate " << i % dim << " is "
            << coordinates[i] << ", not finite";
    throw std::invalid_argument(message.str());
  }
}

// Runs `body` inside a callback that PETSc calls (MatMult of a shell, SNES function, ...):
// a C++ exception becomes a PETSc error carrying its message, so it travels back through
// PETSc to the caller instead of unwinding through C frames.
template <class Body>
PetscErrorCode petsc_callback(const char* name, Body&& body) noexcept {
  try {
    body();
    return 0;
  } catch (const std::exception& e) {
    return PetscError(PETSC_COMM_SELF, __LINE__, name, __FILE__, PETSC_ERR_LIB, PETSC_ERROR_INITIAL, "%s", e.what());
  }
}

// The snede object a PETSc callback belongs to. A petsc4py handle can keep a PETSc object
// alive after its snede owner was deleted; the owner then clears its contexts, and a call
// through the handle raises this error instead of reaching freed memory.
template <class Owner>
Owner& callback_owner(void* context, const char* owner_name) {
  if (!context)
    throw std::runtime_error(std::string("this PETSc object belonged to a snede ") + owner_name +
                             " that has been deleted; keep the " + owner_name + " alive while you use it");
  return *static_cast<Owner*>(context);
}

// The error a callback left behind by a deleted owner returns (PETSc keeps a non-null context
// when a callback is replaced with a null one, so owners install these instead).
inline PetscErrorCode orphaned_callback_error(const char* owner_name) {
  return petsc_callback(owner_name, [&] { callback_owner<int>(nullptr, owner_name); });
}

}  // namespace snede

// Wrap every PETSc call made by the engine: SNEDE_PETSC(VecCreate(comm, &v));
#define SNEDE_PETSC(...) ::snede::check_petsc((__VA_ARGS__), #__VA_ARGS__, __FILE__, __LINE__)
