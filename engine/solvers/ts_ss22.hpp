// The PETSc TS type "snede_ss22": explicit SS22 (θ₁ = ½, θ₂ = 0), i.e. central differences,
// for second-order ODEs ü = G(t, u) − η u̇ with G from TSSetRHSFunction, the velocity from
// TS2SetSolution and mass-proportional damping η (§2.5). The derivation of its equivalence
// with (2.56)–(2.60) is at the top of ts_ss22.cpp.
#pragma once

#include <petscts.h>

#include <string>

namespace snede {

inline constexpr const char* ts_ss22 = "snede_ss22";

// Registers "snede_ss22" with PETSc (idempotent).
void register_ts_ss22();
// η (1/s) of a TS of type snede_ss22; throws std::invalid_argument for another type or η < 0.
void set_ss22_damping(TS ts, double damping);
double ss22_damping(TS ts);

// Throws std::invalid_argument naming η unless it is finite and ≥ 0.
void require_valid_damping(double damping);

// What a dynamic relaxation gives its TS.
struct Ss22Setup {
  std::string options_prefix;
  double damping = 0;           // η
  double dt = 0;                // the time step before the options
  void* context = nullptr;      // the application context and the RHS function's
  TSRHSFunction acceleration = nullptr;
  PetscErrorCode (*post_step)(TS) = nullptr;
  Vec displacement = nullptr, velocity = nullptr;
};
// Makes `ts` a snede_ss22 integrator from time 0 with these (no step cap, no final time), then
// applies the options under the prefix; throws std::invalid_argument if they change the type
// or leave the step not positive and finite.
void set_up_ss22(TS ts, const Ss22Setup& setup);

}  // namespace snede
