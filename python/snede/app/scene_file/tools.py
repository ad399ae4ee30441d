"""The ``[[tool]]`` tables of a scene file, run in their order after the loads are relaxed: a
scalpel sweep (``kind = "scalpel"``: a blade, the segment ``start``, moved in ``moves`` equal
steps to ``end``, the body relaxed after each; snede.TetrahedralCutter) and a needle insertion
(``kind = "needle"``: from where the line through ``entry`` along ``direction`` meets the
surface, ``depth`` deep in ``steps`` updates; snede.NeedleInsertion). Before anything runs,
each path is checked against the body's reference shape: a sweep must meet it, a needle must
start outside it and its tip stay inside. A sweep takes at most MAX_STEPS moves, an insertion
as many updates, and a needle's ``h_ref`` may not refine the body beyond ``[mesh] max_cells``."""
from __future__ import annotations

import math

import numpy as np

import snede
from snede import meshing
from snede.app.scene_file.reading import (DIRECTION, POINT, POSITIVE, REFUSED, SEGMENT, Kind, SceneFileError, Table,
                                      choice, integer_kind, is_number, number_kind)
from snede.app.scenes.scene import briefly

KINDS = ("scalpel", "needle")
AIM = np.array([0.31, 0.47, 0.83])  # a direction no mesh lines up with, to tell inside from outside
SAMPLES_PER_MOVE = 4  # blade positions tried per move when checking that a sweep meets the body
# Each move or update is a relaxation, a step of the series and a frame of the GIF, which holds
# the mesh's points, boundary and displacement until the end and takes matplotlib a fraction of
# a second to draw: 1000 take minutes, a billion would never end.
MAX_STEPS = 1000
STEPS = integer_kind(f"a positive integer up to {MAX_STEPS} (each is a relaxation, a step of the series and a "
                     "frame of the GIF)", 1, MAX_STEPS)


def _friction(value):
    """A FrictionProfile from a number (the same all along the shaft), [distance, force] pairs
    (distances from the tip increasing from 0) or "figure 6.4"; REFUSED otherwise."""
    if value == "figure 6.4":
        return snede.FrictionProfile.figure_6_4()
    if is_number(value) and value >= 0:
        return snede.FrictionProfile.uniform(float(value))
    pairs = value if isinstance(value, list) and value else None
    if pairs is None or not all(isinstance(p, list) and len(p) == 2 and all(is_number(x) for x in p) for p in pairs):
        return REFUSED
    distances, forces = np.array(pairs, dtype=np.float64).T
    if distances[0] != 0 or np.any(np.diff(distances) <= 0) or np.any(forces < 0):
        return REFUSED
    return snede.FrictionProfile(distances, forces)


FRICTION = Kind('a force per unit of shaft surface in N/m² (a number ≥ 0), [distance from the tip, force] pairs '
                'with distances increasing from 0, or "figure 6.4"', _friction)
STATIC_FACTOR = number_kind("a number ≥ 1", lambda v: v >= 1)


def _leaves(mesh, hit, direction) -> bool:
    """Whether a ray along ``direction`` leaves the body where it ``hit`` its boundary (boundary
    faces are oriented outward), rather than enters it."""
    a, b, c = mesh.points[hit.face]
    return float(np.cross(b - a, c - a) @ direction) > 0


def _inside(mesh, point) -> bool:
    """Whether ``point`` is inside the body: a ray from it first meets the boundary leaving."""
    hit = mesh.ray_hit(point, AIM)
    return hit is not None and _leaves(mesh, hit, AIM)


def _crosses(mesh, a, b) -> bool:
    """Whether the segment a–b meets the body's boundary."""
    hit = mesh.ray_hit(a, b - a)
    return hit is not None and hit.distance <= np.linalg.norm(b - a)


class Scalpel:
    """A blade (a segment) moved from ``start`` to ``end`` in ``moves`` steps."""

    methods = snede.static.METHODS

    def __init__(self, table: Table):
        self.key = table.name
        self.start, self.end = np.array(table.get("start", SEGMENT)), np.array(table.get("end", SEGMENT))
        self.moves = table.get("moves", STEPS, meaning="how many steps the blade takes from start to end")
        self.table = table

    def path(self, samples: int) -> np.ndarray:
        """(samples + 1, 2, 3): the blade at equal steps from start to end."""
        t = np.linspace(0.0, 1.0, samples + 1)[:, None, None]
        return (1 - t) * self.start + t * self.end

    def check(self, mesh) -> None:
        for a, b in [*self.path(SAMPLES_PER_MOVE * self.moves), *np.stack([self.start, self.end], axis=1)]:
            if _crosses(mesh, a, b) or _inside(mesh, (a + b) / 2):
                return
        self.table.fail(None, f"never meets the body: the blade's sweep from start {self.start.tolist()} to end "
                              f"{self.end.tolist()} passes outside it (its reference shape spans "
                              f"{_span(mesh)})")

    def run(self, run) -> bool:
        """Place the blade, then move it step by step, relaxing after each; False if a
        relaxation failed (the run stops there)."""
        cutter = run.cutter()
        cutter.move(self.start)
        path = self.path(self.moves)
        for k in range(1, self.moves + 1):
            report = cutter.move(path[k])
            run.cut_report = run.cut_report + report
            result = run.relax()
            run.say(f"{self.key}: move {k}/{self.moves}: {report}; relaxed: {briefly(result)}")
            run.record(f"scalpel, move {k}/{self.moves}", path[k])
            if not result.converged:
                return False
        cutter.lift()
        return True


class Needle:
    """A needle inserted ``depth`` from the surface along ``direction``."""

    methods = ("cg", "newton")

    def __init__(self, table: Table, max_cells: int):
        self.key, self.table = table.name, table
        self.entry = np.array(table.get("entry", POINT, meaning="a point outside the body on the needle's line"))
        direction = np.array(table.get("direction", DIRECTION))
        self.direction = direction / np.linalg.norm(direction)
        self.depth = table.get("depth", POSITIVE, meaning="how far the tip goes in past the surface, in metres")
        self.steps = table.get("steps", STEPS, meaning="how many updates the insertion takes")
        self.radius = table.get("radius", POSITIVE, snede.NeedleOptions.default_radius)
        self.friction = table.get("friction", FRICTION, snede.FrictionProfile.figure_6_4())
        self.static_factor = table.get("static_factor", STATIC_FACTOR, snede.NeedleOptions().static_factor)
        self.h_ref = table.get("h_ref", POSITIVE, None)
        if self.h_ref is not None:
            # Bisection refines every element within radius of the shaft, and those up to one
            # element beyond, to edges of h_ref: the tube around the shaft and the ball at the tip
            # filled with tetrahedra no larger than regular ones of edge h_ref (fewer than it makes).
            reach = self.radius + self.h_ref
            tube = math.pi * reach**2 * self.depth + 4 / 3 * math.pi * reach**3
            try:
                meshing.check_cells(meshing.tetrahedra_estimate(tube, 0.0, self.h_ref), max_cells,
                                    f"{self.h_ref:g} m", "give a larger h_ref (each halving makes 8 times as "
                                    "many), or raise mesh.max_cells if you mean it")
            except ValueError as error:
                table.fail("h_ref", str(error))

    def check(self, mesh) -> None:
        hit = mesh.ray_hit(self.entry, self.direction)
        if hit is None:
            self.table.fail("entry", f"{self.entry.tolist()} with direction {self.direction.round(6).tolist()}: "
                                     f"the needle's line never meets the body (its reference shape spans "
                                     f"{_span(mesh)})")
        size = float(np.ptp(mesh.points, axis=0).max())
        if _leaves(mesh, hit, self.direction):  # (an entry on the surface, going in, is outside)
            if hit.distance <= 1e-9 * size:
                self.table.fail("direction", f"{self.direction.round(6).tolist()} points out of the body at the entry "
                                             f"{self.entry.tolist()}, which is on its surface")
            self.table.fail("entry", f"{self.entry.tolist()} is inside the body: give a point outside it on the "
                                     "needle's line (the needle starts where the line meets the surface)")
        leaves = mesh.ray_hit(hit.point + 1e-9 * size * self.direction, self.direction)
        if leaves is not None and self.depth >= leaves.distance:
            self.table.fail("depth", f"{self.depth:g} m takes the tip out of the body: the needle's line leaves "
                                     f"it {leaves.distance:.4g} m past the entry point {hit.point.round(6).tolist()}")

    def insertion(self, body, method: str, rtol: float, solver_options: dict) -> snede.NeedleInsertion:
        """The needle, its tip where its line meets the body as the loads deformed it (``start``),
        relaxed with ``method``, ``rtol`` and the scene's ``solver_options``."""
        hit = body.mesh.ray_hit(self.entry, self.direction, body.displacement)
        if hit is None:
            self.table.fail("entry", "misses the body as the loads deformed it: the needle's line no longer "
                                     "meets it")
        self.start = hit.point
        return snede.NeedleInsertion(body, hit.point, self.direction, self.friction, static_factor=self.static_factor,
                                     h_ref=self.h_ref, radius=self.radius, method=method, rtol=rtol,
                                     **solver_options)

    def run(self, run) -> bool:
        """Insert the needle from where its line meets the deformed surface; False if an update
        did not converge."""
        body = run.body
        run.needle = self.insertion(body, run.method, run.rtol, run.scene.solver_options)
        step = self.depth / self.steps

        def after(done, total, report):
            tip = self.start + run.needle.depth * self.direction
            run.say(f"{self.key}: update {done}/{total}, tip {run.needle.depth * 1e3:.1f} mm in: "
                    f"{report.rearrangements} rearrangements, {len(run.needle.needle_nodes)} needle nodes, "
                    f"{body.mesh.n_cells} tetrahedra")
            run.record(f"needle, {run.needle.depth * 1e3:.1f} mm in", np.array([self.start, tip]))

        run.insertion = run.needle.insert(self.depth, step, progress=after)
        return run.insertion.converged


def _span(mesh) -> str:
    low, high = mesh.points.min(axis=0), mesh.points.max(axis=0)
    return f"{np.round(low, 6).tolist()} to {np.round(high, 6).tolist()}"


def read_tools(tables: list[Table], method: str | None, max_cells: int) -> list:
    """The tools of the ``[[tool]]`` tables, in order; a needle, which stays in the body, only
    last. ``method``: the solver's, when the file names one; ``max_cells``: the body's limit."""
    tools = []
    for table in tables:
        kind = table.get("kind", choice(KINDS))
        tool = Scalpel(table) if kind == "scalpel" else Needle(table, max_cells)
        table.close()
        if tools and isinstance(tools[-1], Needle):
            table.fail(None, f"comes after the needle of {tools[-1].key}: a needle stays in the body, so it is "
                             "the last tool")
        if method is not None and method not in tool.methods:
            raise SceneFileError(f'{table.source}: solver.method "{method}" cannot relax the {kind} of {table.name}: '
                                 f'it takes {" or ".join(tool.methods)}')
        tools.append(tool)
    return tools

