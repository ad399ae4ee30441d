// Whether Galerkin multigrid levels built for one static solve serve the next ones (issue 31:
// reuse across tool moves). In an interactive loop every tool move is followed by one solve
// from the previous state; while the mesh and the constraints' projections stay the same (a
// grasper dragging, a blade moving through an incision it already made), the levels of an
// earlier solve — the assembled tangent at that state, its Galerkin products, the coarse
// factorisation, the smoothers' bounds — still precondition the tangent well. When only the
// projections change (a needle's stick-slip), the levels keep their interpolation and are
// refilled at the new state (static_solver.cpp). They are kept
// until the preconditioner shows its age: a solve that needed more than `refresh_ratio` times
// the CG iterations per Newton iteration of the solve that built them, or one that failed.
#pragma once

namespace snede {

class PreconditionerReuse {
 public:
  // refresh_ratio: ≥ 1, or 0 to build the levels anew for every solve.
  explicit PreconditionerReuse(double refresh_ratio);
  // Measured on the interactive loops (docs/results/interactive.md, "Reuse across moves").
  static constexpr double default_refresh_ratio = 1.5;

  // Whether levels filled for an earlier solve (on the same mesh and projections) serve the next.
  bool keep() const { return !stale_; }
  // After a solve: its Newton and CG iterations, whether it converged, and whether it built the
  // levels it used (then its CG per Newton iteration is the baseline of the ones that reuse them).
  void record(int newton_iterations, int linear_iterations, bool converged, bool built_levels);

 private:
  double refresh_ratio_;
  double baseline_ = 0;  // CG per Newton iteration of the solve that built the levels
  bool stale_ = true;
};

}  // namespace snede
