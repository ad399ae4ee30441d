"""The tools the pointer drives, one per interactive scene, over the scene's own body, cutter,
needle and solver (``snede.scenes``): the scalpel of the ``cut`` scene (§3.2) and the needle
of the 2D ``needle`` scene (§6.8.1: its slab and needle, ``scenes.needle_slab``).

A tool turns the pointer (``press``/``drag``/``release`` at scene points, from the view's
``on_plane``) into *moves* — plain dictionaries, what a recording stores — and ``apply``
carries a move out on the body and relaxes it. The live session and the replay both go
through ``apply``, so a replay repeats exactly what the session did.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import snede
from snede.interactive.view import View, direction_from_angles


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
    """The ``cut`` scene's scalpel: a blade along y, wider than the beam (as the scene's), its
    edge where the pointer meets the beam's front face y = 0. A press places it, a drag moves
    it in steps of at least the scene's STEP elements (shorter steps leave faces unselected:
    ``scenes.cut``), a release lifts it: the next press starts a new incision."""

    name = "scalpel"

    def __init__(self, scene, method: str, rtol: float):
        from snede.scenes import cut

        self.scene, self.body = scene, scene.body
        self.width = cut.WIDTH
        self.step = cut.STEP * cut.LENGTH / scene.details["divisions"][0]
        self.solver = snede.StaticSolver(self.body, method, rtol=rtol)
        self.first = _relaxation(self.solver.solve())  # the beam sags under gravity before any cut
        self.cutter = snede.TetrahedralCutter(self.body)
        self.edge = None  # where the blade's edge meets y = 0, while pressed
        centre = (cut.LENGTH / 2, cut.WIDTH / 2, -0.03)  # the beam sagging to some 10 cm at its tip
        self.view = View(centre, tuple(direction_from_angles(*cut.VIEW)), (0.0, 0.0, 1.0), height=0.24)
        self.plane = ((0.0, 0.0, 0.0), (0.0, 1.0, 0.0))

    @property
    def held(self) -> bool:
        return self.edge is not None

    def blade(self, edge) -> list:
        x, _, z = edge
        return [[float(x), -0.5 * self.width, float(z)], [float(x), 1.5 * self.width, float(z)]]

    def press(self, point) -> list[dict]:
        self.edge = np.asarray(point, dtype=float)
        return [{"tool": self.name, "action": "move", "blade": self.blade(self.edge)}]

    def drag(self, point) -> list[dict]:
        """Moves to ``point`` in equal steps of at least ``step``; none if it is nearer."""
        point = np.asarray(point, dtype=float)
        count = math.floor(np.linalg.norm(point - self.edge) / self.step)
        if count == 0:
            return []
        start, self.edge = self.edge, point
        return [{"tool": self.name, "action": "move", "blade": self.blade(start + (point - start) * k / count)}
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
        return {"blade": None if self.edge is None else np.array(self.blade(self.edge))}

    def write(self, writer, time: float) -> None:
        from snede.scenes.incision import incision_cells

        writer.write(self.body, time=time, incision=incision_cells(self.body.mesh, self.lips()))

    def picture(self) -> dict:
        return {"highlight": self.lips()}


class Needle:
    """The ``needle`` scene's needle (the 2D slab, §6.8.1), entering at the slab's left side:
    a drag pushes it by how far the pointer goes along the shaft (back is ignored: the needle
    is not withdrawn), in updates of the scene's speed × h_ref, each relaxed with its
    stick-slip rearrangements, up to the scene's depth."""

    name = "needle"

    def __init__(self, scene, method: str, rtol: float):
        from snede.scenes import needle, needle_slab

        self.scene, self.body = scene, scene.body
        self.needle = needle_slab.needle_for(self.body, needle.H_REF, method=method, rtol=rtol)
        self.step = scene.details["speed_h_ref_per_update"] * needle_slab.h(needle.H_REF)
        self.depth_limit = needle_slab.DEPTH
        self.entry, self.direction = np.asarray(needle_slab.ENTRY), np.asarray(needle_slab.DIRECTION)
        self.first = None
        self.grip = None  # (the pointer's place along the shaft, the depth) at the press
        size = needle_slab.SIZE
        self.view = View((size / 2, size / 2, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0), height=1.3 * size)
        self.plane = ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))

    @property
    def held(self) -> bool:
        return self.grip is not None

    def _along(self, point) -> float:
        return float((np.asarray(point, dtype=float)[:2] - self.entry) @ self.direction)

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
        from snede.scenes.needle import Frame, draw_needle

        mesh = self.body.mesh
        frame = Frame(mesh.points, mesh.cells, self.body.displacement.copy(), self.needle.node_state(),
                      self.needle.depth)
        return {"decorate": lambda ax: draw_needle(ax, frame)}


TOOLS = {"cut": Scalpel, "needle": Needle}  # the interactive scenes and the tool of each
