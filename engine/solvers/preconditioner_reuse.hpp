// Whether Galerkin multigrid levels filled for one Newton iteration serve the next ones, within
// a solve and across solves (issue 31: reuse across tool moves; issue 49: ageing within a solve).
// In an interactive loop every tool move is followed by one solve from the previous state; while
// the mesh and the constraints' projections stay the same (a grasper dragging, a blade moving
// through an incision it already made), the levels of an earlier solve — the assembled tangent at
// that state, its Galerkin products, the coarse factorisation, the smoothers' bounds — still
// precondition the tangent well. When only the projections change (a needle's stick-slip), the
// levels keep their interpolation and are refilled at the new state (preconditioner_state.cpp). Within
// one solve from far away (a body loaded from rest) the tangent changes more from step to step.
// Levels are kept until they show their age: a Newton iteration whose CG needs more than
// `refresh_ratio` times the CG iterations of the first Newton iteration the levels served after
// they were filled, or a linear solve or a solve that failed. Then they are filled at the state
// of now (preconditioner_state.cpp).
#pragma once

namespace snede {

class PreconditionerReuse {
 public:
  // refresh_ratio: ≥ 1, or 0 to fill the levels anew at the start of every solve (and keep them
  // through it).
  explicit PreconditionerReuse(double refresh_ratio);
  // docs/results/interactive.md, "Levels that age within a solve": 1.5, 2 and 3 cost the same
  // on the cut loops; on the static 98k block 2 took as few CG iterations as 1.5 (38) with one
  // fill fewer, 3 took 50; the needle into the 10k liver filled 196 times with 2, 246 with 1.5 and
  // 176 with 3 and 175 before levels were refilled within a solve, for the same CG iterations.
  static constexpr double default_refresh_ratio = 2.0;

  // Whether the levels as filled last still serve the next Newton iteration.
  bool keep() const { return !stale_; }
  // The levels were filled at the current state. `new_baseline`: the next linear solve's CG
  // iterations are the baseline later ones are compared with — false when they were refilled on
  // the interpolation of earlier constraints, which keep the baseline of the levels made for those.
  void filled(bool new_baseline);
  // After each Newton iteration's linear solve with the levels: its CG iterations, and whether it
  // converged.
  void record_linear_solve(int iterations, bool converged);
  // After a whole solve.
  void record_solve(bool converged);

 private:
  double refresh_ratio_;
  double baseline_ = 0;  // CG iterations of the first linear solve after the levels were filled
  bool awaiting_baseline_ = false;
  bool stale_ = true;
};

}  // namespace snede
