// Dynamic relaxation (§2.5, §4.1) of a distributed static problem (issue 18): the damped
// motion M ü + η M u̇ = −F(u) integrated by the TS type snede_ss22 on the problem's
// communicator, the lumped masses summed over the ranks, until (6.9)
// ‖F(u)‖ ≤ rtol·√(‖f_ext‖² + ‖f_react‖²) (+ its round-off floor). The same steps are taken on
// any number of ranks. Options under the prefix (default "drelax_"): -drelax_ts_monitor,
// -drelax_ts_dt, -drelax_ts_ss22_damping.
#pragma once

#include <petscts.h>

#include <string>

#include "core/petsc_handle.hpp"
#include "solve/distributed_static.hpp"
#include "solve/solve_result.hpp"
#include "solve/stopping.hpp"

namespace snede {

class DistributedRelaxation {
 public:
  // Collective. damping: η ≥ 0 (1/s); dt: the time step (s), or 0 for the CFL estimate (2.61).
  DistributedRelaxation(DistributedStatic& problem, double damping, double dt, const std::string& options_prefix);
  ~DistributedRelaxation();
  DistributedRelaxation(const DistributedRelaxation&) = delete;
  DistributedRelaxation& operator=(const DistributedRelaxation&) = delete;

  // Collective: steps from the problem's state (starting at rest the first time) until (6.9)
  // holds or max_steps ("DIVERGED_MAX_IT"); a blow-up, a non-finite state or an inverted
  // element stops it with that reason.
  SolveResult run(double rtol, int max_steps);
  double time_step() const;

 private:
  void acceleration(Vec u, Vec a);
  void after_step();
  static PetscErrorCode acceleration_callback(TS ts, PetscReal t, Vec u, Vec a, void* context);
  static PetscErrorCode post_step_callback(TS ts);

  DistributedStatic& problem_;
  TsHandle ts_;
  VecHandle velocity_, inverse_mass_, residual_;
  StoppingRule stopping_;
  double external_norm_ = 0;
  double last_residual_norm_ = 0;  // ‖F(u_n)‖ from the latest force evaluation
  double last_reaction_norm_ = 0;
  std::string failure_;
  bool converged_ = false;
};

}  // namespace snede
