"""Dynamic relaxation (§2.5, §4.1, §4.4.1): the damped motion M ü + η M u̇ = f(u) of a body
with lumped masses, integrated by explicit SS22 / central differences until it settles in the
static equilibrium. The integrator is PETSc's TS of type ``snede_ss22`` with options prefix
``options_prefix`` (default ``dynamic_``), so the command line tunes it:
``-dynamic_ts_monitor``, ``-dynamic_ts_max_steps 500`` (a cap on the total steps),
``-dynamic_ts_dt 1e-3``, ``-dynamic_ts_ss22_damping 20``, ``-dynamic_ts_view``.
"""
from __future__ import annotations

import numpy as np

from snede import _checks, _records, _snede
from snede.distributed import DistributedRelaxation, relaxation_options
from snede.distributed_body import RunsOnRanks, on_ranks
from snede._snede import DynamicRelaxationOptions, SolveResult


class DynamicRelaxation(RunsOnRanks):
    """``DynamicRelaxation(body, damping, dt=None, *, options=None, ...)``: relax
    ``body.displacement`` in time.

    * ``options``: a :class:`snede.DynamicRelaxationOptions` record holding ``damping``, ``dt``,
      ``options_prefix`` (default ``"dynamic_"``) and ``petsc_options`` (default: the default
      record); a keyword given (not None) changes its field; the record checks each value.

    * ``damping``: η (1/s) of the damping C = η M, ≥ 0. §4.1: the fastest relaxation has
      η = 2√λ₁ (λ₁ the lowest eigenvalue of M⁻¹K); Table 4.4 lists 17–27 1/s for its cylinder.
    * ``dt``: time step (s); None takes the CFL estimate (2.61) ``cfl_time_step``, renewed
      when the mesh changes size. Above the critical step the motion blows up; that is
      reported as ``reason == "DIVERGED_BLOW_UP"``, not raised.
    * ``petsc_options``: PETSc options without the prefix, e.g. ``{"ts_monitor": None}``, for
      this solver only; the command line (PETSc's global options, as they are when the solver
      is made) still wins.
    * ``comm`` (an mpi4py communicator): ``run()`` is collective over its ranks (issue 18):
      rank 0's body is distributed with its fixed vertices, external forces and displacement,
      relaxed by :class:`snede.DistributedRelaxation` (the same steps and displacement as
      serially), and the result gathered into ``body.displacement`` on every rank; a body
      refined, loaded or moved between runs is taken up anew, at rest. ``run``, ``dt`` and
      ``part`` are available. None (default): the body's ``comm``, and without one
      the serial solver.

    The state is ``body.displacement`` and ``velocity`` (both (n_points, dim)); it starts at
    rest. After a cut or refinement the velocity is carried over like the displacement.

    A membrane (a body on a surface mesh, §5.3) relaxes like a volume: its lumped masses are
    area × thickness × density, and ``cfl_time_step`` measures each triangle in its own plane
    with the plane-stress wave speed. An organ's closed skin hanging under gravity settles at
    ``damping=10`` (docs/results/membranes_on_organs.md).
    """

    _on_ranks = "run(), dt and part"

    def __init__(self, body, damping: float | None = None, dt: float | None = None, *,
                 options: DynamicRelaxationOptions | None = None, options_prefix: str | None = None,
                 petsc_options: dict | None = None, comm=None):
        self._settings = relaxation_options(options, damping, dt, options_prefix, petsc_options)
        self.body = body
        self._distributed = on_ranks(body, comm)
        if self._distributed is not None:
            self._start_relaxation()
            self._impl = None
            return
        self._impl = _snede.DynamicRelaxation(body._model, self._settings)

    @property
    def options(self) -> DynamicRelaxationOptions:
        """A copy of the settings this relaxation was made with."""
        return DynamicRelaxationOptions(**_records.fields(self._settings))

    def _start_relaxation(self) -> None:
        self._problem = self._distributed.problem()
        self._relaxation = DistributedRelaxation(self._problem, options=self._settings)

    def step(self, n: int = 1) -> SolveResult:
        """Take ``n`` time steps. ``converged`` is False only on divergence (blow-up, NaN,
        inverted elements); ``residual_norm`` is ‖F(u)‖ at the final state."""
        return self._impl.step(_checks.count(n, "n"))

    def run(self, rtol: float = 1e-3, max_steps: int = 100000) -> SolveResult:
        """Step until ‖F(u)‖ ≤ rtol·√(‖f_ext‖² + ‖f_react‖²) (criterion (6.9)), or
        ``max_steps`` (``reason == "DIVERGED_MAX_IT"``)."""
        if self._distributed is not None:
            if self._distributed.changed():  # refined, loaded or moved since: start from the body at rest
                self._start_relaxation()
            result = self._relaxation.run(rtol, max_steps)
            self._distributed.gather_into_body(self._problem)
            return result
        return self._impl.run(float(rtol), _checks.count(max_steps, "max_steps"))

    def critical_time_step(self, flop_budget: float = 50e6, initial: float | None = None,
                           reduction: float = 0.15, min_steps: int = 200) -> float:
        """§4.4.1: the largest step for which an undamped run from the current state does not
        blow up (‖u‖ > 1e15 or NaN) within ``flop_budget`` flops (and at least ``min_steps``
        steps, which large meshes need), searched from ``initial`` (None: the CFL estimate) in
        factors of (1 − ``reduction``). The state is restored."""
        return self._impl.critical_time_step(float(flop_budget), float(initial or 0.0), float(reduction),
                                             _checks.count(min_steps, "min_steps", 1))

    @property
    def cfl_time_step(self) -> float:
        """(2.61): (2/√3)·h/c, h the smallest inscribed-sphere diameter, c the dilatational
        wave speed √((λ+2μ)/ρ) (plane stress: √(E/((1−ν²)ρ)))."""
        return self._impl.cfl_time_step()

    @property
    def dt(self) -> float:
        return self._relaxation.dt if self._distributed is not None else self._impl.dt

    @dt.setter
    def dt(self, value: float) -> None:
        self._impl.dt = float(value)

    @property
    def damping(self) -> float:
        return self._impl.damping

    @property
    def velocity(self) -> np.ndarray:
        """Velocity (m/s) at the half step behind the displacement, (n_points, dim) (a copy)."""
        return self._impl.velocity

    @velocity.setter
    def velocity(self, v) -> None:
        self._impl.velocity = np.ascontiguousarray(self.body._field("velocity", v))

    @property
    def ts(self):
        """The petsc4py TS (type ``snede_ss22``)."""
        return self._impl.ts
