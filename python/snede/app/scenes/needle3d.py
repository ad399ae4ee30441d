"""§6.9, Figure 6.14: a needle of radius 1 mm inserted 70 mm from the left into a 10 cm cube of
liver fixed at the bottom (shear modulus 1.8 kPa: E = 5.0 kPa at ν = 0.4), stick-slip friction
with liver's forces (``snede.needle_forces.liver_profile``: 0.45 N over 70 mm, 79 % of it the
cutting bulge at the tip, per unit of shaft surface, static twice dynamic), the mesh refined by
bisection along the shaft and at the tip to h_ref = 0.1 m / ``--divisions`` (default 64:
1.6 mm), the needle advancing ``--speed``·h_ref per update (default 0.5), each update relaxed
until no needle node changes between stick and slip, with multigrid on the refinement
(``-needle_pc_type mg``). The cube's face is dragged about a millimetre into it around the
entry, the tissue at the tip about a centimetre (docs/results/needle3d.md).

Writes the XDMF series (about 20 frames, each on its own refined mesh, point field
``needle_state``: 0 none, 1 stick, 2 slip), the picture of the deformed cube seen from the
entry with the needle drawn in, a section through the needle's axis (the deformed mesh cut by
the plane y = entry, coloured by |u|: the drag), a picture and a GIF of the needle as the mesh
represents it: its nodes (blue stick, red slip) and the jagged surface they span (the faces
whose three vertices are needle nodes, coloured by |u|).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

import numpy as np

import snede
from snede.needle_forces import liver_profile, liver_young
from snede.app._extras import need
from snede.app.interactive.tools import Needle, plane_along, register, whole_view
from snede.app.plotting import _figure, animate, draw_3d, save_3d
from snede.app.scenes.scene import Parameters, Scene, material, shaft_force

SIZE, DEPTH, RADIUS = 0.1, 0.07, 1e-3
# Liver's shear modulus (snede.needle_forces); ν = 0.4 stays below the ratio at which linear
# tetrahedra lock (0.45), and the drag along the shaft is governed by the shear modulus.
POISSON = 0.4
YOUNG = liver_young(POISSON)
# Off the grid lines of the start mesh, so the nodes the needle catches lie around its axis, not
# on one line of vertices.
ENTRY, DIRECTION = (-0.005, 0.0513, 0.0489), (1.0, 0.0, 0.0)
DIVISIONS, SPEED, FRAMES = 64, 0.5, 20
OPTIONS = ("divisions", "speed", "formulation")  # the scene options it uses (the command line refuses the others)
DESCRIPTION = ("§6.9 needle (r = 1 mm) inserted 70 mm into a 10 cm cube of liver with liver's forces: refined "
               "along the shaft, stick-slip")
METHODS = ("cg", "newton")
VIEW = (20.0, -60.0)  # the needle-surface picture
ENTRY_VIEW = (15.0, -145.0)  # the cube's picture: from the left front, where the needle enters
MM = 1e3


def cube(material_, formulation: str = "p1"):
    """The cube: the 2 × 2 × 2 Kuhn box bisected 3 times (384 tetrahedra), fixed at the bottom."""
    mesh = snede.meshing.box((SIZE, SIZE, SIZE), (2, 2, 2))
    mesh.refine_uniform(3)
    body = snede.Body(mesh, material_, formulation=formulation)
    body.fix(held(mesh.points))
    return body


def needle_for(body, h_ref: float, method: str, rtol: float) -> "snede.NeedleInsertion":
    """The scene's needle at its entry, liver's forces, refining to ``h_ref``, multigrid on the refinement."""
    return snede.NeedleInsertion(body, ENTRY, DIRECTION, liver_profile(DEPTH, RADIUS), radius=RADIUS, h_ref=h_ref,
                                 method=method, rtol=rtol, petsc_options={"pc_type": "mg"})


def held(points) -> np.ndarray:
    return np.isclose(points[:, 2], 0.0)


def held_in_view(points) -> np.ndarray:
    """The held vertices the cube's picture can show: those on the edges of its bottom face."""
    on_side = np.isclose(points[:, :2], 0.0).any(axis=1) | np.isclose(points[:, :2], SIZE).any(axis=1)
    return held(points) & on_side


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


def section(points, cells, u, y: float) -> tuple[list, list]:
    """The tetrahedral mesh cut by the plane y = ``y`` (reference coordinates): one polygon per
    tetrahedron it crosses (a triangle or a quadrilateral, corners ordered around it), as the
    cut points' reference positions and displacements, linear along the cut edges."""
    side = points[cells, 1] > y  # (n, 4)
    crossed = side.any(axis=1) & ~side.all(axis=1)
    positions, displacements = [], []
    for cell, above in zip(cells[crossed], side[crossed]):
        corners = [(a, b) for i, a in enumerate(cell) for j, b in enumerate(cell) if i < j and above[i] != above[j]]
        ends = np.array(corners)
        t = (y - points[ends[:, 0], 1]) / (points[ends[:, 1], 1] - points[ends[:, 0], 1])
        p = points[ends[:, 0]] + t[:, None] * (points[ends[:, 1]] - points[ends[:, 0]])
        d = u[ends[:, 0]] + t[:, None] * (u[ends[:, 1]] - u[ends[:, 0]])
        centre = p.mean(axis=0)
        order = np.argsort(np.arctan2(p[:, 2] - centre[2], p[:, 0] - centre[0]))
        positions.append(p[order])
        displacements.append(d[order])
    return positions, displacements


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
        from snede.app.run_scene import Progress

        self.needle = needle_for(self.body, self.h_ref, method, rtol)
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
        cut = self.draw_section(folder / "needle3d_section.png")
        gif = animate(self.frames, folder / "needle3d.gif", self._draw_frame, fps=4, projection="3d")
        return {
            "converged": report.converged, "reason": report.reason,
            "iterations": sum(s.solver_iterations for s in report.steps), "linear_iterations": 0,
            "residual_norm": None, "seconds": report.seconds, "updates": report.updates,
            "rearrangements": report.rearrangements, "update_rate_hz": report.update_rate,
            "mean_iterations": report.mean_iterations, "max_iterations": report.max_iterations,
            "tetrahedra": self.body.mesh.n_cells, "needle_nodes": len(self.needle.needle_nodes),
            "stick": last.sticking, "slip": last.slipping, "needle_surface_faces": len(last.faces),
            "frames": len(self.frames), "entry_drag_m": self.entry_drag(),
            "max_displacement_m": float(np.linalg.norm(self.body.displacement, axis=1).max()),
            "notes": f"{report}; {self.body.mesh.n_cells} tetrahedra; needle nodes: {last.sticking} stick, "
                     f"{last.slipping} slip; the mesh's needle surface has {len(last.faces)} faces; the entry face dragged "
                     f"{self.entry_drag() * MM:.2f} mm",
            "files": {"gif": str(gif), "needle_surface": str(surface), "section": str(cut)},
        }

    def _draw_frame(self, ax, frame: Frame) -> None:
        colors = need("matplotlib.colors", "snede's pictures")

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

    def entry_drag(self) -> float:
        """How far the tissue around the entry is dragged (m): the largest |u| on the face x = 0
        the needle enters through."""
        on_face = np.isclose(self.body.mesh.points[:, 0], 0.0) & self.body.mesh.live_vertices
        return float(np.linalg.norm(self.body.displacement[on_face], axis=1).max())

    def _needle_axis(self) -> np.ndarray:
        """(2, 3): from 15 mm outside the entry to the tip (deformed coordinates: the needle is rigid)."""
        direction = np.asarray(DIRECTION)
        tip = np.asarray(ENTRY) + (self.needle.depth if self.needle else 0.0) * direction
        return np.array([np.asarray(ENTRY) - 0.015 * direction, tip])

    def draw_needle(self, ax) -> None:
        """The needle on the cube's picture: its axis, drawn over the (opaque) cube."""
        axis = self._needle_axis()
        ax.plot(axis[:, 0], axis[:, 1], axis[:, 2], color="0.1", linewidth=3.0, solid_capstyle="round", zorder=5,
                label=f"needle (r = {RADIUS * MM:g} mm, {self.needle.depth * MM:.0f} mm in)")

    def draw_section(self, path):
        """The deformed mesh cut by the plane through the needle's axis (y = entry), coloured by
        |u| with its edges, to scale: the whole section and the entry enlarged, the needle in
        grey, the reference outline dashed, the fixed bottom black, a scale bar in each."""
        colors = need("matplotlib.colors", "snede's pictures")
        from matplotlib.collections import PolyCollection
        from matplotlib.patches import Rectangle

        plt = _figure()
        mesh = self.body.mesh
        positions, displacements = section(mesh.points, mesh.cells, self.body.displacement, ENTRY[1])
        polygons = [(p + d)[:, [0, 2]] * MM for p, d in zip(positions, displacements)]
        magnitude = np.array([np.linalg.norm(d, axis=1).mean() for d in displacements]) * MM
        centres = np.array([p.mean(axis=0) for p in polygons])
        axis = self._needle_axis() * MM
        entry_x, entry_z = ENTRY[0] * MM, ENTRY[2] * MM
        views = {"section through the needle's axis": ((-20.0, SIZE * MM + 5), (-5.0, SIZE * MM + 5), 10.0),
                 "the entry, enlarged": ((entry_x - 5, entry_x + 35), (entry_z - 12, entry_z + 12), 5.0)}
        figure, axes = plt.subplots(1, 2, figsize=(11, 4.4), layout="constrained", gridspec_kw={"width_ratios": (1, 1.3)})
        for ax, (title, (xlim, zlim, bar)) in zip(axes, views.items()):
            shown = ((centres[:, 0] > xlim[0]) & (centres[:, 0] < xlim[1]) & (centres[:, 1] > zlim[0])
                     & (centres[:, 1] < zlim[1]))
            norm = colors.Normalize(0.0, magnitude[shown].max())  # each panel its own range: the entry's drag shows
            ax.add_collection(PolyCollection(polygons, array=magnitude, cmap="viridis", norm=norm,
                                             edgecolors=(0, 0, 0, 0.5), linewidths=0.3))
            ax.add_patch(Rectangle((0, 0), SIZE * MM, SIZE * MM, fill=False, linestyle=(0, (3, 2)), edgecolor="0.45",
                                   linewidth=0.8, label="reference outline"))
            ax.add_patch(Rectangle((axis[0, 0], entry_z - RADIUS * MM), axis[1, 0] - axis[0, 0], 2 * RADIUS * MM,
                                   facecolor="0.55", edgecolor="0.1", linewidth=0.6, zorder=3,
                                   label=f"needle (r = {RADIUS * MM:g} mm)"))
            ax.plot([-20, SIZE * MM + 5], [0, 0], color="k", linewidth=4, label="fixed bottom")
            x0, z0 = xlim[0] + 0.06 * (xlim[1] - xlim[0]), zlim[0] + 0.08 * (zlim[1] - zlim[0])
            ax.plot([x0, x0 + bar], [z0, z0], color="k", linewidth=2.5)
            ax.text(x0 + bar / 2, z0 + 0.02 * (zlim[1] - zlim[0]), f"{bar:g} mm", ha="center", va="bottom", fontsize=8)
            ax.set(xlim=xlim, ylim=zlim, xlabel="x [mm]", ylabel="z [mm]", aspect="equal")
            ax.set_title(title, fontsize=9)
            figure.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax, label="|u| [mm]", shrink=0.9)
        axes[0].legend(loc="upper right", fontsize=7, framealpha=0.85)
        figure.suptitle(f"needle3d: the liver cube cut at y = {ENTRY[1] * MM:.1f} mm, deformed (to scale): the entry face "
                        f"dragged {self.entry_drag() * MM:.1f} mm, the tissue at the tip {magnitude.max():.1f} mm", fontsize=10)
        figure.savefig(path, dpi=120)
        plt.close(figure)
        return path


def build(parameters: Parameters) -> Scene:
    name = parameters.material or "linear"
    divisions = DIVISIONS if parameters.divisions is None else parameters.divisions
    if divisions < 4:
        raise ValueError(f"--divisions for needle3d sets h_ref = 0.1 m / divisions and must be at least 4, got {divisions}")
    speed = parameters.speed or SPEED
    body = cube(material(name, YOUNG, POISSON), parameters.formulation or "p1")
    insertion = Insertion(body, SIZE / divisions, speed)
    return Scene(
        methods=METHODS,
        name="needle3d", description=DESCRIPTION, body=body, default_method="cg" if name == "linear" else "newton",
        probe_name="needle force along shaft [N]", probe=lambda b: shaft_force(insertion.needle), default_rtol=1e-3,
        evolve=insertion.evolve, fixed=held, decorate=insertion.draw_needle,
        picture=lambda: {"loads": False, "view": ENTRY_VIEW, "fixed": held_in_view(body.mesh.points)},
        details={"h_ref_m": SIZE / divisions, "radius_m": RADIUS, "speed_h_ref_per_update": speed, "depth_m": DEPTH,
                 "young_pa": YOUNG, "poisson": POISSON})


@register("needle3d")
def tool(scene: Scene, method: str, rtol: float) -> Needle:
    """The needle of ``python -m snede view needle3d``, entering the cube's left face, in updates
    of the scene's speed × h_ref, seen as the scene's picture sees it (from the entry's side);
    the pointer moves on the plane of the shaft that faces the view."""
    h_ref = scene.details["h_ref_m"]
    view = whole_view(scene.body, ENTRY_VIEW)
    return Needle(scene.body, needle_for(scene.body, h_ref, method, rtol), ENTRY, DIRECTION,
                  scene.details["speed_h_ref_per_update"] * h_ref, DEPTH, view, plane_along(ENTRY, DIRECTION, view))
