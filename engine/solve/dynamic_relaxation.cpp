#include "solve/dynamic_relaxation.hpp"

#include <petsc/private/tsimpl.h>
#include <petsctime.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "solve/stopping.hpp"

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

void require_damping(double damping) {
  if (!(damping >= 0) || !std::isfinite(damping)) {
    std::ostringstream message;
    message << "damping η must be a finite number ≥ 0 (1/s), got " << damping;
    throw std::invalid_argument(message.str());
  }
}

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
    SNEDE_PETSC(VecAXPBY(ts->vec_dot, dt / (1 + half_damping), (1 - half_damping) / (1 + half_damping), s.acceleration));
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
    require_damping(s.damping);
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

// ---- Helpers of DynamicRelaxation -------------------------------------------------------

// A blown-up state (§4.4.1).
constexpr double blow_up_norm = 1e15;

double norm_of(Vec v) {
  PetscReal n = 0;
  SNEDE_PETSC(VecNorm(v, NORM_2, &n));
  return n;
}

double wall_seconds() {
  PetscLogDouble t = 0;
  SNEDE_PETSC(PetscTime(&t));
  return t;
}

std::vector<double> values_of(Vec v) {
  const PetscScalar* data = nullptr;
  PetscInt n = 0;
  SNEDE_PETSC(VecGetLocalSize(v, &n));
  SNEDE_PETSC(VecGetArrayRead(v, &data));
  std::vector<double> values(data, data + n);
  SNEDE_PETSC(VecRestoreArrayRead(v, &data));
  return values;
}

void set_values(Vec v, std::span<const double> values) {
  PetscInt n = 0;
  SNEDE_PETSC(VecGetLocalSize(v, &n));
  if (values.size() != static_cast<std::size_t>(n))
    throw std::invalid_argument("expected " + std::to_string(n) + " values (n_points × dim), got " +
                                std::to_string(values.size()));
  PetscScalar* data = nullptr;
  SNEDE_PETSC(VecGetArray(v, &data));
  std::copy(values.begin(), values.end(), data);
  SNEDE_PETSC(VecRestoreArray(v, &data));
}

void project_onto_allowed_motions(const Model& model, Vec v) {
  PetscScalar* data = nullptr;
  PetscInt n = 0;
  SNEDE_PETSC(VecGetLocalSize(v, &n));
  SNEDE_PETSC(VecGetArray(v, &data));
  model.constraints().project({data, static_cast<std::size_t>(n)});
  SNEDE_PETSC(VecRestoreArray(v, &data));
}

// Diameter of the inscribed sphere (circle): 2r = 2·dim·|τ| / Σ facet measures.
double inscribed_diameter(int dim, std::span<const double> corners) {
  const double measure = std::abs(signed_volume(dim, corners));
  auto point = [&](int i) { return Eigen::Vector3d(corners[i * dim], corners[i * dim + 1], dim == 3 ? corners[i * dim + 2] : 0.0); };
  double facets = 0;
  for (int i = 0; i <= dim; ++i) {
    int other[3], k = 0;
    for (int j = 0; j <= dim; ++j)
      if (j != i) other[k++] = j;
    facets += dim == 2 ? (point(other[0]) - point(other[1])).norm()
                       : 0.5 * (point(other[1]) - point(other[0])).cross(point(other[2]) - point(other[0])).norm();
  }
  return 2 * dim * measure / facets;
}

// Modulus of the dilatational wave: λ + 2μ in 3D, E/(1 − ν²) = 4μ(λ+μ)/(λ+2μ) in plane stress.
double dilatational_modulus(const Material& material, int dim) {
  const Lame lame = std::visit([](const auto& m) { return m.lame; }, material);
  return dim == 3 ? lame.lambda + 2 * lame.mu : 4 * lame.mu * (lame.lambda + lame.mu) / (lame.lambda + 2 * lame.mu);
}

// Restores TS max steps (the user's cap, -<prefix>ts_max_steps) however a solve ends.
class MaxStepsGuard {
 public:
  MaxStepsGuard(TS ts, PetscInt cap) : ts_(ts), cap_(cap) {}
  ~MaxStepsGuard() { TSSetMaxSteps(ts_, cap_); }

 private:
  TS ts_;
  PetscInt cap_;
};

}  // namespace

void register_ts_ss22() {
  SNEDE_PETSC(TSInitializePackage());
  PetscErrorCode (*existing)(TS) = nullptr;
  SNEDE_PETSC(PetscFunctionListFind(TSList, ts_ss22, &existing));
  if (!existing) SNEDE_PETSC(TSRegister(ts_ss22, create_ss22));
}

void set_ss22_damping(TS ts, double damping) {
  require_ss22(ts);
  require_damping(damping);
  data_of(ts).damping = damping;
}

double ss22_damping(TS ts) {
  require_ss22(ts);
  return data_of(ts).damping;
}

// ---- DynamicRelaxation --------------------------------------------------------------------

DynamicRelaxation::DynamicRelaxation(Model& model, double damping_eta, double dt, const std::string& options_prefix)
    : model_(model) {
  require_damping(damping_eta);
  if (!(dt >= 0) || !std::isfinite(dt)) {
    std::ostringstream message;
    message << "dt must be positive and finite (or 0 for the CFL estimate), got " << dt;
    throw std::invalid_argument(message.str());
  }
  register_ts_ss22();
  try {
    generation_ = model_.generation();
    Vec u = model_.displacement();
    SNEDE_PETSC(VecDuplicate(u, &velocity_));
    SNEDE_PETSC(VecZeroEntries(velocity_));
    SNEDE_PETSC(VecDuplicate(u, &inverse_mass_));
    SNEDE_PETSC(VecDuplicate(u, &residual_));
    SNEDE_PETSC(TSCreate(PETSC_COMM_SELF, &ts_));
    SNEDE_PETSC(TSSetOptionsPrefix(ts_, options_prefix.c_str()));
    SNEDE_PETSC(TSSetType(ts_, ts_ss22));
    set_ss22_damping(ts_, damping_eta);
    SNEDE_PETSC(TSSetApplicationContext(ts_, this));
    SNEDE_PETSC(TSSetRHSFunction(ts_, nullptr, acceleration_callback, this));
    SNEDE_PETSC(TSSetPostStep(ts_, post_step_callback));
    SNEDE_PETSC(TS2SetSolution(ts_, u, velocity_));
    const double default_dt = dt > 0 ? dt : cfl_time_step();
    SNEDE_PETSC(TSSetTime(ts_, 0.0));
    SNEDE_PETSC(TSSetTimeStep(ts_, default_dt));
    SNEDE_PETSC(TSSetMaxSteps(ts_, PETSC_MAX_INT));  // no cap unless -<prefix>ts_max_steps
    SNEDE_PETSC(TSSetMaxTime(ts_, PETSC_MAX_REAL));
    SNEDE_PETSC(TSSetExactFinalTime(ts_, TS_EXACTFINALTIME_STEPOVER));
    SNEDE_PETSC(TSSetFromOptions(ts_));
    PetscBool is_ss22 = PETSC_FALSE;
    SNEDE_PETSC(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(ts_), ts_ss22, &is_ss22));
    if (!is_ss22)
      throw std::invalid_argument("dynamic relaxation integrates with the TS type " + std::string(ts_ss22) + "; -" +
                                  options_prefix + "ts_type must not change it");
    if (!(time_step() > 0) || !std::isfinite(time_step())) {
      std::ostringstream message;
      message << "-" << options_prefix << "ts_dt must be positive and finite, got " << time_step();
      throw std::invalid_argument(message.str());
    }
    follows_cfl_ = dt == 0 && time_step() == default_dt;
  } catch (...) {
    TSDestroy(&ts_);
    VecDestroy(&velocity_);
    VecDestroy(&inverse_mass_);
    VecDestroy(&residual_);
    throw;
  }
}

DynamicRelaxation::~DynamicRelaxation() {
  TSDestroy(&ts_);
  VecDestroy(&velocity_);
  VecDestroy(&inverse_mass_);
  VecDestroy(&residual_);
}

double DynamicRelaxation::cfl_time_step() const {
  const Mesh& mesh = model_.body().mesh();
  double size = std::numeric_limits<double>::infinity();
  for (ElementId e : mesh.cell_ids()) size = std::min(size, inscribed_diameter(mesh.dim(), mesh.corners(e)));
  const double wave_speed =
      std::sqrt(dilatational_modulus(model_.body().material(), mesh.dim()) / model_.body().density());
  return 2 / std::sqrt(3.0) * size / wave_speed;  // (2.61)
}

double DynamicRelaxation::time_step() const {
  PetscReal dt = 0;
  SNEDE_PETSC(TSGetTimeStep(ts_, &dt));
  return dt;
}

void DynamicRelaxation::set_time_step(double dt) {
  if (!(dt > 0) || !std::isfinite(dt)) {
    std::ostringstream message;
    message << "dt must be positive and finite, got " << dt;
    throw std::invalid_argument(message.str());
  }
  SNEDE_PETSC(TSSetTimeStep(ts_, dt));
  follows_cfl_ = false;
}

std::vector<double> DynamicRelaxation::velocity() {
  reissue_sizes_if_mesh_changed();
  return values_of(velocity_);
}

void DynamicRelaxation::set_velocity(std::span<const double> values) {
  reissue_sizes_if_mesh_changed();
  for (double x : values)
    if (!std::isfinite(x)) throw std::invalid_argument("velocity must be finite");
  set_values(velocity_, values);
}

void DynamicRelaxation::reissue_sizes_if_mesh_changed() {
  if (generation_ == model_.generation()) return;
  // The mesh changed size (a cut or a refinement): the velocity is carried over like the
  // displacement (a copy moves with its original, a midpoint with its edge), and the same TS
  // takes the new vectors, so a user's handle and options survive.
  const std::vector<double> old_velocity = values_of(velocity_);
  const auto n_old_points = static_cast<VertexId>(old_velocity.size() / model_.dim());
  const std::vector<double> carried = model_.carried_over(old_velocity, n_old_points);
  SNEDE_PETSC(VecDestroy(&velocity_));
  SNEDE_PETSC(VecDestroy(&inverse_mass_));
  SNEDE_PETSC(VecDestroy(&residual_));
  Vec u = model_.displacement();
  SNEDE_PETSC(VecDuplicate(u, &velocity_));
  SNEDE_PETSC(VecDuplicate(u, &inverse_mass_));
  SNEDE_PETSC(VecDuplicate(u, &residual_));
  set_values(velocity_, carried);
  SNEDE_PETSC(TSReset(ts_));
  SNEDE_PETSC(TS2SetSolution(ts_, u, velocity_));
  generation_ = model_.generation();
  if (follows_cfl_) SNEDE_PETSC(TSSetTimeStep(ts_, cfl_time_step()));
}

void DynamicRelaxation::prepare_state() {
  // Constraints may have been set between calls: put u on them and let v move only along them.
  model_.enforce_constraints(model_.displacement());
  project_onto_allowed_motions(model_, velocity_);
  update_inverse_mass();
}

void DynamicRelaxation::update_inverse_mass() {
  // Lumped masses (§2.5), recomputed per call since elements may change without a size change.
  const std::vector<double> mass = model_.body().lumped_mass();
  std::vector<double> inverse(mass.size() * model_.dim());
  for (std::size_t v = 0; v < mass.size(); ++v)
    for (int k = 0; k < model_.dim(); ++k) inverse[v * model_.dim() + k] = mass[v] > 0 ? 1 / mass[v] : 0.0;
  set_values(inverse_mass_, inverse);
}

SolveResult DynamicRelaxation::step(int n) {
  if (n < 0) throw std::invalid_argument("the number of steps must be ≥ 0, got " + std::to_string(n));
  return advance(n, Mode::steps, 0);
}

SolveResult DynamicRelaxation::run(double rtol, int max_steps) {
  if (!(rtol > 0) || !std::isfinite(rtol)) {
    std::ostringstream message;
    message << "rtol must be positive, got " << rtol;
    throw std::invalid_argument(message.str());
  }
  if (max_steps < 0) throw std::invalid_argument("max_steps must be ≥ 0, got " + std::to_string(max_steps));
  return advance(max_steps, Mode::relaxation, rtol);
}

double DynamicRelaxation::tolerance(double reaction_norm) const {
  if (mode_ != Mode::relaxation) return 0;
  StoppingRule rule;
  rule.criterion = StoppingCriterion::with_reactions;
  rule.rtol = rtol_;
  rule.force_scale = model_.force_scale();
  rule.n_dofs = static_cast<double>(model_.n_dofs());
  return rule.tolerance(external_norm_, reaction_norm);
}

SolveResult DynamicRelaxation::advance(PetscInt n_steps, Mode mode, double rtol) {
  reissue_sizes_if_mesh_changed();
  prepare_state();
  SolveResult result;
  const double start = wall_seconds();
  PetscLogDouble start_flops = 0;
  SNEDE_PETSC(PetscGetFlops(&start_flops));
  mode_ = mode;
  rtol_ = rtol;
  const std::vector<double>& f = model_.external_forces();
  double sum = 0;
  for (double x : f) sum += x * x;
  external_norm_ = std::sqrt(sum);
  history_.clear();
  failure_.clear();
  converged_ = false;

  Vec u = model_.displacement();
  bool already_converged = false;
  if (mode == Mode::relaxation) {
    already_converged = converged_at(u);
    result.initial_residual_norm = checked_residual_norm_;
  }
  if (!already_converged) result.iterations = static_cast<int>(take_steps(n_steps));
  if (mode == Mode::steps) result.initial_residual_norm = history_.empty() ? 0 : history_.front();

  // The verdict is checked on the final state.
  EvaluationReport report;
  model_.residual(u, residual_, report);
  result.residual_norm = norm_of(residual_);
  result.tolerance = tolerance(model_.last_reaction_norm());
  std::string why;
  if (!failure_.empty()) {
    result.reason = failure_;
  } else if (!report.domain_errors.empty() || !std::isfinite(result.residual_norm)) {
    result.reason = "DIVERGED_NONFINITE_STATE";
  } else if (!model_.admissible(u, &why)) {
    result.reason = why;
  } else if (mode == Mode::relaxation) {
    result.converged = already_converged || converged_;
    result.reason = result.converged ? "CONVERGED_FNORM_ABS" : "DIVERGED_MAX_IT";
  } else {
    TSConvergedReason reason = TS_CONVERGED_ITERATING;
    SNEDE_PETSC(TSGetConvergedReason(ts_, &reason));
    result.converged = true;
    result.reason = n_steps == 0 ? "CONVERGED_ITS" : TSConvergedReasons[reason];
  }
  EvaluationReport energy_report;
  result.energy = model_.potential_energy(u, energy_report);
  result.residual_history = history_;
  result.seconds = wall_seconds() - start;
  PetscLogDouble flops = 0;
  SNEDE_PETSC(PetscGetFlops(&flops));
  result.flops = flops - start_flops;
  return result;
}

PetscInt DynamicRelaxation::take_steps(PetscInt n_steps) {
  PetscInt cap = 0, first = 0, last = 0;
  SNEDE_PETSC(TSGetMaxSteps(ts_, &cap));
  SNEDE_PETSC(TSGetStepNumber(ts_, &first));
  PetscInt target = n_steps > PETSC_MAX_INT - first ? PETSC_MAX_INT : first + n_steps;
  if (mode_ != Mode::stability_trial) target = std::min(target, cap);
  {
    MaxStepsGuard restore(ts_, cap);
    SNEDE_PETSC(TSSetMaxSteps(ts_, target));
    SNEDE_PETSC(TSSolve(ts_, nullptr));
  }
  SNEDE_PETSC(TSGetStepNumber(ts_, &last));
  return last - first;
}

bool DynamicRelaxation::converged_at(Vec u) {
  EvaluationReport report;
  model_.residual(u, residual_, report);
  checked_residual_norm_ = norm_of(residual_);
  return report.domain_errors.empty() && checked_residual_norm_ <= tolerance(model_.last_reaction_norm()) &&
         model_.admissible(u);
}

void DynamicRelaxation::after_step() {
  Vec u = model_.displacement();
  if (mode_ != Mode::stability_trial) history_.push_back(last_residual_norm_);
  if (failure_.empty()) {
    const double norm = norm_of(u);
    if (!std::isfinite(norm)) failure_ = "DIVERGED_NONFINITE_STATE";
    else if (norm > blow_up_norm) failure_ = "DIVERGED_BLOW_UP";
  }
  if (!failure_.empty()) {
    SNEDE_PETSC(TSSetConvergedReason(ts_, TS_DIVERGED_STEP_REJECTED));
    return;
  }
  // The force of this step was evaluated at u_n; confirm at u_{n+1} before stopping.
  if (mode_ == Mode::relaxation && last_residual_norm_ <= last_tolerance_ && converged_at(u)) {
    converged_ = true;
    SNEDE_PETSC(TSSetConvergedReason(ts_, TS_CONVERGED_USER));
  }
}

double DynamicRelaxation::critical_time_step(double flop_budget, double initial, double reduction) {
  if (!(flop_budget > 0) || !std::isfinite(flop_budget))
    throw std::invalid_argument("flop_budget must be positive, got " + std::to_string(flop_budget));
  if (!(initial >= 0) || !std::isfinite(initial))
    throw std::invalid_argument("initial must be positive (or 0 for the CFL estimate), got " + std::to_string(initial));
  if (!(reduction > 0 && reduction < 1))
    throw std::invalid_argument("reduction must lie in (0, 1), got " + std::to_string(reduction));
  reissue_sizes_if_mesh_changed();
  prepare_state();
  const double flops_per_step = static_cast<double>(model_.body().flops_per_element().force) *
                                static_cast<double>(model_.body().mesh().n_cells());
  const auto trial_steps = static_cast<PetscInt>(std::max(1.0, std::ceil(flop_budget / flops_per_step)));

  // Everything a trial changes, restored after each trial and at the end.
  Vec u = model_.displacement();
  const std::vector<double> u0 = values_of(u), v0 = values_of(velocity_);
  const double dt0 = time_step(), damping0 = damping();
  PetscReal t0 = 0;
  PetscInt steps0 = 0;
  SNEDE_PETSC(TSGetTime(ts_, &t0));
  SNEDE_PETSC(TSGetStepNumber(ts_, &steps0));
  auto restore = [&] {
    set_values(u, u0);
    set_values(velocity_, v0);
    SNEDE_PETSC(TSSetTime(ts_, t0));
    SNEDE_PETSC(TSSetStepNumber(ts_, steps0));
    SNEDE_PETSC(TSSetTimeStep(ts_, dt0));
    set_ss22_damping(ts_, damping0);
  };
  auto stable = [&](double dt) {
    restore();
    set_ss22_damping(ts_, 0.0);
    SNEDE_PETSC(TSSetTimeStep(ts_, dt));
    mode_ = Mode::stability_trial;
    failure_.clear();
    take_steps(trial_steps);
    return failure_.empty();
  };

  const double factor = 1 - reduction;
  const int max_trials = 200;
  double dt = initial > 0 ? initial : cfl_time_step();
  try {
    if (stable(dt)) {
      int trial = 0;
      for (; trial < max_trials && stable(dt / factor); ++trial) dt /= factor;
      if (trial == max_trials)
        throw std::runtime_error("no blow-up even at " + std::to_string(dt) +
                                 " s: nothing can vibrate (is every vertex fixed?)");
    } else {
      int trial = 0;
      for (; trial < max_trials && !stable(dt * factor); ++trial) dt *= factor;
      if (trial == max_trials)
        throw std::runtime_error("blow-up even at " + std::to_string(dt * factor) + " s: the state itself diverges");
      dt *= factor;
    }
  } catch (...) {
    restore();
    failure_.clear();
    throw;
  }
  restore();
  failure_.clear();
  return dt;
}

PetscErrorCode DynamicRelaxation::acceleration_callback(TS, PetscReal, Vec u, Vec a, void* context) {
  return petsc_callback("snede dynamic relaxation force", [&] {
    auto* self = static_cast<DynamicRelaxation*>(context);
    Model& model = self->model_;
    EvaluationReport report;
    model.residual(u, a, report);  // F(u) = P∇Π(u) on u's constraints
    self->last_residual_norm_ = norm_of(a);
    self->last_tolerance_ = self->tolerance(model.last_reaction_norm());
    std::string why;
    if (self->failure_.empty()) {
      if (!report.domain_errors.empty()) self->failure_ = "DIVERGED_NONFINITE_STATE";
      else if (self->mode_ != Mode::stability_trial && !report.inverted.empty() && !model.admissible(u, &why))
        self->failure_ = why;
    }
    // a = −M⁻¹ P ∇Π(u): the net force on the allowed motions over the lumped mass.
    project_onto_allowed_motions(model, a);
    SNEDE_PETSC(VecPointwiseMult(a, self->inverse_mass_, a));
    SNEDE_PETSC(VecScale(a, -1.0));
  });
}

PetscErrorCode DynamicRelaxation::post_step_callback(TS ts) {
  return petsc_callback("snede dynamic relaxation post-step", [&] {
    void* context = nullptr;
    SNEDE_PETSC(TSGetApplicationContext(ts, &context));
    static_cast<DynamicRelaxation*>(context)->after_step();
  });
}

}  // namespace snede
