"""§5.2 cutting in 2D: a plane-stress sheet 10 × 6 cm, 1 mm thick (E = 50 kPa, ν = 0.3), held
in grips along its short edges that pull it 8 % longer, relaxes (a static solve); then a point
scalpel enters through the top edge and follows an S-curve down through 60 % of the sheet's
height. The scalpel moves in deformed coordinates, the Delaunay cutter (§5.2.2) remeshes
around it in the reference configuration, and the sheet relaxes from its carried-over state
after every move: the tension pulls the incision open behind the scalpel.

Writes the XDMF series (every few moves, with a new mesh when the cut changed it) with the
cell field ``incision`` (1 on the triangles with an edge on the lips), a picture of the deformed
mesh with its edges drawn and the lips in red, and an animation (GIF) of the cut opening.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import snede
from snede.planar_cutting import PlanarCutResult, sample_path
from snede.app.plotting import HIGHLIGHT, animate, draw_2d
from snede.app.scenes.scene import Parameters, Scene, briefly, divisions, material, solve_entries
from snede.app.scenes.incision import incision_cells, lips_gap

LENGTH, HEIGHT, THICKNESS = 0.1, 0.06, 0.001
YOUNG, POISSON, DENSITY = 5e4, 0.3, 1000.0
STRETCH = 0.08  # the grips pull the sheet this much longer, half at each end
DEPTH = 0.6  # how far down the scalpel goes, as a fraction of the height
SWAY = 0.12  # the S-curve's amplitude, as a fraction of the length
OPTIONS = ("divisions", "formulation")  # the scene options it uses (the command line refuses the others)
DESCRIPTION = "§5.2 Delaunay cut along an S-curve into a stretched plane-stress sheet, relaxed after each move"
METHODS = snede.static.METHODS
FRAMES = 30  # about this many frames in the series and the animation, besides the stretched sheet


def scalpel_path(step: float) -> np.ndarray:
    """(n, 2) the scalpel's positions, deformed coordinates, at most ``step`` apart: from a tenth
    of the height above the middle of the top edge straight down to it, then one period of a
    sine of amplitude SWAY·LENGTH down to DEPTH of the height, at equal steps along the curve."""
    s = np.linspace(0.0, 1.0, 1001)
    curve = np.c_[0.5 * LENGTH + SWAY * LENGTH * np.sin(2 * math.pi * s), HEIGHT * (1 - DEPTH * s)]
    along = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(curve, axis=0), axis=1))]
    at = np.linspace(0.0, along[-1], math.ceil(along[-1] / step) + 1)
    curve = np.c_[np.interp(at, along, curve[:, 0]), np.interp(at, along, curve[:, 1])]
    return sample_path(np.r_[[[0.5 * LENGTH, 1.1 * HEIGHT]], curve], step)


@dataclass
class Frame:
    """What a picture of the cut needs: the mesh, the state, the lips, the scalpel."""

    points: np.ndarray
    cells: np.ndarray
    displacement: np.ndarray
    incision: np.ndarray  # (m, 2) vertex ids of the lips' edges
    scalpel: np.ndarray | None  # (2,) deformed coordinates; None before the cut
    label: str


class SheetCut:
    """The scene's run (``evolve``): stretch, then scalpel moves and relaxations; the frames it writes."""

    def __init__(self, body):
        self.body = body
        self.cutter, self.path, self.frames, self.results = None, None, [], []

    def incision(self) -> np.ndarray:
        """The lips' edges ((m, 2) vertex ids; both lips)."""
        return np.zeros((0, 2), dtype=np.int64) if self.cutter is None else self.cutter.incision_edges()

    def opening(self) -> float:
        return lips_gap(self.body, self.incision())

    def _record(self, writer, time: float, scalpel, label: str) -> None:
        mesh, incision = self.body.mesh, self.incision()
        writer.write(self.body, time=time, incision=incision_cells(mesh, incision))
        self.frames.append(Frame(mesh.points, mesh.cells, self.body.displacement.copy(), incision,
                                 None if scalpel is None else np.array(scalpel), label))

    def evolve(self, method: str, rtol: float, writer, folder, progress: bool) -> dict:
        say = print if progress else (lambda *args, **kwargs: None)
        solver = snede.StaticSolver(self.body, method, rtol=rtol)
        result = solver.solve()
        self.results.append(result)
        say(f"sheet-cut: stretched {STRETCH:.0%} by the grips: {result}", flush=True)
        self._record(writer, 0.0, None, f"stretched {STRETCH:.0%}")

        self.cutter = snede.DelaunayCutter(self.body)
        self.path = scalpel_path(self.cutter.eps_edge)  # steps of ε_edge, as DelaunayCutter.cut
        triangles = self.body.mesh.n_cells
        moves, done = len(self.path), 0
        total = PlanarCutResult(triangles_before=triangles, triangles_after=triangles)  # as yet no moves
        every = math.ceil(moves / FRAMES)
        for k, point in enumerate(self.path, start=1):
            if not result.converged:
                say(f"sheet-cut: stopped before move {k}/{moves}: the relaxation did not converge ({result.reason})",
                    flush=True)
                break
            report = self.cutter.move(point)
            total, done = total + report, k
            result = solver.solve()
            self.results.append(result)
            say(f"sheet-cut: move {k:>3}/{moves}, scalpel at ({point[0] * 1e3:5.1f}, {point[1] * 1e3:5.1f}) mm: "
                f"{report.flips} flips, {report.nodes_inserted} inserted, {report.nodes_removed} removed, "
                f"{report.triangles_after} triangles; relaxed: {briefly(result)}", flush=True)
            if k % every == 0 or k == moves or not result.converged:
                self._record(writer, float(k), point, f"move {k}/{moves}: lips {self.opening() * 1e3:.1f} mm apart")

        self._fit_frames()
        gif = animate(self.frames, folder / "sheet-cut.gif", self._draw_frame, fps=6)
        solves, opening = solve_entries(self.results), self.opening()
        return {
            **solves, "seconds": solves["seconds"] + total.seconds,
            "solve_seconds": solves["seconds"], "cut_seconds": total.seconds,
            "moves": done, "frames": len(self.frames), "eps_edge_m": self.cutter.eps_edge,
            "triangles_before": total.triangles_before, "triangles_after": total.triangles_after,
            "flips": total.flips, "nodes_inserted": total.nodes_inserted, "nodes_removed": total.nodes_removed,
            "incision_splits": total.incision_splits, "entries": total.entries, "exits": total.exits,
            "stuck": total.stuck, "incision_edges": len(self.incision()), "opening_m": opening,
            "notes": f"{total}; {len(self.results)} solves in {solves['seconds']:.2f} s; "
                     f"the lips open by up to {opening * 1e3:.1f} mm",
            "files": {"gif": str(gif)},
        }

    def _fit_frames(self) -> None:
        """One colour scale and one view for every frame: over their meshes' vertices and the path."""
        used = [np.unique(f.cells) for f in self.frames]
        self._largest = max(np.linalg.norm(f.displacement[v], axis=1).max() for f, v in zip(self.frames, used))
        every = np.concatenate([f.points[v] + f.displacement[v] for f, v in zip(self.frames, used)] + [self.path])
        margin = 0.03 * LENGTH
        self._box = every.min(axis=0) - margin, every.max(axis=0) + margin

    def _draw_scalpel(self, ax, scalpel) -> None:
        """The path the scalpel follows (dotted) and the scalpel, where it is."""
        ax.plot(self.path[:, 0], self.path[:, 1], color="k", linestyle=":", linewidth=0.8)
        if scalpel is not None:
            ax.plot(*scalpel, marker="v", markersize=6, color="k")

    def _draw_frame(self, ax, frame: Frame) -> None:
        draw_2d(ax, frame.points, frame.cells, frame.displacement, vmax=max(self._largest, 1e-12), reference=False,
                highlight=frame.incision)
        self._draw_scalpel(ax, frame.scalpel)
        (x0, y0), (x1, y1) = self._box
        ax.set(xlim=(x0, x1), ylim=(y0, y1))
        ax.text(0.02, 0.98, frame.label, transform=ax.transAxes, fontsize=8, va="top")
        if len(frame.incision):
            ax.text(0.02, 0.93, f"incision: {len(frame.incision)} edges", transform=ax.transAxes, fontsize=8,
                    va="top", color=HIGHLIGHT)

    def decorate(self, ax) -> None:
        self._draw_scalpel(ax, self.frames[-1].scalpel)


def held(points) -> np.ndarray:
    """The vertices the grips hold: the short edges x = 0 and x = LENGTH (reference)."""
    return np.isclose(points[:, 0], 0.0) | np.isclose(points[:, 0], LENGTH)


def build(parameters: Parameters) -> Scene:
    n = divisions(parameters, 40, 5, "for the sheet-cut must be a multiple of 5 (n × 3n/5 squares)")
    name = parameters.material or "linear"
    mesh = snede.meshing.rectangle((LENGTH, HEIGHT), (n, 3 * n // 5))
    body = snede.Body(mesh, material(name, YOUNG, POISSON), density=DENSITY, thickness=THICKNESS, formulation=parameters.formulation or "p1")
    x = mesh.points
    pull = 0.5 * STRETCH * LENGTH
    body.fix(np.isclose(x[:, 0], 0.0), (-pull, 0.0))  # the grips: clamped, pulled apart
    body.fix(np.isclose(x[:, 0], LENGTH), (pull, 0.0))
    sheet = SheetCut(body)
    return Scene(
        methods=METHODS,
        name="sheet-cut", description=DESCRIPTION, body=body,
        default_method="cg" if name == "linear" else "newton",
        probe_name="widest gap between the lips [m]", probe=lambda b: sheet.opening(),
        evolve=sheet.evolve, decorate=sheet.decorate, fixed=held,
        picture=lambda: {"reference": False, "highlight": sheet.incision()},
        details={"divisions": [n, 3 * n // 5], "stretch": STRETCH, "depth_fraction": DEPTH, "sway_fraction": SWAY})
