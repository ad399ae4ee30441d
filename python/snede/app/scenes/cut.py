"""§3.2–§3.3 cutting: a soft 20 × 5 × 5 cm beam (neo-Hookean, E = 100 kPa, ν = 0.3, ρ = 1000)
fixed at x = 0 sags under gravity; a scalpel — a blade along y, wider than the beam — comes
down from above at x ≈ 5 cm, where the top of the beam is stretched, to 70 % of the beam's
depth in small steps, and the beam relaxes (a static solve) after every step: the incision
opens into a V and the beam sags further.

Writes the XDMF series (a new mesh after each step that cut) with the cell field ``incision``
(1 on the tetrahedra with a face on the cut), a picture with the incision in red and an
animation (GIF) of the cut with the blade.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import snede
from snede.app._extras import need
from snede.app.interactive.tools import Scalpel, register
from snede.app.interactive.view import View, direction_from_angles
from snede.app.plotting import HIGHLIGHT, animate, draw_3d
from snede.app.scenes.cantilever import held  # the beam is held as the cantilever is: its end x = 0
from snede.app.scenes.scene import Parameters, Scene, briefly, divisions, material, solve_entries
from snede.app.scenes.incision import incision_cells, lips_gap

LENGTH, WIDTH, HEIGHT = 0.2, 0.05, 0.05
YOUNG, POISSON, DENSITY = 1e5, 0.3, 1000.0
AT, DEPTH = 0.25, 0.7  # where the blade enters (fraction of the length), how deep it goes (of the height)
# The blade's step and where it enters, in element sizes h. With the current cutter, steps
# under about h/2 leave faces unselected (a tetrahedron must be crossed within the sweeps of
# the last two moves), and a blade 0.3 h past a layer of vertices cuts the grid more cleanly
# than one halfway between two layers.
STEP, OFFSET = 0.75, 0.3
OPTIONS = ("divisions", "formulation")  # the scene options it uses (the command line refuses the others)
DESCRIPTION = "§3.2 scalpel cut 70 % into a soft beam sagging under gravity, relaxed after each step"
METHODS = snede.static.METHODS
VIEW = (12.0, -70.0)  # camera (elevation, azimuth): the side and the top, where the V opens


def blade(x: float, z: float) -> np.ndarray:
    """The blade's edge at (x, z): a segment along y, half the beam's width past its front and
    its back faces, so that it cuts all across the beam."""
    return np.array([(x, -0.5 * WIDTH, z), (x, 1.5 * WIDTH, z)], dtype=float)


@dataclass
class Frame:
    """What a picture of the cut needs: the mesh's boundary, the incision, the state, the blade."""

    points: np.ndarray
    faces: np.ndarray
    incision: np.ndarray
    displacement: np.ndarray
    blade: np.ndarray | None  # (2, 3) its edge, deformed coordinates; None before it is placed
    label: str


class Cut:
    """The scene's run (``evolve``): sag, then blade steps and relaxations; the frames it writes."""

    def __init__(self, body, divisions: int):
        self.body, self.divisions = body, divisions
        self.cutter, self.frames, self.results = None, [], []
        self.tip = np.flatnonzero(np.isclose(body.mesh.points[:, 0], LENGTH))

    def blade_path(self) -> np.ndarray:
        """(moves + 1, 2, 3) blade edges in deformed coordinates: the first above the beam, then
        down in steps of STEP elements to DEPTH of the beam's height below its top, OFFSET
        elements past the layer of vertices at AT of the length (where the sagging beam put it)."""
        h = LENGTH / self.divisions
        reference = self.body.mesh.points
        deformed = reference + self.body.displacement
        layer = round(AT * self.divisions)
        top = np.isclose(reference[:, 2], HEIGHT) & (np.isclose(reference[:, 0], layer * h)
                                                     | np.isclose(reference[:, 0], (layer + 1) * h))
        x = (layer + OFFSET) * h + (deformed[top, 0] - reference[top, 0]).mean()
        z_top = self.z_top = deformed[top, 2].mean()
        start, end = z_top + h / 2, z_top - DEPTH * HEIGHT
        moves = math.ceil((start - end) / (STEP * h))
        path = np.empty((moves + 1, 2, 3))
        for k, z in enumerate(np.linspace(start, end, moves + 1)):
            path[k] = blade(x, z)
        return path

    def _blade_depth(self, blade) -> str:
        depth = self.z_top - blade[0, 2]
        return f"{abs(depth) * 1e3:4.1f} mm {'into' if depth >= 0 else 'above'} the beam"

    def faces(self) -> np.ndarray:
        """The boundary faces the cut opened ((n, 3) vertex ids)."""
        return np.zeros((0, 3), dtype=np.int64) if self.cutter is None else self.cutter.incision_faces()

    def opening(self) -> float:
        return lips_gap(self.body, self.faces())

    def tip_sag(self) -> float:
        return float(-self.body.displacement[self.tip, 2].mean())

    def _record(self, writer, step: int, blade, label: str) -> None:
        mesh, incision = self.body.mesh, self.faces()
        writer.write(self.body, time=float(step), incision=incision_cells(mesh, incision))
        self.frames.append(Frame(mesh.points, mesh.boundary_faces(), incision, self.body.displacement.copy(),
                                 None if blade is None else np.array(blade), label))

    def evolve(self, method: str, rtol: float, writer, folder, progress: bool) -> dict:
        say = print if progress else (lambda *args, **kwargs: None)
        solver = snede.StaticSolver(self.body, method, rtol=rtol)
        self._record(writer, 0, None, "unloaded")
        result = solver.solve()
        self.results.append(result)
        sag = self.tip_sag()
        say(f"cut: sagging under gravity: {result}", flush=True)
        self._record(writer, 1, None, f"sagging: tip {sag * 1e3:.1f} mm down")

        self.cutter = snede.TetrahedralCutter(self.body)
        path = self.blade_path()
        total = self.cutter.move(path[0])  # places the blade above the beam
        moves, done = len(path) - 1, 0
        for k in range(1, moves + 1):
            if not result.converged:
                say(f"cut: stopped before move {k}/{moves}: the relaxation did not converge ({result.reason})",
                    flush=True)
                break
            report = self.cutter.move(path[k])
            total, done = total + report, k
            result = solver.solve()
            self.results.append(result)
            where = self._blade_depth(path[k])
            say(f"cut: move {k:>2}/{moves}, blade {where}: {report}; relaxed: {briefly(result)}", flush=True)
            self._record(writer, k + 1, path[k], f"blade {where}")

        # One colour scale and one box for all frames, over the vertices of the boundary.
        surfaces = [np.unique(f.faces) for f in self.frames]
        self._largest = max(np.linalg.norm(f.displacement[v], axis=1).max() for f, v in zip(self.frames, surfaces))
        every = np.concatenate([f.points[v] + f.displacement[v] for f, v in zip(self.frames, surfaces)])
        self._box = every.min(axis=0), every.max(axis=0)
        gif = animate(self.frames, folder / "cut.gif", self._draw_frame, fps=2, projection="3d")
        opening, incision = self.opening(), self.faces()
        solves = solve_entries(self.results)
        return {
            **solves, "seconds": solves["seconds"] + total.seconds, "moves": done, "frames": len(self.frames),
            "faces_dissected": total.faces_dissected, "vertices_snapped": total.vertices_snapped,
            "snaps_refused": total.snaps_refused, "degenerate_found": total.degenerate_found,
            "edges_collapsed": total.edges_collapsed, "edges_split": total.edges_split,
            "elements_cut_free": total.elements_cut_free, "components": total.components,
            "free_pieces": total.free_pieces, "cut_seconds": total.seconds,
            "incision_faces": len(incision), "opening_m": opening,
            "tip_sag_before_m": sag, "tip_sag_after_m": self.tip_sag(),
            "notes": f"{total}; the lips open by up to {opening * 1e3:.1f} mm, the tip sags "
                     f"{sag * 1e3:.1f} -> {self.tip_sag() * 1e3:.1f} mm",
            "files": {"gif": str(gif)},
        }

    def _draw_frame(self, ax, frame: Frame) -> None:
        colors = need("matplotlib.colors", "snede's pictures")
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection

        scale = colors.Normalize(0.0, max(self._largest, 1e-12))
        draw_3d(ax, frame.points, frame.faces, frame.displacement, norm=scale, highlight=frame.incision)
        if frame.blade is not None:
            edge = frame.blade
            back = edge + np.array([0.0, 0.0, 0.4 * HEIGHT])
            ax.add_collection3d(Poly3DCollection([np.array([edge[0], edge[1], back[1], back[0]])],
                                                 facecolors=(0.5, 0.5, 0.55, 0.35), edgecolors="none"))
            ax.plot(edge[:, 0], edge[:, 1], edge[:, 2], color="k", linewidth=1.5)
        low, high = self._box
        centre, radius = (low + high) / 2, (high - low).max() / 2
        ax.set(xlim=(centre[0] - radius, centre[0] + radius), ylim=(centre[1] - radius, centre[1] + radius),
               zlim=(centre[2] - radius, centre[2] + radius))
        ax.set_box_aspect((1, 1, 1), zoom=1.4)
        ax.view_init(*VIEW)
        ax.text2D(0.03, 0.95, frame.label, transform=ax.transAxes, fontsize=8, color="k")
        if len(frame.incision):
            ax.text2D(0.03, 0.90, f"incision: {len(frame.incision)} faces", transform=ax.transAxes, fontsize=8,
                      color=HIGHLIGHT)


def build(parameters: Parameters) -> Scene:
    n = divisions(parameters, 24, 4, "for the cut must be a multiple of 4 (n × n/4 × n/4 cubes)")
    mesh = snede.meshing.box((LENGTH, WIDTH, HEIGHT), (n, n // 4, n // 4))
    body = snede.Body(mesh, material(parameters.material or "neohookean", YOUNG, POISSON), density=DENSITY,
                      formulation=parameters.formulation or "p1")
    body.fix(held(mesh.points))
    body.add_gravity((0.0, 0.0, -9.81))
    cut = Cut(body, n)
    return Scene(
        methods=METHODS,
        name="cut", description=DESCRIPTION, body=body, default_method="newton",
        probe_name="widest gap between the lips [m]", probe=lambda b: cut.opening(),
        evolve=cut.evolve, fixed=held, picture=lambda: {"highlight": cut.faces(), "view": VIEW, "reference": False},
        details={"divisions": [n, n // 4, n // 4], "blade_at_reference_x_m": (round(AT * n) + OFFSET) * LENGTH / n,
                 "depth_fraction": DEPTH, "blade_step_elements": STEP})


@register("cut")
def tool(scene: Scene, method: str, rtol: float) -> Scalpel:
    """The scalpel of ``python -m snede view cut``: the scene's blade, its edge where the pointer
    meets the beam's front face y = 0, in steps of the scene's STEP elements."""
    centre = (LENGTH / 2, WIDTH / 2, -0.03)  # the beam sagging to some 10 cm at its tip
    view = View(centre, tuple(direction_from_angles(*VIEW)), (0.0, 0.0, 1.0), height=0.24)
    return Scalpel(scene.body, snede.StaticSolver(scene.body, method, rtol=rtol), lambda edge: blade(edge[0], edge[2]),
                   STEP * LENGTH / scene.details["divisions"][0], view, ((0.0, 0.0, 0.0), (0.0, 1.0, 0.0)))
