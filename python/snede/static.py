"""Static relaxation: linear CG, nonlinear CG and truncated Newton through PETSc (§2.4, §3.1,
§4.4.2). Every PETSc object carries ``options_prefix`` (default ``static_``), so the command
line tunes it: ``-static_snes_monitor``, ``-static_snes_ncg_type fr``,
``-static_snes_linesearch_type snede_secant``, ``-static_ksp_monitor``, ``-log_view``.
"""
from __future__ import annotations

from snede import _checks, _records, _snede
from snede._petsc import option_list
from snede.distributed_body import RunsOnRanks, on_ranks
from snede._snede import SolveResult, StaticOptions

#: the names ``method`` takes, from the engine's table (static_options.hpp)
METHODS = tuple(_snede.static_methods)
LINE_SEARCHES = ("cp", "snede_newton", "snede_secant", "bt", "l2", "basic")
NCG_TYPES = ("prp", "fr", "hs", "dy", "cd")


class StaticSolver(RunsOnRanks):
    """``StaticSolver(body, method="newton", rtol=1e-6, ...)``; ``solve()`` relaxes
    ``body.displacement`` in place and returns a :class:`snede.SolveResult`.

    * ``options``: a :class:`snede.StaticOptions` record holding every setting below but
      ``line_search``, ``ncg_type`` and ``comm`` (default: ``StaticOptions()``, whose fields are
      the defaults: method ``"newton"``, rtol 1e-6, criterion ``"6.9"``, round_tolerance 1e-12,
      max_iterations 10000, options_prefix ``"static_"``). A keyword given (not None) changes
      its field of that record; the record checks each value (a ValueError or TypeError naming
      the field), the engine the whole at construction.

    * ``method``: ``"cg"`` (linear CG, LinearElastic only), ``"ncg"`` (nonlinear CG,
      Polak-Ribière by default; ``ncg_type="fr"`` for Fletcher-Reeves) or ``"newton"``
      (truncated Newton: inner CG with Eisenstat-Walker tolerances, stopped at negative
      curvature; a direction that does not go downhill, which PETSc's CG returns when its first
      direction has negative curvature, is replaced by the steepest descent, so that a
      wrinkling membrane does not end in DIVERGED_LINE_SEARCH).
    * ``line_search`` (ncg): ``"snede_secant"`` (default: the secant method of §4.4.2, whose
      first slope comes from a tangent action, so it needs no scale), ``"snede_newton"``
      (Newton on the directional derivative), or ``"cp"`` (PETSc's secant on the directional
      derivative from λ = 0 and the initial step ``snes_linesearch_damping``: the thesis's
      scale-dependent secant; set the damping to the problem's step scale).
    * ``criterion``: ``"6.9"`` (default; ‖r‖ ≤ rtol·√(‖f_ext‖² + ‖f_react‖²) plus a round-off
      floor) or ``"6.8"`` (‖r‖ ≤ rtol·‖f_ext‖).
    * ``petsc_options``: a dict of PETSc options without the prefix, e.g.
      ``{"snes_monitor": None, "snes_max_it": 50}``. They, ``line_search`` and ``ncg_type``
      apply to this solver only, not to later solvers with the same prefix; the command line
      (PETSc's global options, as they are when the solver is made) still wins.

    * ``preconditioner`` (cg and newton): the PETSc PC of the CG. ``"none"``; ``"jacobi"``
      (the diagonal of the tangent, computed element by element: no matrix); ``"gamg"``
      (algebraic multigrid on a tangent assembled from the same element kernels, with the
      rigid-body modes as near null space; refilled at every Newton iteration unless
      ``-static_snes_lag_preconditioner k`` lags it, rebuilt after a cut or refinement); or any
      PETSc PC that works on an assembled matrix (``"ilu"``, ``"icc"``, ``"sor"``, ``"lu"``);
      or ``"mg"``: multigrid for any mesh, membranes included. On a mesh refined with ``mesh.refine_uniform``
      or ``refine_around`` whose coarser cuts through the refinement tree are conforming (§6.5),
      the levels are those coarser meshes, each with its own matrix-free tangent shell over the
      same element kernels (linearised at the injected state), Chebyshev/Jacobi smoothing and LU
      on the coarsest level. On any other mesh — made by gmsh, read from a file, or cut, flipped
      or collapsed since its refinement — the coarse level is the piecewise linear space of a
      background grid over the reference configuration, with one copy of a grid node per
      connected piece of the fine vertices it reaches (virtual nodes: a cut never ties the
      lips), and a Galerkin coarse operator from the tangent assembled by the element kernels,
      filled at the first Newton iteration of a solve and kept through its next iterations and
      the next solves while the mesh and the constraints' projections stay the same (a grasper
      dragging a patch held at a moving displacement), until a Newton iteration needs more than
      ``-static_mg_refresh_ratio`` (default 2; 0: filled once per solve) times the CG
      iterations of the first one after they were filled, or a solve fails: then they are filled
      again at the state of now; ``-static_mg_coarsening aggregation`` takes rigid-motion
      aggregates instead. Levels are made anew at the first solve after a mesh change (after a
      change of constraints alone, Newton's grid or aggregation levels are refilled instead;
      after vertices only moved, a cut's snap, they are carried over as they are until they show
      their age; after elements changed, a linear material's assembled tangent is made from the
      earlier one, only the blocks the edit touched computed; ``-static_rebuild_after_edits``
      makes everything anew after every edit); ``follow_seconds`` says what that cost,
      ``preconditioner_fills`` how often the preconditioner was filled, ``multigrid_builds`` how
      often levels were made (``multigrid_edits`` of them from the earlier ones), ``tangent_assemblies`` how often every element's matrix was assembled. ``multigrid_source`` says which kind is in use
      (``"bisection"``, ``"grid"``, ``"aggregation"``), ``multigrid_levels`` and
      ``multigrid_unknowns`` the levels' sizes; ``-static_mg_coarsening`` chooses (default
      ``auto``: bisection when it applies and its coarsest level is at most a sixteenth of
      the mesh or 1 000 unknowns, else grid), ``-static_mg_grid_width`` (in vertex spacings,
      (volume / vertices)^(1/d), at least 1, default 4),
      ``-static_mg_aggregate_width`` and ``-static_mg_aggregation_smoothing`` tune the coarse
      spaces. ``-static_mg_levels_ksp_type``, ``-static_pc_mg_levels`` and the other
      ``-static_mg_*`` options of PETSc's PCMG tune it (docs/results/interactive.md).
      ``"auto"``: ``"mg"`` for cg and newton on meshes of 1 000 cells or more, membranes
      included (where it measured faster than no preconditioner), else ``"none"``; chosen
      again when the mesh crosses that size (a needle's refinement grows it).
      On a membrane every preconditioner assembled from element matrices takes each element's
      positive part (compressed, wrinkling elements are indefinite). None (default):
      ``-static_pc_type`` if given, else ``"auto"``. ``-static_pc_type`` on the command line wins
      over the argument. The shell stays the operator in every case.

    * ``comm`` (an mpi4py communicator): ``solve()`` is collective and runs over all its ranks
      (issue 18, ``snede.distributed_body``), one included: rank 0's body is distributed, its
      fixed vertices and external forces become a :class:`snede.DistributedStatic`, and the same
      engine solver (the same methods, criteria, options and preconditioners) solves it from the
      body's displacement; the result is gathered into ``body.displacement`` on every rank. The
      problem and its solver are kept while the body's mesh and conditions stay the same. On
      ranks ``"mg"`` coarsens by aggregation of each rank's vertices (``-static_mg_coarsening``
      aggregation or auto; bisection and grid levels need the whole mesh), ``"lu"`` and
      ``"cholesky"`` factor with MUMPS, ``"bjacobi"`` is ILU(0) on each rank's block and
      ``"sor"`` sweeps each rank's rows; ``"auto"`` chooses as serially (but none on a
      membrane, which has no ``"mg"`` on ranks). ``part`` is this rank's
      part. Every rank must pass the same arguments (else every rank raises ValueError naming
      them). None (default): the body's ``comm``, and without one the serial solver.

    ``solve()`` first checks that every piece of the body (cells joined through faces) is held:
    a piece whose constraints do not stop all its rigid motions (3 in 2D, 6 in 3D; vertices on
    one line leave the rotation about it), or a membrane piece with fewer than 6 constrained
    displacement components, e.g. one a cut freed of its supports, has no static solution, and raises
    ValueError at once naming it (``body.fix_free_pieces()`` or ``body.fix`` holds it).

    Every method solves the system divided by the force scale E·t·H (E·H² in 3D), so that the
    answer does not depend on the units (E from 1e-3 to 1e155 Pa give the same displacement);
    ``-static_ksp_monitor`` prints residual norms divided by it, while ``SolveResult``
    reports them in newtons.
    """

    _on_ranks = "solve() and part (the others after the first solve())"

    def __init__(self, body, method: str | None = None, rtol: float | None = None, *,
                 options: StaticOptions | None = None, criterion: str | None = None,
                 round_tolerance: float | None = None, max_iterations: int | None = None, line_search: str | None = None,
                 ncg_type: str | None = None, options_prefix: str | None = None, petsc_options: dict | None = None,
                 preconditioner: str | None = None, comm=None):
        max_iterations = _checks.optional_count(max_iterations, "max_iterations", 1)
        if preconditioner is not None and (not isinstance(preconditioner, str) or not preconditioner.strip()):
            raise ValueError(f"preconditioner must be a PETSc PC type name such as 'none', 'jacobi' or 'gamg', "
                             f"got {preconditioner!r}")
        settings = _records.settings(StaticOptions, options, method=method, rtol=rtol, criterion=criterion,
                                     round_tolerance=round_tolerance, max_iterations=max_iterations,
                                     options_prefix=options_prefix, preconditioner=preconditioner)
        # petsc_options (a dict) replaces the record's; line_search and ncg_type add to them
        extra = dict(settings.petsc_options) if petsc_options is None else dict(petsc_options)
        if line_search is not None:
            if settings.method != "ncg":
                raise ValueError("line_search applies to method='ncg'")
            if line_search not in LINE_SEARCHES:
                raise ValueError(f"line_search must be one of {LINE_SEARCHES}, got {line_search!r}")
            extra.setdefault("snes_linesearch_type", line_search)
        if ncg_type is not None:
            if ncg_type not in NCG_TYPES:
                raise ValueError(f"ncg_type must be 'prp' or 'fr' (or hs, dy, cd), got {ncg_type!r}")
            extra.setdefault("snes_ncg_type", ncg_type)
        settings.petsc_options = option_list(extra)
        method = settings.method
        self.body = body
        self.method = method
        self._settings = settings
        self._problem, self._impl = None, None
        self._distributed = on_ranks(body, comm)
        if self._distributed is not None:
            return
        self._impl = _snede.StaticSolver(body._model, self._settings, body.mesh._bisection_if_any())

    @property
    def options(self) -> StaticOptions:
        """A copy of the settings this solver was made with (a :class:`snede.StaticOptions`)."""
        return StaticOptions(**_records.fields(self._settings))

    def solve(self) -> SolveResult:
        if self._distributed is not None:
            return self._solve_distributed()
        # A mesh refined for the first time after this solver was made has a hierarchy now.
        self._impl.use_bisection(self.body.mesh._bisection_if_any())
        return self._impl.solve()

    def _solve_distributed(self) -> SolveResult:
        problem = self._distributed.problem()
        # On the conditions every rank now agrees on: all ranks raise, none waits.
        self._distributed.require_held()
        if problem is not self._problem:  # a new mesh or new conditions: a solver for them
            self._problem, self._impl = problem, _snede.StaticSolver(problem._impl, self._settings)
        result = self._impl.solve()
        self._distributed.gather_into_body(problem)
        return result

    @property
    def preconditioner(self) -> str:
        """The PETSc PC type the CG uses ("none" for ncg)."""
        return self._impl.preconditioner

    @property
    def multigrid_levels(self) -> list[int]:
        """Elements per level of the ``"mg"`` preconditioner, coarsest first, the body's mesh
        last (empty for other preconditioners); rebuilt at the first solve after a mesh change."""
        return list(self._impl.multigrid_levels)

    @property
    def multigrid_unknowns(self) -> list[int]:
        """Unknowns per level of the ``"mg"`` preconditioner, coarsest first, the body's last."""
        return list(self._impl.multigrid_unknowns)

    @property
    def multigrid_source(self) -> str:
        """What made the ``"mg"`` levels: ``"bisection"`` (the mesh's refinement tree), ``"grid"``
        or ``"aggregation"`` (any mesh); empty for other preconditioners."""
        return self._impl.multigrid_source

    @property
    def follow_seconds(self) -> float:
        """Seconds the last ``solve()`` spent following a change of the mesh or of the
        constraints before iterating (new vectors, assembled tangent, multigrid levels)."""
        return self._impl.follow_seconds

    @property
    def preconditioner_fills(self) -> int:
        """How many times this solver filled its preconditioner (an assembled tangent, multigrid
        levels at a state) since it was made: less than once per solve where it reuses one."""
        return self._impl.preconditioner_fills

    @property
    def sparsity_builds(self) -> int:
        """How many times this solver made its assembled tangent's sparsity: once per change of
        the mesh's elements (a cut, a flip, a refinement), not when vertices only moved (a cut
        snapping a vertex onto the blade keeps it; its values are filled again)."""
        return self._impl.sparsity_builds

    @property
    def sparsity_edits(self) -> int:
        """How many of :attr:`sparsity_builds` were made from the earlier sparsity after a cut or
        a refinement: only the rows of the vertices the edit touched are found again
        (``-static_rebuild_after_edits`` makes them from scratch)."""
        return self._impl.sparsity_edits

    @property
    def tangent_assemblies(self) -> int:
        """How many times this solver assembled every element's matrix into its tangent. After a
        cut or a refinement of a body whose tangent does not depend on the state (a linear
        material, not a membrane), Newton with Galerkin levels kept across solves makes the new
        tangent from the earlier one instead: only the blocks the edit touched are computed, the
        others keep their (exact) values (``-static_rebuild_after_edits`` assembles anew)."""
        return self._impl.tangent_assemblies

    @property
    def piece_labellings(self) -> int:
        """How many times this solver labelled every piece of the mesh for its check that the
        constraints hold each one (a solve refuses a piece a cut freed): at the first solve, and
        after a cut only when a piece split off, pieces were joined or a piece is not held;
        otherwise only the pieces of the vertices the edit touched are found again
        (``-static_rebuild_after_edits`` labels them after every change of the elements)."""
        return self._impl.piece_labellings

    @property
    def multigrid_builds(self) -> int:
        """How many times this solver made multigrid levels (a grid, aggregates or a cut through
        the bisection tree, with their interpolations): after a mesh change, or a change of
        constraints the levels did not take over in place. Newton's Galerkin levels keep their
        interpolation through changes of constraints alone (a needle's stick-slip) and are only
        refilled, until they show their age (``-static_mg_refresh_ratio``)."""
        return self._impl.multigrid_builds

    @property
    def multigrid_edits(self) -> int:
        """How many of :attr:`multigrid_builds` were grid levels made from the earlier ones after
        a cut or a refinement of a volume mesh: on the grid of the first build, only the node
        copies the edit reached are found again (``-static_rebuild_after_edits`` makes them from scratch, on the
        same grid)."""
        return self._impl.multigrid_edits

    @property
    def ksp(self):
        """The petsc4py KSP: linear CG's, or Newton's inner one. Made afresh (what was set on
        the old one through petsc4py is lost; command-line options are read again) when the
        preconditioner "auto" chooses again after the mesh grew or shrank past 1 000 cells."""
        return self._impl.ksp

    @property
    def snes(self):
        """The petsc4py SNES (None for linear CG); made afresh as :attr:`ksp` is."""
        return self._impl.snes
