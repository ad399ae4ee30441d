"""The tools the pointer drives, one per interactive scene, over the scene's own body, cutter,
needle and solver: a ``Scalpel`` or a ``Needle``. Each interactive built-in scene registers the
function making its tool (``register``: the ``cut`` scene's scalpel, §3.2; the ``needle`` and
``needle3d`` scenes' needles, §6.8.1 and §6.9); a scene file's is ``file_tool``.

A tool turns the pointer (``press``/``drag``/``release`` at scene points, from the view's
``on_plane``) into *moves* — plain dictionaries, what a recording stores — and ``apply``
carries a move out on the body and relaxes it. The live session and the replay both go
through ``apply``, so a replay repeats exactly what the session did.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

import snede
from snede.app.interactive.view import View, direction_from_angles

# The interactive scenes' tools, by scene name: make(scene, method, rtol) -> a Scalpel or a Needle.
# The scene modules register theirs (``register``); this module imports none of them.
TOOLS: dict[str, Callable] = {}


@dataclass
class Relaxation:
    """The outcome of one move: how the body relaxed after it."""

    converged: bool
    reason: str
    seconds: float  # the solve's (the needle's: the update's, with its rearrangements)
    iterations: int
    faces_dissected: int = 0  # the scalpel's


def _relaxation(result, faces_dissected: int = 0) -> Relaxation:
    return Relaxation(bool(result.converged), str(result.reason), float(result.seconds), int(result.iterations),
                      faces_dissected)


def _points(moves, name: str) -> np.ndarray:
    """The finite (2, 3) blade of a move, or ValueError."""
    blade = np.asarray(moves, dtype=float)
    if blade.shape != (2, 3) or not np.isfinite(blade).all():
        raise ValueError(f"{name} must be two finite 3D points, got {moves!r}")
    return blade


class Scalpel:
    """A scalpel: a blade (a segment) whose place follows the pointer on the tool's plane
    (``blade(point)``: the blade there). A press places it, a drag moves it in steps of at
    least ``step`` (shorter steps leave faces unselected: ``scenes.cut``), a release lifts it:
    the next press starts a new incision. The body is relaxed by ``solver`` once before the
    first move (the loads) and after each."""

    name = "scalpel"

    def __init__(self, body, solver, blade, step: float, view: View, plane):
        self.body, self.solver, self.blade, self.step = body, solver, blade, step
        self.view, self.plane = view, plane
        self.first = _relaxation(self.solver.solve())  # the body sags under its loads before any cut
        self.cutter = snede.TetrahedralCutter(self.body)
        self.edge = None  # where the pointer holds the blade, while pressed

    @property
    def held(self) -> bool:
        return self.edge is not None

    def press(self, point) -> list[dict]:
        self.edge = np.asarray(point, dtype=float)
        return [{"tool": self.name, "action": "move", "blade": self.blade(self.edge).tolist()}]

    def drag(self, point) -> list[dict]:
        """Moves to ``point`` in equal steps of at least ``step``; none if it is nearer."""
        point = np.asarray(point, dtype=float)
        count = math.floor(np.linalg.norm(point - self.edge) / self.step)
        if count == 0:
            return []
        start, self.edge = self.edge, point
        return [{"tool": self.name, "action": "move", "blade": self.blade(start + (point - start) * k / count).tolist()}
                for k in range(1, count + 1)]

    def release(self, point) -> list[dict]:
        self.edge = None
        return [{"tool": self.name, "action": "lift"}]

    def apply(self, move: dict) -> Relaxation | None:
        if move["action"] not in ("move", "lift"):
            raise ValueError(f"a scalpel move's 'action' is move or lift, got {move['action']!r}")
        if move["action"] == "lift":
            self.cutter.lift()
            return None
        report = self.cutter.move(_points(move["blade"], "a scalpel move's 'blade'"))
        return _relaxation(self.solver.solve(), report.faces_dissected)

    def lips(self) -> np.ndarray:
        """The incision's faces ((m, 3) vertex ids)."""
        return self.cutter.incision_faces()

    def marks(self) -> dict:
        """What the window draws besides the body: the blade's edge (deformed coordinates)."""
        return {"blade": None if self.edge is None else self.blade(self.edge)}

    def write(self, writer, time: float) -> None:
        from snede.app.scenes.incision import incision_cells

        writer.write(self.body, time=time, incision=incision_cells(self.body.mesh, self.lips()))

    def picture(self) -> dict:
        return {"highlight": self.lips()}


class Needle:
    """A needle (``snede.NeedleInsertion``) entering at ``entry`` along ``direction``: a drag
    pushes it by how far the pointer goes along the shaft (back is ignored: the needle is not
    withdrawn), in updates of ``step``, each relaxed with its stick-slip rearrangements, up to
    ``depth_limit``. ``picture``: the replay's picture arguments (``Needle.picture``)."""

    name = "needle"

    def __init__(self, body, needle, entry, direction, step: float, depth_limit: float, view: View, plane,
                 picture=None):
        self.body, self.needle, self.step, self.depth_limit = body, needle, step, depth_limit
        self.entry, self.direction = np.asarray(entry, dtype=float), np.asarray(direction, dtype=float)
        self.view, self.plane, self._picture = view, plane, picture
        self.first = None
        self.grip = None  # (the pointer's place along the shaft, the depth) at the press

    @property
    def held(self) -> bool:
        return self.grip is not None

    def _along(self, point) -> float:
        return float((np.asarray(point, dtype=float)[:len(self.entry)] - self.entry) @ self.direction)

    def press(self, point) -> list[dict]:
        self.grip = (self._along(point), self.needle.depth)
        return []

    def drag(self, point) -> list[dict]:
        along, depth = self.grip
        target = min(depth + self._along(point) - along, self.depth_limit)
        planned, moves = self.needle.depth, []
        while target - planned >= self.step:
            moves.append({"tool": self.name, "action": "advance", "distance": self.step})
            planned += self.step
        return moves

    def release(self, point) -> list[dict]:
        self.grip = None
        return []

    def apply(self, move: dict) -> Relaxation:
        if move["action"] != "advance":
            raise ValueError(f"a needle move's 'action' is advance, got {move['action']!r}")
        distance = move["distance"]
        if isinstance(distance, bool) or not isinstance(distance, (int, float)) or not distance >= 0:
            raise ValueError(f"a needle move's 'distance' must be a non-negative number, got {distance!r}")
        report = self.needle.advance(float(distance))
        return Relaxation(bool(report.converged), str(report.reason), float(report.seconds),
                          int(report.solver_iterations))

    def lips(self) -> np.ndarray:
        return np.zeros((0, 3), dtype=np.int64)  # the needle makes none

    def marks(self) -> dict:
        """What the window draws besides the body: the needle from a centimetre outside the
        entry to its tip, its sticking and slipping nodes (deformed coordinates)."""
        ends = np.array([self.entry - 0.01 * self.direction, self.entry + self.needle.depth * self.direction])
        x = self.body.mesh.points + self.body.displacement
        state = self.needle.node_state()
        return {"needle": ends, "stick": x[state == 1], "slip": x[state == 2]}

    def write(self, writer, time: float) -> None:
        writer.write(self.body, time=time, point_fields={"needle_state": self.needle.node_state()})

    def picture(self) -> dict:
        return {} if self._picture is None else self._picture(self)


def whole_view(body, angles) -> View:
    """A view of the whole body from ``angles`` (matplotlib's elevation, azimuth), z up."""
    points = body.mesh.points
    low, high = points.min(axis=0), points.max(axis=0)
    return View(tuple((low + high) / 2), tuple(direction_from_angles(*angles)), (0.0, 0.0, 1.0),
                height=2.0 * float((high - low).max()))


def plane_along(point, direction, view: View) -> tuple:
    """The plane through ``point`` that holds ``direction`` and faces the view most."""
    direction = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    forward = view.axes()[2]
    normal = forward - (forward @ direction) * direction
    return tuple(np.asarray(point, dtype=float)), tuple(normal / np.linalg.norm(normal))


def register(scene: str):
    """A decorator: ``make(scene, method, rtol) -> tool`` is the tool of the built-in scene named
    ``scene`` (its module registers it when imported: ``snede.app.scenes.builders()`` imports them
    all)."""
    def add(make: Callable):
        TOOLS[scene] = make
        return make

    return add


def file_tool(scene, tools: list, method: str, rtol: float):
    """The tool of a scene file (``scene_file``): its first ``[[tool]]`` table's, seen from the
    file's picture's angles. A scalpel keeps the file's blade (its start): the pointer places the
    blade's middle on the plane through the start's middle across the blade, in steps of the
    file's (start to end over its moves). A needle enters where the file's line meets the body
    its loads deformed, in updates of the file's (depth over its steps), up to its depth."""
    from snede.app.run_scene import static_solver
    from snede.app.scene_file.frames import VIEW
    from snede.app.scene_file.tools import Scalpel as FileScalpel

    if not tools:
        raise ValueError(f"the scene file {scene.details['scene_file']} has no [[tool]] table: view drives a "
                         "scalpel or a needle the file declares")
    tool, view = tools[0], whole_view(scene.body, VIEW)
    if method not in tool.methods:
        raise ValueError(f"method {method!r} cannot relax the {type(tool).__name__.lower()} of {tool.key}: it takes "
                         f"{' or '.join(tool.methods)}")
    solver = static_solver(scene, method, rtol)
    if isinstance(tool, FileScalpel):
        span = tool.start[1] - tool.start[0]
        step = float(np.linalg.norm((tool.end - tool.start).mean(axis=0))) / tool.moves
        return Scalpel(scene.body, solver, lambda middle: np.array([middle - span / 2, middle + span / 2]), step,
                       view, (tuple(tool.start.mean(axis=0)), tuple(span / np.linalg.norm(span))))
    first = _relaxation(solver.solve())  # the loads, before the needle enters
    insertion = tool.insertion(scene.body, method, rtol, scene.solver_options)
    needle = Needle(scene.body, insertion, tool.start, tool.direction, tool.depth / tool.steps, tool.depth, view,
                    plane_along(tool.start, tool.direction, view))
    needle.first = first
    return needle
