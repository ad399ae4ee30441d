#include "solvers/failed_solve.hpp"

#include <petsc/private/pcimpl.h>
#include <petsc/private/pcmgimpl.h>

namespace snede {
namespace {

// Whether a smoother's PC changes the right-hand side before it solves (PETSc's own test,
// PCPreSolveChangeRHS, is not exported): PCMG then gives the finest level a copy it owns.
bool changes_right_hand_side(KSP smoother) noexcept {
  PC pc = nullptr;
  if (!smoother || KSPGetPC(smoother, &pc)) return false;
  PetscErrorCode (*changes)(PC, PetscBool*) = nullptr;
  if (PetscObjectQueryFunction(reinterpret_cast<PetscObject>(pc), "PCPreSolveChangeRHS_C", &changes) || !changes)
    return false;
  PetscBool change = PETSC_FALSE;
  return !changes(pc, &change) && change;
}

}  // namespace

void take_back_lent_vectors(PC pc) noexcept {
  if (!pc) return;
  // Every PC built on PCMG has this method, and a PC_MG as its data.
  PetscErrorCode (*get_levels)(PC, PetscInt*) = nullptr;
  if (PetscObjectQueryFunction(reinterpret_cast<PetscObject>(pc), "PCMGGetLevels_C", &get_levels) || !get_levels)
    return;
  const auto* mg = static_cast<const PC_MG*>(pc->data);
  if (!mg || !mg->levels || mg->nlevels < 1) return;
  PC_MG_Levels* finest = mg->levels[mg->nlevels - 1];
  if (!changes_right_hand_side(finest->smoothd) && !changes_right_hand_side(finest->smoothu)) {
    finest->b = nullptr;
    finest->B = nullptr;
  }
  finest->x = nullptr;
  finest->X = nullptr;
}

}  // namespace snede
