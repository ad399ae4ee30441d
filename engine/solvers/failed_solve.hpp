// What a solve that failed with a PETSc error must repair before its objects are reused or
// destroyed.
//
// PETSc 3.18's PCMG (and the PCs built on it: GAMG, HMG) lends its finest level the vectors
// of each application and takes them back only when the cycle succeeds. After an error in the
// cycle (a smoother that cannot work on a shell, a failing operator) the level still holds the
// caller's right-hand side, which the next application and PCReset_MG destroy although the
// outer KSP owns it: the vector is freed twice, and destroying the solver crashes (SEGV).
#pragma once

#include <petscksp.h>

namespace snede {

// Takes the lent vectors back from `pc` if it is a multigrid PC; any other PC is left as it is.
void take_back_lent_vectors(PC pc) noexcept;

// Runs `solve` (a KSPSolve or SNESSolve through `ksp`); if it throws, `ksp`'s PC first gets its
// lent vectors back.
template <class Solve>
void solve_through(KSP ksp, Solve&& solve) {
  try {
    solve();
  } catch (...) {
    PC pc = nullptr;
    if (!KSPGetPC(ksp, &pc)) take_back_lent_vectors(pc);
    throw;
  }
}

}  // namespace snede
