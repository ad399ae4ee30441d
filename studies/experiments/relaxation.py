"""Chapter 4: static relaxation (nonlinear CG) against dynamic relaxation on the Table 4.2
cylinders under gravity (§4.2–§4.5: Tables 4.4 and 4.5, Figures 4.7 and 4.9–4.13, 4.15).

    .venv/bin/python -m studies.experiments.relaxation [--quick] [--out DIR]

The cylinder (Table 4.1: g = 9.8, ρ = 1000, E = 1e4, ν = 0.3, γ = 8) is fixed at x = min and
released under gravity −z from rest. Every run records the energy error
(e, e)_K = ½ eᵀK(û)e, e = u − û, against flops and seconds, where û is the reference of §4.2
(nonlinear CG to ‖r‖ ≤ 1e-2‖f‖, then truncated Newton to 1e-10, 1e-12 for linear).
Recording is excluded from the cost: the monitor's own seconds and flops are subtracted.

Writes relaxation.md, relaxation.csv (one row per table entry, column ``part``),
relaxation_curves.csv (energy error against cost, thinned to about 200 points per run),
relaxation_<material>.png (Figures 4.9–4.13) and relaxation_short_edge.png (Figure 4.15).
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import snede
from snede import PETSc
from studies.experiments.common import (Column, PageTemplate, markdown_table, options_prefix, parse_arguments, pyplot,
                                        save_figure, write_csv)

MESHES = Path(__file__).resolve().parents[2] / "meshes"
GRAVITY, DENSITY, YOUNG, POISSON, VERONDA_GAMMA = 9.8, 1000.0, 1e4, 0.3, 8.0
MATERIALS = {
    "LinearElastic": lambda young: snede.LinearElastic(young, POISSON),
    "StVenantKirchhoff": lambda young: snede.StVenantKirchhoff(young, POISSON),
    "NeoHookean": lambda young: snede.NeoHookean(young, POISSON),
    "VerondaWestmann": lambda young: snede.VerondaWestmann(young, POISSON, VERONDA_GAMMA),
}
THESIS_TABLE_4_4 = {"LinearElastic": 17.0, "StVenantKirchhoff": 20.0, "NeoHookean": 21.0, "VerondaWestmann": 27.0}
THESIS_STIFF_ETA = 27.0  # Figure 4.13: St. Venant-Kirchhoff with E = 2e4
THESIS_PEAK_MFLOPS = 246.0  # Pentium III, repeated add of a 1024-double vector
THESIS_CRITICAL_STEP_MS = 1.0  # §4.6: "approximately 1 ms" on the small mesh
# Table 4.5: (material, mesh, method) -> (% peak, iterations/s, MFLOP/iteration)
THESIS_TABLE_4_5 = {
    ("LinearElastic", "small", "dynamic"): (49, 628, 0.2), ("LinearElastic", "small", "linear CG"): (56, 708, 0.2),
    ("StVenantKirchhoff", "small", "NCG Newton"): (48, 71, 1.7),
    ("StVenantKirchhoff", "small", "NCG secant"): (53, 113, 1.2),
    ("StVenantKirchhoff", "small", "dynamic"): (62, 426, 0.4),
    ("NeoHookean", "small", "NCG Newton"): (85, 109, 1.9), ("NeoHookean", "small", "NCG secant"): (77, 144, 1.3),
    ("NeoHookean", "small", "dynamic"): (54, 356, 0.4),
    ("VerondaWestmann", "small", "NCG Newton"): (90, 91, 2.4),
    ("VerondaWestmann", "small", "NCG secant"): (80, 120, 1.7),
    ("VerondaWestmann", "small", "dynamic"): (61, 327, 0.5),
    ("NeoHookean", "large", "NCG Newton"): (73, 12, 14.2), ("NeoHookean", "large", "NCG secant"): (66, 16, 9.9),
    ("NeoHookean", "large", "dynamic"): (49, 41, 2.9),
}
# The scale-dependent secant (PETSc's cp): first trial step α₋₁ in m/N. The thesis's 0.001
# sits in the range where the iteration count barely changes (see the table of α₋₁ in relaxation.md).
CP_DAMPING = 1e-3
CP_DAMPING_SWEEP = (1e-4, 1e-3, 1e-2, 1e-1)
TARGET_REDUCTION = 1e-8  # "converged" for the cost comparisons: (e,e)_K ≤ 1e-8 (e₀,e₀)_K
THESIS_LINEAR_TARGET = 1e-4  # §4.5.4: "an energy error of less than 10⁻⁴"


@dataclass(frozen=True)
class Case:
    """One material setting of the study; ``young`` differs from Table 4.1 only for Figure 4.13."""

    material: str
    young: float = YOUNG

    @property
    def name(self) -> str:
        return self.material if self.young == YOUNG else f"{self.material} E={self.young:g}"

    @property
    def thesis_eta(self) -> float:
        return THESIS_TABLE_4_4[self.material] if self.young == YOUNG else THESIS_STIFF_ETA

    def make_material(self):
        return MATERIALS[self.material](self.young)


@dataclass(frozen=True)
class StaticMethod:
    label: str
    line_search: str
    ncg_type: str

    @property
    def petsc_options(self) -> dict:
        return {"snes_linesearch_damping": CP_DAMPING} if self.line_search == "cp" else {}


STATIC_METHODS = [StaticMethod(f"NCG {name} {beta.upper()}", line_search, beta)
                  for beta in ("prp", "fr")
                  for name, line_search in (("secant", "snede_secant"), ("Newton", "snede_newton"),
                                            ("scale-dep. secant", "cp"))]


@dataclass
class CylinderMesh:
    """Points and cells of a cylinder; every body gets its own ``snede.Mesh`` built from them."""

    label: str
    points: np.ndarray
    cells: np.ndarray

    @classmethod
    def read(cls, label: str, path: Path) -> "CylinderMesh":
        mesh = snede.Mesh.read(path)
        return cls(label, mesh.points, mesh.cells)

    def body(self, material) -> snede.Body:
        mesh = snede.Mesh(self.points, self.cells)
        body = snede.Body(mesh, material, density=DENSITY)
        body.fix(np.isclose(mesh.points[:, 0], mesh.points[:, 0].min()))
        body.add_gravity((0.0, 0.0, -GRAVITY))
        return body


@dataclass
class Reference:
    """The 'exact' solution û of §4.2 and the energy error measured against it."""

    body: snede.Body
    displacement: np.ndarray
    converged: bool
    residual_norm: float
    tolerance: float

    def energy_error(self, u) -> float:
        """(e, e)_K = ½ eᵀ K(û) e with e = u − û."""
        e = np.asarray(u).reshape(self.displacement.shape) - self.displacement
        return 0.5 * float(np.sum(e * self.body.tangent_apply(self.displacement, e)))

    @property
    def initial_error(self) -> float:
        return self.energy_error(np.zeros_like(self.displacement))

    def potential_energy(self, u) -> float:
        """Π(u) = Π_int(u) − f_extᵀu."""
        u = np.asarray(u).reshape(self.displacement.shape)
        return self.body.energy(u) - float(np.sum(self.body.external_forces() * u))


def newton_reference(mesh: CylinderMesh, case: Case) -> Reference:
    """§4.2: nonlinear CG to ‖r‖ ≤ 1e-2‖f_ext‖, then truncated Newton to 1e-10 (1e-12 for the
    linear material), criterion (6.8). Newton's default backtracking stops at round-off on some
    of these problems (DIVERGED_LINE_SEARCH near 1e-8); it is then continued with PETSc's cp
    line search, whose absolute slope tolerance is switched off (its default 1e-15 declares
    convergence at the first step here, where forces are ~0.01 N and steps ~1e-8 m)."""
    body = mesh.body(case.make_material())
    rtol = 1e-12 if case.material == "LinearElastic" else 1e-10
    snede.StaticSolver(body, "ncg", rtol=1e-2, criterion="6.8", options_prefix=options_prefix("reference_ncg")).solve()
    for line_search in ("bt", "cp"):
        result = snede.StaticSolver(body, "newton", preconditioner="none",
                                    rtol=rtol, criterion="6.8", max_iterations=200,
                                    options_prefix=options_prefix("reference_newton"),
                                    petsc_options={"snes_linesearch_type": line_search,
                                                   "snes_linesearch_atol": 0.0}).solve()
        converged = result.converged and result.residual_norm <= result.tolerance
        if converged:
            break
    return Reference(body, body.displacement, converged, result.residual_norm, result.tolerance)


@dataclass
class Curve:
    """Energy error against cost along one run; ``outcome`` is the solver's own verdict."""

    label: str
    iterations: list = field(default_factory=list)
    mflop: list = field(default_factory=list)
    seconds: list = field(default_factory=list)
    energy_error: list = field(default_factory=list)
    converged: bool = False
    reason: str = ""
    final_energy_difference: float = float("nan")  # Π(u_end) − Π(û)

    def cost_to_reach(self, target: float) -> dict | None:
        """Iterations, MFLOP and seconds at the first recorded state with error ≤ target."""
        below = np.flatnonzero(np.asarray(self.energy_error) <= target)
        if not len(below):
            return None
        i = below[0]
        return {"iterations": self.iterations[i], "mflop": self.mflop[i], "seconds": self.seconds[i]}


class CostRecorder:
    """A PETSc monitor (SNES, TS or KSP) that appends (iteration, cost, energy error) to a
    curve every ``every`` iterations. The seconds and flops it spends itself are subtracted,
    so the recorded cost is that of the solver alone."""

    def __init__(self, reference: Reference, curve: Curve, every: int = 1, offset=None):
        self.reference, self.curve, self.every = reference, curve, every
        self.offset = 0.0 if offset is None else np.asarray(offset).ravel()  # KSP solves for an increment
        self._last_iteration = -1

    def start(self) -> None:
        self._start_seconds, self._start_flops = time.perf_counter(), PETSc.Log.getFlops()
        self._excluded_seconds = self._excluded_flops = 0.0

    def record(self, iteration: int, u) -> None:
        if iteration == self._last_iteration or iteration % self.every:
            return
        now, flops = time.perf_counter(), PETSc.Log.getFlops()
        self._last_iteration = iteration
        curve = self.curve
        curve.iterations.append(int(iteration))
        curve.seconds.append(now - self._start_seconds - self._excluded_seconds)
        curve.mflop.append((flops - self._start_flops - self._excluded_flops) / 1e6)
        curve.energy_error.append(self.reference.energy_error(u.getArray() + self.offset))
        self._excluded_seconds += time.perf_counter() - now
        self._excluded_flops += PETSc.Log.getFlops() - flops

    def snes_monitor(self, snes, iteration, fnorm) -> None:
        self.record(iteration, snes.getSolution())

    def ts_monitor(self, ts, step, t, u) -> None:
        self.record(step, u)

    def ksp_monitor(self, ksp, iteration, rnorm) -> None:
        self.record(iteration, ksp.getSolution())

    def latest_error(self) -> float:
        return self.curve.energy_error[-1] if self.curve.energy_error else float("inf")


def finish_curve(curve: Curve, result, reference: Reference, body) -> Curve:
    curve.converged, curve.reason = result.converged, result.reason
    u = body.displacement
    curve.final_energy_difference = reference.potential_energy(u) - reference.potential_energy(reference.displacement)
    return curve


def static_curve(mesh: CylinderMesh, case: Case, reference: Reference, method: StaticMethod | None,
                 rtol: float, every: int = 1) -> Curve:
    """Nonlinear CG with ``method``, or linear CG (method None, linear material), from rest
    to ‖r‖ ≤ rtol under criterion (6.9)."""
    body = mesh.body(case.make_material())
    curve = Curve(method.label if method else "linear CG")
    if method is None:
        solver = snede.StaticSolver(body, "cg", preconditioner="none",
                                    rtol=rtol, max_iterations=100000, options_prefix=options_prefix("cg"))
        recorder = CostRecorder(reference, curve, every, offset=body.displacement)
        solver.ksp.setMonitor(recorder.ksp_monitor)
    else:
        solver = snede.StaticSolver(body, "ncg", rtol=rtol, max_iterations=100000, line_search=method.line_search,
                                    ncg_type=method.ncg_type, options_prefix=options_prefix(method.label),
                                    petsc_options=method.petsc_options)
        recorder = CostRecorder(reference, curve, every)
        solver.snes.setMonitor(recorder.snes_monitor)
    recorder.start()
    return finish_curve(curve, solver.solve(), reference, body)


def critical_time_step(mesh: CylinderMesh, case: Case) -> float:
    """§4.4.1: the largest step at which an undamped run from rest does not blow up within
    50 MFLOP, searched from the CFL estimate in steps of 15 %."""
    body = mesh.body(case.make_material())
    return snede.DynamicRelaxation(body, damping=0.0, options_prefix=options_prefix("critical")).critical_time_step()


def dynamic_curve(mesh: CylinderMesh, case: Case, reference: Reference, eta: float, dt: float, rtol: float,
                  every: int = 1, max_steps: int = 300000) -> Curve:
    """Dynamic relaxation with damping η and step dt from rest to ‖r‖ ≤ rtol (6.9)."""
    body = mesh.body(case.make_material())
    dynamics = snede.DynamicRelaxation(body, damping=eta, dt=dt, options_prefix=options_prefix("dynamic"))
    curve = Curve(f"dynamic η={eta:.3g}")
    recorder = CostRecorder(reference, curve, every)
    dynamics.ts.setMonitor(recorder.ts_monitor)
    recorder.start()
    return finish_curve(curve, dynamics.run(rtol=rtol, max_steps=max_steps), reference, body)


def stable_dynamic_curve(mesh: CylinderMesh, case: Case, reference: Reference, eta: float, dt: float, rtol: float,
                         every: int = 1, max_reductions: int = 6) -> tuple[Curve, float, int]:
    """``dynamic_curve`` at dt; if the run diverges (blow-up or inverted elements: §4.4.1's trial
    only covers the first steps from rest, not the deformed state), again at a step lowered by
    15 % at a time. Returns the curve, the step used and the number of reductions."""
    for reductions in range(max_reductions + 1):
        step = dt * 0.85 ** reductions
        curve = dynamic_curve(mesh, case, reference, eta, step, rtol, every=max(1, round(every * dt / step)))
        if curve.converged or not curve.reason.startswith("DIVERGED_") or curve.reason == "DIVERGED_MAX_IT":
            break
    return curve, step, reductions


def steps_to_target(mesh: CylinderMesh, case: Case, reference: Reference, eta: float, dt: float, target: float,
                    max_steps: int, chunk: int = 100) -> int | None:
    """Time steps until (e,e)_K ≤ target (None if not within max_steps or on blow-up)."""
    body = mesh.body(case.make_material())
    dynamics = snede.DynamicRelaxation(body, damping=eta, dt=dt, options_prefix=options_prefix("damping_search"))
    curve = Curve("search")
    recorder = CostRecorder(reference, curve)
    dynamics.ts.setMonitor(recorder.ts_monitor)
    recorder.start()
    while recorder.latest_error() > target and (not curve.iterations or curve.iterations[-1] < max_steps):
        if not dynamics.step(chunk).converged:
            return None
    reached = curve.cost_to_reach(target)
    return reached["iterations"] if reached else None


def damping_search(mesh: CylinderMesh, case: Case, reference: Reference, dt: float, grid, max_steps: int):
    """§4.4.1's trial and error: the η on ``grid`` that reaches (e,e)_K ≤ 1e-8 (e₀,e₀)_K in the
    fewest steps, refined by ±1 s⁻¹ around the best grid value."""
    target = TARGET_REDUCTION * reference.initial_error
    steps = {eta: steps_to_target(mesh, case, reference, eta, dt, target, max_steps) for eta in grid}

    def best():
        return min((eta for eta in steps if steps[eta] is not None), key=lambda eta: (steps[eta], eta))

    for eta in (best() - 1.0, best() + 1.0):
        if eta > 0 and eta not in steps:
            steps[eta] = steps_to_target(mesh, case, reference, eta, dt, target, max_steps)
    return best(), steps


# -- Table 4.5: machine peak and throughput ------------------------------------------------------
def best_rate(operation, work: float, repeats: int, rounds: int = 3) -> float:
    """``work`` units per second of ``operation``, best of ``rounds`` timings of ``repeats`` calls."""
    best = float("inf")
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(repeats):
            operation()
        best = min(best, time.perf_counter() - start)
    return work * repeats / best


def machine_peak(quick: bool) -> list[dict]:
    """(a) the thesis's baseline, a repeated vector add: at 1024 doubles (as in §4.5.2), at 32768
    (in cache, long enough to amortise Python's call overhead) and far beyond the caches, with
    numpy (a += b, 1 flop per entry) and PETSc VecAXPY (y += αx, 2 flops per entry); (b) a
    STREAM triad a = b + s·c beyond the caches: PETSc VecWAXPY in one pass and numpy in two
    passes (24 bytes and 2 flops per entry counted, as STREAM does)."""
    rows = []
    scale = 0.1 if quick else 1.0
    large = 2 ** 22 if quick else 2 ** 24
    for n in (1024, 32768, large):
        a, b = np.ones(n), np.full(n, 1e-9)
        x, y = PETSc.Vec().createWithArray(np.ones(n)), PETSc.Vec().createWithArray(np.full(n, 1e-9))
        repeats = max(5, int(scale * 2e8 / n))
        for kernel, operation, flops in (("numpy a += b", lambda: np.add(a, b, out=a), 1),
                                         ("PETSc VecAXPY", lambda: y.axpy(1e-9, x), 2)):
            rows.append({"part": "peak", "kernel": kernel, "entries": n, "in_cache": n <= 32768,
                         "mflops": best_rate(operation, flops * n / 1e6, repeats)})
    b, c, a = np.ones(large), np.ones(large), np.empty(large)
    x, y, w = (PETSc.Vec().createWithArray(v) for v in (np.ones(large), np.ones(large), np.empty(large)))

    def numpy_triad():
        np.multiply(c, 3.0, out=a)
        np.add(a, b, out=a)

    for kernel, operation in (("PETSc VecWAXPY triad", lambda: w.waxpy(3.0, x, y)), ("numpy triad", numpy_triad)):
        entries_per_second = best_rate(operation, large, repeats=5 if quick else 20)
        rows.append({"part": "peak", "kernel": kernel, "entries": large, "in_cache": False,
                     "mflops": 2 * entries_per_second / 1e6, "gbytes_per_s": 24 * entries_per_second / 1e9})
    return rows


def throughput(mesh: CylinderMesh, case: Case, method: str, eta: float, dt: float, rtol: float) -> dict:
    """Iterations per second and MFLOP per iteration of an unmonitored run (Table 4.5)."""
    body = mesh.body(case.make_material())
    if method == "dynamic":
        result = snede.DynamicRelaxation(body, damping=eta, dt=dt, options_prefix=options_prefix("rate")).run(
            rtol=rtol, max_steps=300000)
    elif method == "linear CG":
        result = snede.StaticSolver(body, "cg", preconditioner="none", rtol=rtol, max_iterations=100000,
                                    options_prefix=options_prefix("rate")).solve()
    else:
        line_search = {"NCG secant": "snede_secant", "NCG Newton": "snede_newton"}[method]
        result = snede.StaticSolver(body, "ncg", rtol=rtol, max_iterations=100000, line_search=line_search,
                                    options_prefix=options_prefix("rate")).solve()
    return {"part": "table_4_5", "case": case.name, "mesh": mesh.label, "method": method,
            "iterations": result.iterations, "seconds": result.seconds, "converged": result.converged,
            "iterations_per_second": result.iterations / result.seconds,
            "mflop_per_iteration": result.flops / 1e6 / max(result.iterations, 1),
            "mflops": result.flops / 1e6 / result.seconds}


# -- Figure 4.15: one short edge -------------------------------------------------------------------
def short_edge_choice(mesh: CylinderMesh, smallest_ratio: float) -> tuple[int, int]:
    """An interior vertex a near the middle of the cylinder and a neighbour b such that moving
    a onto b + r(a − b) keeps every cell positively oriented for all r ≥ smallest_ratio (the
    volumes are linear in r, so checking the smallest r suffices)."""
    boundary = np.zeros(len(mesh.points), dtype=bool)
    boundary[snede.Mesh(mesh.points, mesh.cells).boundary_faces().ravel()] = True
    centre = 0.5 * (mesh.points.min(axis=0) + mesh.points.max(axis=0))
    for a in np.argsort(np.linalg.norm(mesh.points - centre, axis=1)):
        if boundary[a]:
            continue
        star = mesh.cells[np.any(mesh.cells == a, axis=1)]
        for b in np.unique(star[star != a]):
            points = moved_vertex(mesh.points, a, b, smallest_ratio)
            corners = points[star]
            volumes = np.einsum("ij,ij->i", np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                                corners[:, 3] - corners[:, 0])
            if np.all(volumes > 0):
                return int(a), int(b)
    raise RuntimeError("no interior edge can be shortened without inverting a cell")


def moved_vertex(points: np.ndarray, a: int, b: int, ratio: float) -> np.ndarray:
    """Points with vertex a moved along the edge towards b, so that |ab| becomes ratio·|ab|."""
    moved = points.copy()
    moved[a] = points[b] + ratio * (points[a] - points[b])
    return moved


def edge_lengths(mesh: CylinderMesh) -> np.ndarray:
    pairs = np.concatenate([mesh.cells[:, [i, j]] for i, j in itertools.combinations(range(4), 2)])
    pairs = np.unique(np.sort(pairs, axis=1), axis=0)
    return np.linalg.norm(mesh.points[pairs[:, 0]] - mesh.points[pairs[:, 1]], axis=1)


def short_edge_study(mesh: CylinderMesh, ratios, eta: float, rtol: float, dt_original: float):
    """Figure 4.15 on the small mesh: linear CG (linear material) and, for neo-Hookean, nonlinear
    CG with the secant and the scale-dependent secant line searches and dynamic relaxation at
    η* with the critical step of each mesh."""
    a, b = short_edge_choice(mesh, min(ratios))
    rows, curves = [], {}
    for ratio in ratios:
        shortened = CylinderMesh(f"edge×{ratio:g}", moved_vertex(mesh.points, a, b, ratio), mesh.cells)
        quality = snede.Mesh(shortened.points, shortened.cells).quality()
        geometry = {"part": "short_edge", "ratio": ratio, "vertex": a, "neighbour": b,
                    "shortest_edge": float(edge_lengths(shortened).min()),
                    "min_aspect_ratio": float(quality.aspect_ratio.min())}
        linear, neo = Case("LinearElastic"), Case("NeoHookean")
        linear_reference, neo_reference = newton_reference(shortened, linear), newton_reference(shortened, neo)
        dt = critical_time_step(shortened, neo)
        dynamic, step, reductions = stable_dynamic_curve(shortened, neo, neo_reference, eta, dt, rtol,
                                                         every=max(1, round(dt_original / dt)))
        runs = [("linear CG (linear)", static_curve(shortened, linear, linear_reference, None, rtol), linear_reference),
                ("NCG secant PRP", static_curve(shortened, neo, neo_reference, STATIC_METHODS[0], rtol), neo_reference),
                ("NCG scale-dep. secant PRP", static_curve(shortened, neo, neo_reference, STATIC_METHODS[2], rtol),
                 neo_reference),
                (f"dynamic η={eta:.3g}", dynamic, neo_reference)]
        for method, curve, reference in runs:
            reached = curve.cost_to_reach(TARGET_REDUCTION * reference.initial_error)
            curves[(method, ratio)] = curve
            is_dynamic = method.startswith("dynamic")
            rows.append({**geometry, "method": method, "critical_step_ms": 1e3 * dt if is_dynamic else None,
                         "time_step_used_ms": 1e3 * step if is_dynamic else None,
                         "step_reductions": reductions if is_dynamic else None,
                         "converged": curve.converged, "reason": curve.reason,
                         "iterations": curve.iterations[-1], "mflop": curve.mflop[-1], "seconds": curve.seconds[-1],
                         "iterations_to_target": reached and reached["iterations"],
                         "mflop_to_target": reached and reached["mflop"],
                         "seconds_to_target": reached and reached["seconds"]})
    return rows, curves


# -- the study ---------------------------------------------------------------------------------
def cp_damping_rows(mesh: CylinderMesh, cases, rtol: float) -> list[dict]:
    """How the scale-dependent secant depends on its first trial step α₋₁."""
    rows = []
    for case in cases:
        for damping in CP_DAMPING_SWEEP:
            body = mesh.body(case.make_material())
            result = snede.StaticSolver(body, "ncg", rtol=rtol, max_iterations=20000, line_search="cp",
                                        options_prefix=options_prefix("cp_sweep"),
                                        petsc_options={"snes_linesearch_damping": damping}).solve()
            rows.append({"part": "cp_damping", "case": case.name, "mesh": mesh.label, "damping": damping,
                         "converged": result.converged, "reason": result.reason, "iterations": result.iterations,
                         "mflop": result.flops / 1e6})
    return rows


def convergence_runs(mesh: CylinderMesh, case: Case, settings: dict, static_methods, eta_best: float | None = None,
                     every: int = 1):
    """Reference, critical step, damping search (unless η* is given) and every recorded run of
    one case on one mesh, recording every ``every`` iterations. Returns (summary rows, damping
    rows, curves, η*, dt, reference)."""
    reference = newton_reference(mesh, case)
    dt = critical_time_step(mesh, case)
    damping_rows = []
    if eta_best is None:
        eta_best, steps = damping_search(mesh, case, reference, dt, settings["eta_grid"], settings["max_search_steps"])
        damping_rows = [{"part": "damping_search", "case": case.name, "mesh": mesh.label, "eta": eta,
                         "steps_to_target": n, "best": eta == eta_best} for eta, n in sorted(steps.items())]
    methods = [m for m in STATIC_METHODS if m.label in static_methods]
    runs = [(static_curve(mesh, case, reference, method, settings["rtol"], every), None) for method in methods]
    if case.material == "LinearElastic":
        runs.insert(0, (static_curve(mesh, case, reference, None, settings["rtol"], every), None))
    for factor in settings["eta_factors"]:
        curve, step, _ = stable_dynamic_curve(mesh, case, reference, factor * eta_best, dt, settings["rtol"], every)
        runs.append((curve, step))
    target = TARGET_REDUCTION * reference.initial_error
    rows = []
    for curve, step in runs:
        reached = curve.cost_to_reach(target)
        thesis_level = curve.cost_to_reach(THESIS_LINEAR_TARGET)
        rows.append({
            "part": "convergence", "case": case.name, "mesh": mesh.label, "tetrahedra": len(mesh.cells),
            "method": curve.label, "eta_best": eta_best, "critical_step_ms": 1e3 * dt,
            "time_step_used_ms": step and 1e3 * step,
            "reference_converged": reference.converged, "reference_residual": reference.residual_norm,
            "initial_error": reference.initial_error, "converged": curve.converged, "reason": curve.reason,
            "iterations": curve.iterations[-1], "mflop": curve.mflop[-1], "seconds": curve.seconds[-1],
            "final_error": curve.energy_error[-1], "final_energy_difference": curve.final_energy_difference,
            "iterations_to_target": reached and reached["iterations"], "mflop_to_target": reached and reached["mflop"],
            "seconds_to_target": reached and reached["seconds"],
            "seconds_to_1e-4_J": thesis_level and thesis_level["seconds"]})
    return rows, damping_rows, [curve for curve, _ in runs], eta_best, dt, reference


def modal_eigenvalues(reference: Reference) -> np.ndarray:
    """Eigenvalues of M⁻¹K(û) on the free dofs (lumped M), ascending: §4.1's analysis linearised
    at the solution. Dense, column by column from tangent actions: for the small mesh only."""
    body = reference.body
    points = body.mesh.points
    free = np.repeat(~np.isclose(points[:, 0], points[:, 0].min()), 3)
    columns = []
    for dof in np.flatnonzero(free):
        unit = np.zeros(free.size)
        unit[dof] = 1.0
        columns.append(body.tangent_apply(reference.displacement, unit.reshape(-1, 3)).ravel()[free])
    stiffness = np.array(columns).T
    mass = np.repeat(body.lumped_mass(), 3)[free]
    scaled = stiffness / np.sqrt(np.outer(mass, mass))
    return np.linalg.eigvalsh(0.5 * (scaled + scaled.T))


def thinned(curve: Curve, n: int = 200) -> list[int]:
    """About n indices, logarithmically spaced in iteration count, always the first and last."""
    count = len(curve.iterations)
    return sorted(set(np.unique(np.geomspace(1, count, n).astype(int) - 1).tolist()) | {0, count - 1})


def curve_rows(curves_by_key: dict) -> list[dict]:
    rows = []
    for (case, mesh, label), curve in curves_by_key.items():
        rows += [{"case": case, "mesh": mesh, "method": label, "iteration": curve.iterations[i],
                  "mflop": curve.mflop[i], "seconds": curve.seconds[i], "energy_error": curve.energy_error[i]}
                 for i in thinned(curve)]
    return rows


def line_style(label: str) -> dict:
    if label.startswith("dynamic"):
        return {"color": "C3", "ls": "-"}
    if label == "linear CG":
        return {"color": "k", "ls": "-"}
    colour = {"secant": "C0", "Newton": "C1", "scale-dep. secant": "C2"}[label.split(" ", 1)[1].rsplit(" ", 1)[0]]
    return {"color": colour, "ls": "--" if label.endswith("FR") else "-"}


def figure_name(case_name: str) -> str:
    return f"relaxation_{case_name.replace(' ', '_').replace('=', '')}.png"


def plot_convergence(curves: dict, case_name: str, meshes, path: Path) -> None:
    """Figures 4.9–4.13: energy error against MFLOP and seconds, one row per mesh."""
    plt = pyplot()
    figure, axes = plt.subplots(len(meshes), 2, figsize=(11, 4.2 * len(meshes)), squeeze=False)
    for row, mesh in zip(axes, meshes):
        labels = [label for (case, m, label) in curves if case == case_name and m == mesh]
        dynamic = sorted((label for label in labels if label.startswith("dynamic")),
                         key=lambda label: float(label.split("=")[1]))
        for label in labels:
            curve = curves[(case_name, mesh, label)]
            style = line_style(label)
            if label in dynamic:
                style["ls"] = {0: ":", 1: "-", 2: "-."}[dynamic.index(label)] if len(dynamic) == 3 else "-"
            for ax, x in zip(row, (curve.mflop, curve.seconds)):
                ax.semilogy(x, np.maximum(curve.energy_error, 1e-30), lw=1.1, label=label, **style)
        # A run far slower than the rest (Fletcher-Reeves on St. Venant-Kirchhoff) would squeeze
        # the others into the left edge: clip the axis at 1.5× the slowest of the others.
        costs = {label: (curves[(case_name, mesh, label)].mflop[-1], curves[(case_name, mesh, label)].seconds[-1])
                 for label in labels}
        for column, (ax, unit) in enumerate(zip(row, ("MFLOP", "seconds"))):
            ends = sorted(cost[column] for cost in costs.values())
            limit = 1.5 * max(end for end in ends if end <= 3 * ends[len(ends) // 2])
            clipped = ends[-1] > limit
            if clipped:
                ax.set_xlim(0, limit)
            ax.set_xlabel(unit)
            ax.set_ylabel("energy error (e,e)_K [J]")
            ax.set_title(f"{case_name}, {mesh} mesh" + (" (slow runs clipped)" if clipped else ""))
            ax.grid(True, which="both", alpha=0.3)
        row[0].legend(fontsize=7)
    save_figure(figure, path, 110)


def plot_short_edge(curves: dict, path: Path) -> None:
    """Figure 4.15: one panel per method, one curve per edge ratio, energy error against MFLOP."""
    plt = pyplot()
    methods = list(dict.fromkeys(method for method, _ in curves))
    figure, axes = plt.subplots(1, len(methods), figsize=(4.2 * len(methods), 4), squeeze=False)
    for ax, method in zip(axes[0], methods):
        for (m, ratio), curve in curves.items():
            if m == method:
                ax.semilogy(curve.mflop, np.maximum(curve.energy_error, 1e-30), lw=1.1, label=f"edge × {ratio:g}")
        ax.set_title(method, fontsize=9)
        ax.set_xlabel("MFLOP")
        ax.set_ylabel("energy error (e,e)_K [J]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    save_figure(figure, path, 110)


def settings_for(quick: bool) -> dict:
    if quick:
        return {"meshes": {"small": MESHES / "cylinder_small.msh"}, "large_cases": (),
                "cases": (Case("LinearElastic"), Case("NeoHookean")), "rtol": 1e-6,
                "static_methods": ("NCG secant PRP", "NCG secant FR", "NCG scale-dep. secant PRP"),
                "large_static_methods": (), "large_every": 1,
                "eta_grid": (14.0, 20.0, 28.0), "eta_factors": (1.0,), "max_search_steps": 20000,
                "short_edge_ratios": (1.0, 0.01), "cp_cases": ()}
    return {"meshes": {"small": MESHES / "cylinder_small.msh", "large": MESHES / "cylinder_large.msh"},
            "large_cases": tuple(MATERIALS),
            "cases": tuple(Case(m) for m in MATERIALS) + (Case("StVenantKirchhoff", 2e4),), "rtol": 1e-7,
            "static_methods": tuple(m.label for m in STATIC_METHODS),
            "large_static_methods": tuple(m.label for m in STATIC_METHODS if m.ncg_type == "prp"), "large_every": 2,
            "eta_grid": (6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0, 22.0, 24.0, 26.0, 28.0, 31.0, 34.0, 38.0,
                         42.0, 48.0),
            "eta_factors": (2 / 3, 1.0, 1.5), "max_search_steps": 30000,
            "short_edge_ratios": (1.0, 0.1, 0.01, 0.001),
            "cp_cases": (Case("NeoHookean"), Case("VerondaWestmann"), Case("StVenantKirchhoff"))}


CONVERGENCE_COLUMNS = [
    Column("case", "material"), Column("mesh", "mesh"), Column("method", "method"),
    Column("time_step_used_ms", "Δt [ms]", "{:.3f}"), Column("iterations_to_target", "its to target"),
    Column("mflop_to_target", "MFLOP to target", "{:.1f}"), Column("seconds_to_target", "s to target", "{:.3f}"),
    Column("iterations", "its total"),
    Column("mflop", "MFLOP total", "{:.1f}"), Column("final_error", "final (e,e)_K [J]", "{:.1e}"),
    Column("final_energy_difference", "Π(u)−Π(û) [J]", "{:.1e}"), Column("reason", "reason")]
DAMPING_COLUMNS = [Column("case", "material"), Column("eta_best", "η* [1/s] (ours)", "{:g}"),
                   Column("thesis_eta", "η_crit thesis [1/s]", "{:g}"),
                   Column("eta_modal", "2√λ₁ at û [1/s] (§4.1)", "{:.1f}"),
                   Column("critical_step_ms", "critical Δt [ms] (§4.4.1)", "{:.3f}"),
                   Column("stability_limit_ms", "2/√λ_n at û [ms]", "{:.3f}"),
                   Column("steps_at_best", "steps to target at η*")]
PEAK_COLUMNS = [Column("kernel", "kernel"), Column("entries", "entries"),
                Column("mflops", "MFLOP/s", "{:.0f}"), Column("gbytes_per_s", "GB/s", "{:.1f}")]
RATE_COLUMNS = [Column("case", "material"), Column("mesh", "mesh"), Column("method", "relaxation"),
                Column("pct_peak", "% peak (a)", "{:.0f}"), Column("pct_triad", "% triad (b)", "{:.0f}"),
                Column("thesis_pct_peak", "thesis % peak", "{:g}"),
                Column("iterations_per_second", "iter/s", "{:.0f}"), Column("thesis_iterations_per_second",
                                                                             "thesis iter/s", "{:g}"),
                Column("mflop_per_iteration", "MFLOP/iter", "{:.2f}"),
                Column("thesis_mflop_per_iteration", "thesis MFLOP/iter", "{:g}")]
SHORT_EDGE_COLUMNS = [Column("ratio", "edge × r", "{:g}"), Column("shortest_edge", "shortest edge [m]", "{:.2e}"),
                      Column("min_aspect_ratio", "min aspect ratio", "{:.2e}"), Column("method", "method"),
                      Column("critical_step_ms", "critical Δt [ms]", "{:.4f}"),
                      Column("time_step_used_ms", "Δt used [ms]", "{:.4f}"),
                      Column("iterations_to_target", "its to target"),
                      Column("mflop_to_target", "MFLOP to target", "{:.1f}"),
                      Column("seconds_to_target", "s to target", "{:.3f}"), Column("reason", "reason")]
CP_COLUMNS = [Column("case", "material"), Column("damping", "α₋₁ (snes_linesearch_damping)", "{:g}"),
              Column("iterations", "iterations"), Column("mflop", "MFLOP", "{:.0f}"), Column("reason", "reason")]


def ratio(numerator, denominator):
    return numerator / denominator if numerator is not None and denominator else None


def lookup(rows, **keys) -> dict | None:
    return next((row for row in rows if all(row.get(k) == v for k, v in keys.items())), None)


def describe(results: dict, quick: bool) -> str:
    """relaxation.md: studies/templates/relaxation.md filled with the tables and the findings."""
    template = PageTemplate("relaxation")
    convergence, damping, rates, peak = results["convergence"], results["damping"], results["rates"], results["peak"]
    short_edge, cp_rows = results["short_edge"], results["cp_damping"]
    triad = lookup(peak, kernel="PETSc VecWAXPY triad")
    eta_ratio = [row["eta_best"] / row["thesis_eta"] for row in damping]
    steps = [row["critical_step_ms"] for row in damping if row["case"] in THESIS_TABLE_4_4]
    return template.page(
        quick_flag=" --quick" if quick else "", run=template.snippet("quick_run" if quick else "full_run"),
        rtol=results["rtol"], target=TARGET_REDUCTION, cp_damping=CP_DAMPING,
        eta_grid=", ".join(f"{eta:g}" for eta in results["eta_grid"]), damping_table=markdown_table(damping, DAMPING_COLUMNS),
        eta_ratio_min=min(eta_ratio), eta_ratio_max=max(eta_ratio), step_min=min(steps), step_max=max(steps),
        thesis_step=THESIS_CRITICAL_STEP_MS, convergence_table=markdown_table(convergence, CONVERGENCE_COLUMNS),
        figures="\n".join(template.snippet("figure", name=name, file=figure_name(name))
                          for name in dict.fromkeys(row["case"] for row in convergence)),
        peak_a=max(row["mflops"] for row in peak if row["in_cache"]), triad_mflops=triad["mflops"],
        triad_gbytes=triad["gbytes_per_s"], thesis_peak=THESIS_PEAK_MFLOPS, peak_table=markdown_table(peak, PEAK_COLUMNS),
        rates_table=markdown_table(rates, RATE_COLUMNS), vertex=short_edge[0]["vertex"],
        neighbour=short_edge[0]["neighbour"], short_edge_table=markdown_table(short_edge, SHORT_EDGE_COLUMNS),
        cp_section=template.snippet("cp_section", table=markdown_table(cp_rows, CP_COLUMNS)) if cp_rows else "",
        findings="\n".join(findings(results, template)))


def findings(results: dict, template: PageTemplate) -> list[str]:
    """Statements computed from the tables (snippets of ``template``), each comparing with a
    claim of chapter 4."""
    convergence, damping, rates = results["convergence"], results["damping"], results["rates"]
    snippet = template.snippet
    out = []

    def cost(case, mesh, method, key="mflop_to_target"):
        row = lookup(convergence, case=case, mesh=mesh, method=method)
        return row and row[key]

    def dynamic_label(case, mesh):
        eta = lookup(convergence, case=case, mesh=mesh)["eta_best"]
        return f"dynamic η={eta:.3g}"

    for row in damping:
        out.append(snippet(
            "damping", case=row["case"], eta=row["eta_best"], thesis_eta=row["thesis_eta"],
            verdict=snippet("close_to" if abs(row["eta_best"] / row["thesis_eta"] - 1) <= 0.25 else "differs_from"),
            modal=snippet("modal_eta", eta=row["eta_modal"]) if row["eta_modal"] else snippet("no_modal_eta"),
            step=row["critical_step_ms"], limit_ratio=row["critical_step_ms"] / row["stability_limit_ms"]))
    if lookup(convergence, case="LinearElastic", mesh="small", method="linear CG"):
        dyn = dynamic_label("LinearElastic", "small")
        flop_ratio = ratio(cost("LinearElastic", "small", dyn), cost("LinearElastic", "small", "linear CG"))
        if flop_ratio:
            out.append(snippet(
                "linear", flop_ratio=flop_ratio,
                second_ratio=ratio(cost("LinearElastic", "small", dyn, "seconds_to_target"),
                                   cost("LinearElastic", "small", "linear CG", "seconds_to_target")),
                verdict=snippet("agrees_with" if 5 <= flop_ratio <= 10 else "differs_from"),
                cg_seconds=cost("LinearElastic", "small", "linear CG", "seconds_to_1e-4_J"),
                dynamic_seconds=cost("LinearElastic", "small", dyn, "seconds_to_1e-4_J")))
    for case in dict.fromkeys(row["case"] for row in convergence):
        for mesh in dict.fromkeys(row["mesh"] for row in convergence if row["case"] == case):
            if case == "LinearElastic":
                continue
            dyn = cost(case, mesh, dynamic_label(case, mesh))
            secant = cost(case, mesh, "NCG secant PRP")
            statics = {row["method"]: row["mflop_to_target"] for row in convergence
                       if row["case"] == case and row["mesh"] == mesh and row["method"].startswith("NCG")}
            reached = {k: v for k, v in statics.items() if v is not None}
            if dyn and secant:
                best = min(reached, key=reached.get)
                out.append(snippet("nonlinear", case=case, mesh=mesh, secant_ratio=secant / dyn, best=best,
                                   best_ratio=reached[best] / dyn,
                                   thesis=snippet("dynamic_ahead" if case == "StVenantKirchhoff" else "as_quick")))
    cheapest, dearest, fr_ratios = [], [], {}
    for case, mesh in dict.fromkeys((row["case"], row["mesh"]) for row in convergence):
        costs = {ls: cost(case, mesh, f"NCG {ls} PRP") for ls in ("secant", "Newton", "scale-dep. secant")}
        if all(costs.values()):
            cheapest.append(min(costs, key=costs.get))
            dearest.append(max(costs, key=costs.get))
        for ls in ("secant", "Newton", "scale-dep. secant"):
            pr, fr = cost(case, mesh, f"NCG {ls} PRP"), cost(case, mesh, f"NCG {ls} FR")
            if pr and fr:
                fr_ratios.setdefault(f"{case} ({mesh})", []).append(fr / pr)
    if cheapest:
        def counts(found):
            return ", ".join(snippet("count", line_search=ls, count=found.count(ls)) for ls in dict.fromkeys(found))

        out.append(snippet("line_searches", cheapest=counts(cheapest), n_cases=len(cheapest), dearest=counts(dearest)))
    if fr_ratios:
        spans = {name: (min(r), max(r)) for name, r in fr_ratios.items()}
        similar = [name for name, (low, high) in spans.items() if 0.5 <= low and high <= 1.5]
        different = [name for name in spans if name not in similar]
        out.append(snippet(
            "fletcher_reeves", spans="; ".join(f"{name} {low:.2f}–{high:.2f}" for name, (low, high) in spans.items()),
            holds=snippet("holds_except", names=", ".join(different)) if different else snippet("holds_everywhere")))
    for case in dict.fromkeys(row["case"] for row in convergence if row["mesh"] == "large"):
        growth = {}
        for method in ("NCG secant PRP", "dynamic"):
            small = cost(case, "small", dynamic_label(case, "small") if method == "dynamic" else method,
                         "iterations_to_target")
            large = cost(case, "large", dynamic_label(case, "large") if method == "dynamic" else method,
                         "iterations_to_target")
            growth[method] = ratio(large, small)
        if all(growth.values()):
            out.append(snippet("mesh_size", case=case, ncg=growth["NCG secant PRP"], dynamic=growth["dynamic"]))
    for row in convergence:
        if row["iterations_to_target"] is None:
            out.append(snippet("plateau", case=row["case"], mesh=row["mesh"], method=row["method"],
                               reason=row["reason"], error=row["final_error"], energy=row["final_energy_difference"],
                               lower=snippet("lower_equilibrium") if row["final_energy_difference"] < 0 else ""))
    pct = [row["pct_peak"] for row in rates]
    speedups = [row["iterations_per_second"] / row["thesis_iterations_per_second"] for row in rates
                if row["thesis_iterations_per_second"]]
    ordered = all(per_iteration(rates, c, "NCG Newton") > per_iteration(rates, c, "NCG secant")
                  > per_iteration(rates, c, "dynamic")
                  for c in ("StVenantKirchhoff", "NeoHookean", "VerondaWestmann")
                  if lookup(rates, case=c, mesh="small", method="NCG Newton"))
    out.append(snippet("table_4_5", pct_min=min(pct), pct_max=max(pct),
                       order=snippet("ordered" if ordered else "not_ordered"),
                       speed_min=min(speedups), speed_max=max(speedups)))
    out += short_edge_findings(results["short_edge"], template)
    return out


def per_iteration(rates, case: str, method: str) -> float:
    return lookup(rates, case=case, mesh="small", method=method)["mflop_per_iteration"]


def short_edge_findings(rows, template: PageTemplate) -> list[str]:
    out = []
    methods = list(dict.fromkeys(row["method"] for row in rows))
    original = {row["method"]: row for row in rows if row["ratio"] == 1.0}
    shortest = {row["method"]: row for row in rows if row["ratio"] == min(r["ratio"] for r in rows)}
    growth = []
    for method in methods:
        a, b = original.get(method), shortest.get(method)
        if a and b:
            if b["iterations_to_target"] is None:
                growth.append(template.snippet("not_reached", method=method, reason=b["reason"]))
            else:
                growth.append(f"{method}: {ratio(b['mflop_to_target'], a['mflop_to_target']):.2f}×")
    if growth:
        out.append(template.snippet("short_edge", r=min(r["ratio"] for r in rows), growth="; ".join(growth)))
    line_search_failures = sorted({row["ratio"] for row in rows if row["reason"] == "DIVERGED_LINE_SEARCH"})
    if line_search_failures:
        out.append(template.snippet("line_search_fails", ratios=", ".join(format(r, "g") for r in line_search_failures)))
    reduced = [row for row in rows if row.get("step_reductions")]
    if reduced:
        out.append(template.snippet("step_lowered", ratios=", ".join(format(row["ratio"], "g") for row in reduced)))
    return out


def main(argv=None) -> dict:
    arguments = parse_arguments(__doc__, argv)
    settings = settings_for(arguments.quick)
    meshes = {label: CylinderMesh.read(label, path) for label, path in settings["meshes"].items()}
    small = meshes["small"]
    convergence, damping, damping_search_rows, curves, eta_best, critical = [], [], [], {}, {}, {}
    for case in settings["cases"]:
        rows, search, run_curves, eta_best[case.name], critical[case.name], reference = convergence_runs(
            small, case, settings, settings["static_methods"])
        convergence += rows
        damping_search_rows += search
        curves.update({(case.name, "small", c.label): c for c in run_curves})
        eigenvalues = modal_eigenvalues(reference)
        damping.append({"part": "table_4_4", "case": case.name, "eta_best": eta_best[case.name],
                        "thesis_eta": case.thesis_eta, "critical_step_ms": 1e3 * critical[case.name],
                        "steps_at_best": lookup(search, best=True)["steps_to_target"],
                        "eta_modal": 2 * np.sqrt(eigenvalues[0]) if eigenvalues[0] > 0 else None,
                        "stability_limit_ms": 2e3 / np.sqrt(eigenvalues[-1]), "lowest_eigenvalue": eigenvalues[0]})
        print(f"{case.name}: η* = {eta_best[case.name]:g}, Δt = {critical[case.name]:.3e} s", flush=True)
    for material in settings["large_cases"]:
        case = Case(material)
        rows, _, run_curves, _, critical[f"{case.name} large"], _ = convergence_runs(
            meshes["large"], case, settings, settings["large_static_methods"], eta_best[case.name],
            settings["large_every"])
        convergence += rows
        curves.update({(case.name, "large", c.label): c for c in run_curves})
        print(f"{case.name} large mesh done", flush=True)
    print(markdown_table(convergence, CONVERGENCE_COLUMNS), flush=True)

    peak = machine_peak(arguments.quick)
    peak_a = max(row["mflops"] for row in peak if row["in_cache"])
    triad = lookup(peak, kernel="PETSc VecWAXPY triad")["mflops"]
    rates = []
    rate_runs = [(m, "small") for m in MATERIALS if Case(m).name in eta_best]
    rate_runs += [("NeoHookean", "large")] if "large" in meshes else []
    for material, mesh_label in rate_runs:
        case = Case(material)
        methods = ["linear CG", "dynamic"] if material == "LinearElastic" else ["NCG Newton", "NCG secant", "dynamic"]
        dt = critical[case.name if mesh_label == "small" else f"{case.name} large"]
        for method in methods:
            row = throughput(meshes[mesh_label], case, method, eta_best[case.name], dt, settings["rtol"])
            thesis = THESIS_TABLE_4_5.get((material, mesh_label, method), (None, None, None))
            row.update({"pct_peak": 100 * row["mflops"] / peak_a, "pct_triad": 100 * row["mflops"] / triad,
                        "thesis_pct_peak": thesis[0], "thesis_iterations_per_second": thesis[1],
                        "thesis_mflop_per_iteration": thesis[2]})
            rates.append(row)
    print(markdown_table(rates, RATE_COLUMNS), flush=True)

    neo = "NeoHookean"
    short_edge, short_curves = short_edge_study(small, settings["short_edge_ratios"], eta_best[neo], settings["rtol"],
                                                critical[neo])
    print(markdown_table(short_edge, SHORT_EDGE_COLUMNS), flush=True)
    cp_rows = cp_damping_rows(small, settings["cp_cases"], settings["rtol"])

    out = arguments.out
    results = {"convergence": convergence, "damping": damping, "damping_search": damping_search_rows,
               "rates": rates, "peak": peak, "short_edge": short_edge, "cp_damping": cp_rows, "curves": curves,
               "short_edge_curves": short_curves, "rtol": settings["rtol"], "eta_grid": settings["eta_grid"]}
    write_csv(out / "relaxation.csv", damping + damping_search_rows + convergence + peak + rates + short_edge + cp_rows)
    write_csv(out / "relaxation_curves.csv", curve_rows(curves))
    for name in dict.fromkeys(case for case, _, _ in curves):
        plot_convergence(curves, name, [m for m in meshes if any(k[:2] == (name, m) for k in curves)],
                         out / figure_name(name))
    plot_short_edge(short_curves, out / "relaxation_short_edge.png")
    (out / "relaxation.md").write_text(describe(results, arguments.quick))
    print(f"wrote {out / 'relaxation.md'}, relaxation.csv, relaxation_curves.csv and the PNGs")
    return results


if __name__ == "__main__":
    main()
