// Dynamic relaxation (§2.5, §4.1, §4.4.1): the damped motion M ü + η M u̇ = f(u) settles in
// the static equilibrium, integrated by the explicit SS22 scheme (θ₁ = ½, θ₂ = 0) — central
// differences — with lumped masses M and mass-proportional damping C = η M.
//
// The integrator is a PETSc TS type, "snede_ss22", for second-order ODEs ü = G(t, u) − η u̇:
// G comes from TSSetRHSFunction, the velocity from TS2SetSolution, η from
// set_ss22_damping or -<prefix>ts_ss22_damping. DynamicRelaxation drives it with
// G(u) = −M⁻¹ P ∇Π(u) (the net force on the free motions) and carries an options prefix
// (default "dynamic_"), so -dynamic_ts_monitor, -dynamic_ts_max_steps, -dynamic_ts_dt and
// -dynamic_ts_ss22_damping apply; TSSetFromOptions runs after snede's defaults. The TS reads
// its own options database (core/solver_options.hpp): the options' petsc_options, then the
// command line over them.
//
// It drives any Problem (problem.hpp): a serial Model, whose mesh may be cut or refined between
// calls, or a DistributedStatic on its communicator, with the same steps on any number of ranks.
#pragma once

#include <petscts.h>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/solver_options.hpp"
#include "fem/stable_time_step.hpp"
#include "solvers/dynamic_relaxation_options.hpp"
#include "problem/model.hpp"
#include "problem/problem.hpp"
#include "solvers/solve_result.hpp"
#include "problem/stopping.hpp"
#include "solvers/ts_ss22.hpp"

namespace snede {

// §4.4.1: "DIVERGED_NONFINITE_STATE" or "DIVERGED_BLOW_UP" (‖u‖ > 10¹⁵) for a state the
// motion has left behind, else empty.
std::string blow_up_failure(Vec u);

class DynamicRelaxation {
 public:
  // Throws std::invalid_argument for invalid options (DynamicRelaxationOptions::validate).
  DynamicRelaxation(Model& model, const DynamicRelaxationOptions& options);
  // Collective on problem.comm(); the problem must outlive the solver. Throws
  // std::invalid_argument (the same on every rank) for options that differ between the ranks.
  DynamicRelaxation(Problem& problem, const DynamicRelaxationOptions& options);
  ~DynamicRelaxation();
  DynamicRelaxation(const DynamicRelaxation&) = delete;
  DynamicRelaxation& operator=(const DynamicRelaxation&) = delete;

  // n time steps from the current state and velocity. converged = no divergence and an
  // admissible final state; reason "CONVERGED_ITS", or a divergence reason.
  SolveResult step(int n);
  // Steps until ‖F(u)‖ ≤ rtol·√(‖f_ext‖² + ‖f_react‖²) (6.9), or max_steps ("DIVERGED_MAX_IT").
  SolveResult run(double rtol, int max_steps);

  // (2.61) on the problem's mesh.
  double cfl_time_step() const { return problem_.cfl_time_step(); }
  // §4.4.1: a step is stable if an undamped run from the current state does not blow up
  // within flop_budget flops (force kernel flops × elements per step), and at least
  // min_steps steps: on large meshes 50 MFLOP alone buys too few steps (31 on 8724
  // tetrahedra, where 1.5× the stability limit passed). Starting from `initial` (0: the CFL
  // estimate) the step is lowered by `reduction` until stable; a stable start is instead
  // raised by the same factor while it stays stable. Returns the largest stable step found;
  // the state, velocity, time and step count are restored.
  double critical_time_step(double flop_budget = 50e6, double initial = 0, double reduction = 0.15,
                            int min_steps = 200);

  double time_step() const;
  void set_time_step(double dt);
  double damping() const { return ss22_damping(ts_); }
  // (n_points, dim) flattened; the model's displacement is the position.
  std::vector<double> velocity();
  void set_velocity(std::span<const double> values);
  TS ts() const { return ts_; }
  Problem& problem() { return problem_; }

 private:
  // The problem given, or else the one owned.
  DynamicRelaxation(std::unique_ptr<Problem> owned, Problem* problem, const DynamicRelaxationOptions& options);

  enum class Mode { steps, relaxation, stability_trial };
  SolveResult advance(PetscInt n_steps, Mode mode, double rtol);
  // TSSolve for up to n_steps more steps (within the user's cap, except in a stability
  // trial); returns the number taken.
  PetscInt take_steps(PetscInt n_steps);
  void reissue_sizes_if_mesh_changed();
  void prepare_state();
  // (6.9) threshold for the current relaxation; 0 outside one.
  double tolerance(double reaction_norm) const;
  // Evaluates F(u): within the tolerance, finite and admissible?
  bool converged_at(Vec u);
  void after_step();

  static PetscErrorCode acceleration_callback(TS ts, PetscReal t, Vec u, Vec a, void* context);
  static PetscErrorCode post_step_callback(TS ts);

  std::unique_ptr<Problem> owned_problem_;  // the serial model's, when made from a Model
  Problem& problem_;
  SolverOptions option_database_;  // read by the PETSc objects below
  TsHandle ts_;
  VecHandle velocity_;
  VecHandle inverse_mass_;  // 1/m per dof (0 for a vertex without mass)
  VecHandle residual_;
  std::uint64_t generation_ = 0;
  bool follows_cfl_ = false;

  // Bookkeeping of the current advance() or stability trial.
  Mode mode_ = Mode::steps;
  StoppingRule stopping_;  // (6.9), filled per run()
  double external_norm_ = 0;
  std::string failure_;            // a divergence reason, empty while all is well
  bool converged_ = false;
  double last_residual_norm_ = 0;  // ‖F(u_n)‖ from the latest force evaluation
  double last_tolerance_ = 0;
  double checked_residual_norm_ = 0;  // ‖F‖ from the latest converged_at()
  std::vector<double> history_;
};

}  // namespace snede
