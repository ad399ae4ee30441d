#include "solvers/ts_ss22.hpp"

#include <petsc/private/tsimpl.h>

#include <cmath>

#include "core/error.hpp"

namespace snede {
namespace {

// ---- The TS type "snede_ss22" -------------------------------------------------------------
//
// One step, with velocity v at half steps (v_{n−½} stored in ts->vec_dot) and a(u) = G(t, u):
//   v_{n+½} = ((1 − ηΔt/2) v_{n−½} + Δt a(u_n)) / (1 + ηΔt/2),   u_{n+1} = u_n + Δt v_{n+½}.
// This is the central difference (2.62) with C = ηM and M diagonal:
//   M (u_{n+1} − 2u_n + u_{n−1})/Δt² + C (u_{n+1} − u_{n−1})/(2Δt) = f(u_n).
//
// Equivalence with SS22 (2.56)–(2.60) for θ₁ = ½, θ₂ = 0 (Zienkiewicz & Taylor ch. 17, the
// claim of §2.5). With θ₂ = 0, (2.58) reads, for a force f(ū) = −Kū − f_ext,
//   (M + ½ΔtC) ä = f(ū_n) − C v_n,   ū_n = u_n + ½Δt v_n,
// and (2.59)–(2.60) give u_{n+1} = u_n + Δt v_n + ½Δt² ä and v_{n+1} = v_n + Δt ä. Hence
//   ū_{n+1} = u_{n+1} + ½Δt v_{n+1} = ū_n + Δt (v_n + Δt ä) = ū_n + Δt v_{n+1},
//   (v_{n+1} − v_n)/Δt = ä = (M⁻¹f(ū_n) − η v_n)/(1 + ηΔt/2)
//     ⇔ v_{n+1} = ((1 − ηΔt/2) v_n + Δt M⁻¹ f(ū_n)) / (1 + ηΔt/2).
// So SS22's weighted average ū_n and velocity v_n obey exactly the update above, with
// u_n ↔ ū_n and v_{n−½} ↔ v_n: the schemes produce the same sequence (for any force f,
// linear or not) when started from u₀ = ū₀ = u₀ˢˢ + ½Δt v₀ˢˢ, and at rest they coincide, so
// their equilibria and stability limit Δt ≤ 2/√λ_max(M⁻¹K) (§4.1) are the same.

struct SS22 {
  Vec acceleration = nullptr;
  PetscReal damping = 0;  // η
};

SS22& data_of(TS ts) { return *static_cast<SS22*>(ts->data); }


PetscErrorCode ss22_setup(TS ts) {
  return petsc_callback("TSSetUp_SS22", [&] {
    if (!ts->vec_dot) {  // no TS2SetSolution: start at rest
      SNEDE_PETSC(VecDuplicate(ts->vec_sol, &ts->vec_dot));
      SNEDE_PETSC(VecZeroEntries(ts->vec_dot));
    }
    SNEDE_PETSC(VecDuplicate(ts->vec_sol, &data_of(ts).acceleration));
  });
}

PetscErrorCode ss22_reset(TS ts) {
  return petsc_callback("TSReset_SS22", [&] { SNEDE_PETSC(VecDestroy(&data_of(ts).acceleration)); });
}

PetscErrorCode ss22_destroy(TS ts) {
  return petsc_callback("TSDestroy_SS22", [&] {
    SNEDE_PETSC(ss22_reset(ts));
    delete static_cast<SS22*>(ts->data);
    ts->data = nullptr;
  });
}

PetscErrorCode ss22_step(TS ts) {
  return petsc_callback("TSStep_SS22", [&] {
    SS22& s = data_of(ts);
    const PetscReal dt = ts->time_step;
    const PetscReal half_damping = 0.5 * s.damping * dt;
    SNEDE_PETSC(TSPreStage(ts, ts->ptime));
    SNEDE_PETSC(TSComputeRHSFunction(ts, ts->ptime, ts->vec_sol, s.acceleration));
    const PetscReal keep = (1 - half_damping) / (1 + half_damping), push = dt / (1 + half_damping);
    SNEDE_PETSC(VecAXPBY(ts->vec_dot, push, keep, s.acceleration));
    SNEDE_PETSC(VecAXPY(ts->vec_sol, dt, ts->vec_dot));
    SNEDE_PETSC(TSPostStage(ts, ts->ptime, 0, &ts->vec_sol));
    ts->ptime += dt;
  });
}

PetscErrorCode ss22_set_from_options(TS ts, PetscOptionItems* PetscOptionsObject) {
  return petsc_callback("TSSetFromOptions_SS22", [&] {
    SS22& s = data_of(ts);
    SNEDE_PETSC(PetscOptionsReal("-ts_ss22_damping", "Mass-proportional damping eta (1/s)", "set_ss22_damping",
                                 s.damping, &s.damping, nullptr));
    require_valid_damping(s.damping);
  });
}

PetscErrorCode ss22_view(TS ts, PetscViewer viewer) {
  return petsc_callback("TSView_SS22", [&] {
    PetscBool ascii = PETSC_FALSE;
    SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(viewer), PETSCVIEWERASCII, &ascii));
    if (ascii)
      SNEDE_PETSC(PetscViewerASCIIPrintf(viewer, "  explicit SS22 (theta1 = 1/2, theta2 = 0), damping eta = %g 1/s\n",
                                         static_cast<double>(data_of(ts).damping)));
  });
}

PetscErrorCode create_ss22(TS ts) {
  return petsc_callback("TSCreate_SS22", [&] {
    ts->ops->setup = ss22_setup;
    ts->ops->step = ss22_step;
    ts->ops->reset = ss22_reset;
    ts->ops->destroy = ss22_destroy;
    ts->ops->setfromoptions = ss22_set_from_options;
    ts->ops->view = ss22_view;
    ts->usessnes = PETSC_FALSE;
    ts->default_adapt_type = TSADAPTNONE;
    ts->data = new SS22{};
  });
}

void require_ss22(TS ts) {
  PetscBool is_ss22 = PETSC_FALSE;
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(ts), ts_ss22, &is_ss22));
  if (!is_ss22) throw std::invalid_argument(std::string("the TS is not of type ") + ts_ss22);
}

}  // namespace

void require_valid_damping(double damping) {
  require(damping >= 0 && std::isfinite(damping), "damping η (1/s)", "finite and ≥ 0", damping);
}

void register_ts_ss22() {
  SNEDE_PETSC(TSInitializePackage());
  PetscErrorCode (*existing)(TS) = nullptr;
  SNEDE_PETSC(PetscFunctionListFind(TSList, ts_ss22, &existing));
  if (!existing) SNEDE_PETSC(TSRegister(ts_ss22, create_ss22));
}

void set_ss22_damping(TS ts, double damping) {
  require_ss22(ts);
  require_valid_damping(damping);
  data_of(ts).damping = damping;
}

double ss22_damping(TS ts) {
  require_ss22(ts);
  return data_of(ts).damping;
}

void set_up_ss22(TS ts, const Ss22Setup& setup) {
  register_ts_ss22();
  SNEDE_PETSC(TSSetOptionsPrefix(ts, setup.options_prefix.c_str()));
  SNEDE_PETSC(TSSetType(ts, ts_ss22));
  set_ss22_damping(ts, setup.damping);
  SNEDE_PETSC(TSSetApplicationContext(ts, setup.context));
  SNEDE_PETSC(TSSetRHSFunction(ts, nullptr, setup.acceleration, setup.context));
  SNEDE_PETSC(TSSetPostStep(ts, setup.post_step));
  SNEDE_PETSC(TS2SetSolution(ts, setup.displacement, setup.velocity));
  SNEDE_PETSC(TSSetTime(ts, 0.0));
  SNEDE_PETSC(TSSetTimeStep(ts, setup.dt));
  SNEDE_PETSC(TSSetMaxSteps(ts, PETSC_MAX_INT));  // no cap unless -<prefix>ts_max_steps
  SNEDE_PETSC(TSSetMaxTime(ts, PETSC_MAX_REAL));
  SNEDE_PETSC(TSSetExactFinalTime(ts, TS_EXACTFINALTIME_STEPOVER));
  SNEDE_PETSC(TSSetFromOptions(ts));
  PetscBool is_ss22 = PETSC_FALSE;
  SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(ts), ts_ss22, &is_ss22));
  if (!is_ss22)
    throw std::invalid_argument("dynamic relaxation integrates with the TS type " + std::string(ts_ss22) + "; -" +
                                setup.options_prefix + "ts_type must not change it");
  PetscReal dt = 0;
  SNEDE_PETSC(TSGetTimeStep(ts, &dt));
  require(positive_finite(dt), "-" + setup.options_prefix + "ts_dt", "positive and finite", dt);
}

}  // namespace snede
