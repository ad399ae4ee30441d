"""§6.9, Figure 6.14: a needle of radius 1 mm inserted 70 mm from the left into a 10 cm cube fixed
at the bottom (E = 34 kPa, ν = 0.34), stick-slip friction (the Figure 6.4 stand-in profile per
unit of shaft surface, static twice dynamic), the mesh refined by bisection along the shaft and
at the tip to h_ref = 0.1 m / ``--divisions`` (default 64: 1.6 mm), the needle advancing
``--speed``·h_ref per update (default 0.5), each update relaxed until no needle node changes
between stick and slip, with multigrid on the refinement (``-needle_pc_type mg``).

Writes the XDMF series (about 20 frames, each on its own refined mesh, point field
``needle_state``: 0 none, 1 stick, 2 slip), the picture of the deformed cube, a picture and a
GIF of the needle as the mesh represents it: its nodes (blue stick, red slip) and the jagged
surface they span (the faces whose three vertices are needle nodes, coloured by |u|).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

import numpy as np

import snede
from snede.plotting import animate, draw_3d, save_3d
from snede.scenes import Scene, material

SIZE, DEPTH, RADIUS = 0.1, 0.07, 1e-3
YOUNG, POISSON = 34e3, 0.34
# Off the grid lines of the start mesh, so the nodes the needle catches lie around its axis, not
# on one line of vertices.
ENTRY, DIRECTION = (-0.005, 0.0513, 0.0489), (1.0, 0.0, 0.0)
DIVISIONS, SPEED, FRAMES = 64, 0.5, 20
OPTIONS = ("divisions", "speed", "formulation")  # the scene options it uses (the command line refuses the others)
DESCRIPTION = "§6.9 needle (r = 1 mm) inserted 70 mm into a 10 cm cube: refined along the shaft, stick-slip"
METHODS = ("cg", "newton")
VIEW = (20.0, -60.0)


def cube(material_, formulation: str = "p1"):
    """The cube: the 2 × 2 × 2 Kuhn box bisected 3 times (384 tetrahedra), fixed at the bottom."""
    mesh = snede.meshing.box((SIZE, SIZE, SIZE), (2, 2, 2))
    mesh.refine_uniform(3)
    body = snede.Body(mesh, material_, formulation=formulation)
    body.fix(held(mesh.points))
    return body


def held(points) -> np.ndarray:
    return np.isclose(points[:, 2], 0.0)


def needle_faces(cells, nodes) -> np.ndarray:
    """(m, 3) the needle's surface as the mesh represents it (Figure 6.14): the boundary of the
    tetrahedra whose four vertices are all needle nodes (the faces that occur once among them);
    where there are none (h_ref above the radius: the nodes form a chain), the faces whose
    three vertices are needle nodes, each once."""
    on = np.zeros(cells.max() + 1 if len(cells) else 0, dtype=bool)
    on[nodes] = True
    inside = cells[on[cells].all(axis=1)]
    source = inside if len(inside) else cells
    faces = np.concatenate([source[:, [1, 2, 3]], source[:, [0, 3, 2]], source[:, [0, 1, 3]], source[:, [0, 2, 1]]])
    faces = faces[on[faces].all(axis=1)]
    if not len(faces):
        return faces.reshape(0, 3)
    _, first, count = np.unique(np.sort(faces, axis=1), axis=0, return_index=True, return_counts=True)
    keep = first[count == 1] if len(inside) else first
    return faces[np.sort(keep)]


@dataclass
class Frame:
    points: np.ndarray
    faces: np.ndarray
    displacement: np.ndarray
    depth: float
    stick: np.ndarray  # deformed positions of the sticking needle nodes
    slip: np.ndarray

    @property
    def sticking(self) -> int:
        return len(self.stick)

    @property
    def slipping(self) -> int:
        return len(self.slip)


class Insertion:
    """The scene's run (``evolve``): the insertion and the frames it writes."""

    def __init__(self, body, h_ref: float, speed: float):
        self.body, self.h_ref, self.speed = body, h_ref, speed
        self.needle, self.frames = None, []

    def _record(self, writer) -> None:
        mesh, state = self.body.mesh, self.needle.node_state()
        writer.write(self.body, time=self.needle.depth, point_fields={"needle_state": state})
        u = self.body.displacement.copy()
        x = mesh.points + u
        self.frames.append(Frame(mesh.points, needle_faces(mesh.cells, self.needle.needle_nodes), u,
                                 self.needle.depth, x[state == 1], x[state == 2]))

    def evolve(self, method: str, rtol: float, writer, folder, progress: bool) -> dict:
        from snede.run_scene import Progress

        if method not in METHODS:
            raise ValueError(f"the needle3d scene solves with {', '.join(METHODS)}; got {method!r}")
        self.needle = snede.NeedleInsertion(self.body, ENTRY, DIRECTION, snede.FrictionProfile.figure_6_4(),
                                            radius=RADIUS, h_ref=self.h_ref, method=method, rtol=rtol,
                                            petsc_options={"pc_type": "mg"})
        self._record(writer)
        step = self.speed * self.h_ref
        total = math.ceil(DEPTH / step - 1e-9)
        bar = Progress(f"needle3d ({method})", progress, total=total, unit=" updates")

        def after(done, total, report):
            bar(done, f"{report.rearrangements} rearrangements, {self.body.mesh.n_cells} tetrahedra")
            if done % max(1, round(total / FRAMES)) == 0 and done < total:
                self._record(writer)

        try:
            report = self.needle.insert(DEPTH, step, progress=after)
        finally:
            bar.close()
        self._record(writer)
        last = self.frames[-1]
        self._largest = max(float(np.linalg.norm(f.displacement, axis=1).max()) for f in self.frames)
        surface = self.draw_surface(folder / "needle3d_surface.png", last)
        gif = animate(self.frames, folder / "needle3d.gif", self._draw_frame, fps=4, projection="3d")
        return {
            "converged": report.converged, "reason": report.reason,
            "iterations": sum(s.solver_iterations for s in report.steps), "linear_iterations": 0,
            "residual_norm": None, "seconds": report.seconds, "updates": report.updates,
            "rearrangements": report.rearrangements, "update_rate_hz": report.update_rate,
            "mean_iterations": report.mean_iterations, "max_iterations": report.max_iterations,
            "tetrahedra": self.body.mesh.n_cells, "needle_nodes": len(self.needle.needle_nodes),
            "stick": last.sticking, "slip": last.slipping, "needle_surface_faces": len(last.faces),
            "frames": len(self.frames),
            "notes": f"{report}; {self.body.mesh.n_cells} tetrahedra; needle nodes: {last.sticking} stick, "
                     f"{last.slipping} slip; the mesh's needle surface has {len(last.faces)} faces",
            "files": {"gif": str(gif), "needle_surface": str(surface)},
        }

    def _draw_frame(self, ax, frame: Frame) -> None:
        import matplotlib.colors as colors

        if len(frame.faces):
            draw_3d(ax, frame.points, frame.faces, frame.displacement,
                    norm=colors.Normalize(0.0, max(self._largest, 1e-12)))
        tip = np.asarray(ENTRY) + frame.depth * np.asarray(DIRECTION)
        shaft = np.array([np.asarray(ENTRY) - 0.01 * np.asarray(DIRECTION), tip])
        ax.plot(shaft[:, 0], shaft[:, 1], shaft[:, 2], color="k", linewidth=1.0)
        for nodes, colour, label in ((frame.stick, "tab:blue", "stick"), (frame.slip, "tab:red", "slip")):
            if len(nodes):
                ax.scatter(nodes[:, 0], nodes[:, 1], nodes[:, 2], s=1.5 if len(frame.faces) else 6, color=colour,
                           depthshade=False, label=f"{label} ({len(nodes)})")
        # Around the shaft: ±6 r across it, the whole depth along it.
        across = 6 * RADIUS
        ax.set(xlim=(0.0, DEPTH + ENTRY[0]), ylim=(ENTRY[1] - across, ENTRY[1] + across),
               zlim=(ENTRY[2] - across, ENTRY[2] + across))
        ax.set_box_aspect((4, 1, 1), zoom=1.3)
        ax.view_init(*VIEW)
        ax.text2D(0.03, 0.95, f"needle at {frame.depth * 1e3:.1f} mm: {frame.sticking} stick, {frame.slipping} slip",
                  transform=ax.transAxes, fontsize=8)

    def draw_surface(self, path, frame: Frame):
        """A picture of the needle's jagged surface in the mesh, coloured by |u| (Figure 6.14)."""
        return save_3d(path, partial(self._draw_frame, frame=frame),
                       f"needle surface in the mesh: {len(frame.faces)} faces, {self.body.mesh.n_cells} tetrahedra",
                       figsize=(7, 4))

    def shaft_force(self) -> float:
        """Total force the needle exerts on the body along its shaft (N)."""
        return float((self.needle.needle_forces() @ np.asarray(DIRECTION)).sum())


def build(options) -> Scene:
    name = options.material or "linear"
    divisions = DIVISIONS if options.divisions is None else options.divisions
    if divisions < 4:
        raise ValueError(f"--divisions for needle3d sets h_ref = 0.1 m / divisions and must be at least 4, got {divisions}")
    speed = getattr(options, "speed", None) or SPEED
    body = cube(material(name, YOUNG, POISSON), getattr(options, "formulation", None) or "p1")
    insertion = Insertion(body, SIZE / divisions, speed)
    return Scene(
        name="needle3d", description=DESCRIPTION, body=body, default_method="cg" if name == "linear" else "newton",
        probe_name="needle force along shaft [N]", probe=lambda b: insertion.shaft_force(), default_rtol=1e-3,
        evolve=insertion.evolve, fixed=held, picture=lambda: {"loads": False, "view": VIEW},
        details={"h_ref_m": SIZE / divisions, "radius_m": RADIUS, "speed_h_ref_per_update": speed, "depth_m": DEPTH})
