"""Needle insertion with stick-slip friction and adaptive bisection (§6.3–§6.7), 2D.

A rigid straight needle enters a plane-stress body at ``entry`` along ``direction``. Nodes the
tip passes (the end of each crossed edge closest to the shaft, §6.4) become needle nodes that
stick to the needle or slip along it against dynamic friction; after every move the solution
is relaxed and the needle nodes rearranged until no node changes state (§6.3.2, §6.7).

    profile = snede.FrictionProfile.figure_6_4()
    needle = snede.NeedleInsertion(body, entry=(0.0, 0.05), direction=(1.0, 0.0), friction=profile,
                                   h_ref=0.1 / 2**6)
    step = needle.advance(0.001)              # one update: NeedleStepResult
    report = needle.insert(depth=0.07, step=0.001)   # InsertionResult
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from snede import _checks, _records, _renamed, _snede
from snede._engine import engine_property
from snede._snede import NeedleOptions, NeedleStepResult, StaticOptions


class FrictionProfile:
    """Friction force per unit shaft length (N/m; for a plane-stress sheet, across its whole
    thickness) as a function of the distance from the tip along the shaft, in deformed
    coordinates (Figure 6.4). Piecewise linear through ``(distance_from_tip, force_per_length)``
    (distances increasing from 0), constant beyond the last sample."""

    def __init__(self, distance_from_tip, force_per_length):
        d = np.asarray(distance_from_tip, dtype=np.float64).ravel()
        f = np.asarray(force_per_length, dtype=np.float64).ravel()
        self._impl = _snede.FrictionProfile(list(d), list(f))

    @classmethod
    def uniform(cls, force_per_length: float) -> "FrictionProfile":
        """The same force per length all along the shaft."""
        return cls([0.0], [force_per_length])

    @classmethod
    def figure_6_4(cls, scale: float = 1.0) -> "FrictionProfile":
        """A stand-in with the shape of Figure 6.4, which gives no numbers: a bulge at the tip
        (the force needed to cut into the material) of 60 N/m over the first 5 mm, falling to a
        plateau of 20 N/m of shaft friction from 10 mm on. ``scale`` multiplies it."""
        return cls([0.0, 0.002, 0.005, 0.010], [scale * 40.0, scale * 60.0, scale * 45.0, scale * 20.0])

    def __call__(self, distance):
        """Force per length at the given distances from the tip."""
        return np.vectorize(self._impl.at)(np.asarray(distance, dtype=np.float64))

    def integral(self, a: float, b: float) -> float:
        """∫ from a to b (distances from the tip, 0 ≤ a ≤ b) of the profile (N)."""
        return self._impl.integral(float(a), float(b))

    distances = engine_property("distances", convert=np.asarray)
    force_per_length = engine_property("force_per_length", convert=np.asarray)

    def __repr__(self) -> str:
        return f"FrictionProfile(distance_from_tip={self.distances.tolist()}, force_per_length={self.force_per_length.tolist()})"


@dataclass
class InsertionResult:
    """A whole insertion: ``updates`` needle moves, ``rearrangements`` solves in all,
    ``update_rate`` = rearrangements per second (Table 6.5's "updates [Hz]"), CG (or Newton's
    inner CG) iterations per solve on average and at most; ``extensions`` moves carried into the
    tissue and ``halvings`` moves halved (``extension_rings``). ``converged`` is False if any
    update was not; ``reason`` is the first failure's."""

    updates: int
    rearrangements: int
    seconds: float
    update_rate: float
    mean_iterations: float
    max_iterations: int
    converged: bool
    reason: str
    steps: list
    extensions: int = 0
    halvings: int = 0

    def __str__(self) -> str:
        state = "converged" if self.converged else f"NOT converged ({self.reason})"
        return (f"{self.updates} updates, {self.rearrangements} rearrangements in {self.seconds:.3f} s "
                f"({self.update_rate:.0f} Hz), CG iterations {self.mean_iterations:.2f} mean / {self.max_iterations} max; {state}")


class NeedleInsertion:
    """``NeedleInsertion(body, entry, direction, friction, *, options=None, solver=None, **settings)``
    on a 2D (plane-stress) or 3D (tetrahedral) ``snede.Body`` of any material.

    * ``options``: a :class:`snede.NeedleOptions` record of the needle's settings below
      (default ``NeedleOptions()``, whose fields are the defaults); ``solver``: a
      :class:`snede.StaticOptions` record for its static solver (default
      ``NeedleInsertion.default_solver_options()``: linear CG, rtol 1e-3, round_tolerance 1e-8,
      options prefix ``needle_``). A keyword setting given (not None) changes its field of the
      record it belongs to; the records check each value (a ValueError or TypeError naming the
      field).
    * ``entry``, ``direction``: the needle's axis (dim components each, metres); the tip starts
      at ``entry`` (depth 0) and moves along ``direction`` (normalised). The line must meet the
      body. Points are in deformed coordinates: the needle is an object in space.
    * ``friction``: a :class:`FrictionProfile`; the dynamic threshold of a node is the profile
      integrated over its share of the shaft (half-way to its neighbours along the shaft,
      within the body); the static threshold is ``static_factor`` (default 2) times it. In 3D
      the profile is a force per unit of shaft *surface* (N/m²): the integral is multiplied by 2πr.
    * ``radius`` (3D only; default ``NeedleOptions.default_radius``, 1 mm): the needle is a rigid
      cylinder. Its needle nodes are the mesh's jagged image of its surface (Figure 6.14): the
      vertex nearest the axis of every face the axis crosses, and every vertex the tip has passed
      within ``radius`` of the axis (deformed coordinates). Giving a radius for a 2D body is an error.
    * ``h_ref``: refine by bisection (§6.5) around the tip to this edge length after every move;
      in 3D also along the shaft, every element within ``radius`` of the axis.
    * ``method``, ``rtol``, ``criterion``, ``round_tolerance``, ``max_iterations``,
      ``preconditioner``, ``petsc_options`` (a dict), ``options_prefix``: the solver record's fields (see
      :class:`snede.StaticSolver`); stopping (6.9).
      Inexact Newton (``petsc_options={"snes_ksp_ew": None}`` or ``-needle_snes_ksp_ew``,
      Eisenstat–Walker: early steps solve their linear systems loosely) pays in the haptic
      loop: 12–16 % less time with one solve per update at 22k–34k neo-Hookean tetrahedra
      (``studies/benchmarks/needle3d_rates.py --thesis-size``), but 8 % more when every update is
      settled (the ``needle3d`` scene: more Newton steps, each with a new preconditioner).
    * ``max_rearrangements`` (default 200): per update; reaching it is reported, not hidden.
    * ``solves_per_update``: 0 (default) relaxes and rearranges until no node changes state
      in every update; k > 0 allows at most k solves per update and carries pending
      rearrangements into the next one — the thesis's haptic loop (§6.7, Table 6.5) is k = 1,
      which bounds the work per update.
    * ``extrapolate``: start each update's solve from the last state plus the last update's
      displacement change per unit of needle travel (a linear predictor) instead of from the
      last state (the thesis's warm start, the default). Measured on the §6.8.1 slab (h3/h6,
      one solve per update): at ε = 1e-3 it cuts CG iterations from 32 to 19 at 0.01 h_ref per
      update and by 2–10 % at faster speeds; at ε = 1e-2 it costs 8–25 % more.
    * ``extension_rings`` (default 3): a move that would start the solve from inverted elements
      (sticking nodes dragged across their neighbours) is first carried into the tissue: the
      free vertices and slipping needle nodes inside the body within this many rings of the
      sticking nodes move with the needle by weights falling smoothly from 1 to 0 (a few Jacobi
      sweeps of the edge-graph average; the surface stays put). Only if that still inverts an
      element is the move halved; 0 halves at once. On gmsh livers it takes the halvings of a
      30 mm insertion from 13–24 to 1–3. Each solve's solution (to its tolerance), and so the
      stick-slip path, does not depend on it; only where the solve starts.

    The body must be held (``body.fix``) as for any static solve. Needle nodes are taken only
    from vertices the user has not constrained.
    """

    default_solver_options = staticmethod(_snede.NeedleInsertion.default_solver_options)

    def __init__(self, body, entry, direction, friction: FrictionProfile, *, options: NeedleOptions | None = None,
                 solver: StaticOptions | None = None, static_factor: float | None = None, h_ref: float | None = None,
                 radius: float | None = None, max_rearrangements: int | None = None,
                 solves_per_update: int | None = None, extrapolate: bool | None = None,
                 extension_rings: int | None = None, method: str | None = None, rtol: float | None = None,
                 criterion: str | None = None, round_tolerance: float | None = None,
                 max_iterations: int | None = None, preconditioner: str | None = None,
                 options_prefix: str | None = None, petsc_options: dict | None = None):
        body.mesh.require_serial("NeedleInsertion")
        if not isinstance(friction, FrictionProfile):
            raise TypeError(f"friction must be a snede.FrictionProfile, got {type(friction).__name__}")
        needle_settings = _records.settings(
            NeedleOptions, options, static_factor=static_factor, h_ref=h_ref, radius=radius,
            max_rearrangements=_checks.optional_count(max_rearrangements, "max_rearrangements", 1),
            solves_per_update=_checks.optional_count(solves_per_update, "solves_per_update"),
            extrapolate=extrapolate, extension_rings=_checks.optional_count(extension_rings, "extension_rings"))
        solver_settings = _records.settings(
            StaticOptions, self.default_solver_options() if solver is None else solver, method=method, rtol=rtol, criterion=criterion,
            round_tolerance=round_tolerance, max_iterations=_checks.optional_count(max_iterations, "max_iterations", 1),
            preconditioner=preconditioner, options_prefix=options_prefix,
            petsc_options=petsc_options)
        self.body = body
        self.friction_profile = friction
        bisection = body.mesh._bisection() if needle_settings.h_ref is not None else None
        self._impl = _snede.NeedleInsertion(body._model, bisection, np.asarray(entry, dtype=np.float64),
                                            np.asarray(direction, dtype=np.float64), friction._impl,
                                            needle_settings, solver_settings)

    @property
    def options(self) -> NeedleOptions:
        """A copy of the needle's settings (a :class:`snede.NeedleOptions`)."""
        return NeedleOptions(**_records.fields(self._impl.options))

    @property
    def solver_options(self) -> StaticOptions:
        """A copy of the settings of the needle's static solver (a :class:`snede.StaticOptions`),
        with what the needle adds to them: ``mg_coarsening grid`` among its PETSc options unless
        given, and a 2D linear CG's later start of "auto" multigrid."""
        return StaticOptions(**_records.fields(self._impl.solver_options))

    def advance(self, distance: float) -> NeedleStepResult:
        """Move the needle ``distance`` (≥ 0) further in and relax (one update of §6.7)."""
        if not (np.isfinite(distance) and distance >= 0):
            raise ValueError(f"the needle advances by a non-negative, finite distance; got {distance}")
        return self._impl.advance(float(distance))

    def settle(self) -> NeedleStepResult:
        """Relax and rearrange without moving the needle."""
        return self._impl.settle()

    def insert(self, depth: float, step: float, progress=None) -> InsertionResult:
        """Advance in steps of ``step`` until the tip is ``depth`` from the entry point (the last
        step shortened to land on it), then, with ``solves_per_update``, keep updating in place
        until no node changes state (as the thesis's automated insertion does).
        ``progress(done, total, step_report)`` is called after each update."""
        _checks.positive(step, "step")
        if not (np.isfinite(depth) and depth >= self.depth):
            raise ValueError(f"depth must be finite and at least the current depth {self.depth}, got {depth}")
        n_steps = int(np.ceil((depth - self.depth) / step - 1e-9))
        steps = []
        for k in range(n_steps):
            distance = min(step, depth - self.depth)
            steps.append(self.advance(distance))
            if progress is not None:
                progress(k + 1, n_steps, steps[-1])
        while steps and steps[-1].converged and not steps[-1].settled:
            steps.append(self.advance(0.0))
        return summarize(steps)

    depth = engine_property("depth")
    tip = engine_property("tip", convert=np.asarray)
    surface_depth = engine_property(
        "surface_depth", """How far from ``entry`` the shaft's line first meets the deformed body (0 when
        ``entry`` is inside it): ``advance(surface_depth - depth)`` brings the tip to the
        surface in one update. Scans the mesh; ValueError if the line no longer meets the body.""")
    preconditioner_fills = engine_property(
        "preconditioner_fills", """How many times the needle's solver filled its preconditioner (see
        :attr:`snede.StaticSolver.preconditioner_fills`).""")
    multigrid_builds = engine_property(
        "multigrid_builds", """How many times the needle's solver made multigrid levels (see
        :attr:`snede.StaticSolver.multigrid_builds`): after refinements, not after stick-slip
        changes, which refill the levels it has.""")
    multigrid_edits = engine_property(
        "multigrid_edits", """How many of :attr:`multigrid_builds` were grid levels made from the earlier ones
        after a refinement (see :attr:`snede.StaticSolver.multigrid_edits`).""")
    multigrid_source = engine_property(
        "multigrid_source", """What made the needle solver's ``"mg"`` levels at its last solve (see
        :attr:`snede.StaticSolver.multigrid_source`).""")
    multigrid_unknowns = engine_property(
        "multigrid_unknowns", "Unknowns per level of the needle solver's ``\"mg\"`` levels, coarsest first.", list)
    radius = engine_property("radius", "The needle's radius (metres; 0 for a 2D needle, a line).")
    entry = engine_property("entry", convert=np.asarray)
    direction = engine_property("direction", convert=np.asarray)
    needle_nodes = engine_property("needle_nodes", "Vertex ids of the needle nodes.",
                                   lambda nodes: np.asarray(nodes, dtype=np.int64))
    sticking = engine_property("sticking", "True per needle node that sticks (False: slips).",
                               lambda sticking: np.asarray(sticking, dtype=bool))
    d_perp = engine_property("d_perp", "Each needle node's offset from the shaft (held while the needle moves), metres.")
    d_needle = engine_property("d_needle", "Each needle node's position along the shaft from the entry point "
                                           "(deformed).")
    dynamic_thresholds = engine_property("dynamic_thresholds")
    static_thresholds = engine_property("static_thresholds")
    friction = engine_property("friction", "Friction force along the shaft on each slipping node (0 for sticking "
                                           "ones).")

    def needle_forces(self) -> np.ndarray:
        """Forces the needle exerts on the body at its needle nodes (support plus friction),
        (n_needle_nodes, dim)."""
        return self._impl.needle_forces()

    def node_state(self) -> np.ndarray:
        """Per mesh vertex: 0 not a needle node, 1 sticking, 2 slipping (a point field for output)."""
        state = np.zeros(self.body.mesh.n_points, dtype=np.float64)
        state[self.needle_nodes] = np.where(self.sticking, 1.0, 2.0)
        return state


def summarize(steps: list) -> InsertionResult:
    """An InsertionResult over NeedleStepResults."""
    rearrangements = sum(s.rearrangements for s in steps)
    seconds = sum(s.seconds for s in steps)
    iterations = sum(s.solver_iterations for s in steps)
    failed = [s for s in steps if not s.converged]
    return InsertionResult(
        updates=len(steps), rearrangements=rearrangements, seconds=seconds,
        update_rate=rearrangements / seconds if seconds > 0 else float("inf"),
        mean_iterations=iterations / rearrangements if rearrangements else 0.0,
        max_iterations=max((s.max_solver_iterations for s in steps), default=0),
        converged=not failed, reason=failed[0].reason if failed else "CONVERGED", steps=steps,
        extensions=sum(s.extensions for s in steps), halvings=sum(s.halvings for s in steps))


def __getattr__(name):  # the names records had before issue 51 (snede._renamed)
    return _renamed.old_name(__name__, globals(), name)
