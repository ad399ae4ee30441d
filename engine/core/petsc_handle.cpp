#include "core/petsc_handle.hpp"

#include <atomic>
#include <cstdio>

namespace snede {
namespace {
std::atomic<long> failures{0};
}  // namespace

void report_destroy_failure(PetscErrorCode code, const char* type) noexcept {
  ++failures;
  const char* generic = nullptr;
  PetscErrorMessage(code, &generic, nullptr);
  std::fprintf(stderr, "snede: destroying a PETSc %s failed with error %d (%s); its memory may be lost\n", type,
               static_cast<int>(code), generic ? generic : "unknown error");
}

long destroy_failures() noexcept { return failures.load(); }

}  // namespace snede
