"""§6.8.1 needle insertion: the slab of ``needle_slab`` (h_start = h3) pierced along y = 0.05 m
to 70 mm, refined to h_ref = h6 around the tip, the needle advancing ``speed``·h_ref per update
(each update relaxed until no needle node changes between stick and slip). Writes about 40
frames of the series with the needle node state as a point field (0 none, 1 stick, 2 slip),
a picture with the needle and an animation (GIF)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import snede
from snede.app.interactive.tools import Needle, register
from snede.app.interactive.view import View
from snede.app.plotting import animate, draw_2d
from snede.app.scenes.scene import Parameters, Scene, material, shaft_force
from snede.app.scenes.needle_slab import (DEPTH, DIRECTION, ENTRY, POISSON, SIZE, YOUNG, h, held, needle_for,
                                          slab_body)

OPTIONS = ("divisions", "speed", "formulation")  # the scene options it uses (the command line refuses the others)
DESCRIPTION = "§6.8.1 needle inserted 70 mm into the slab: stick-slip friction, bisection at the tip"
H_START, H_REF, SPEED, FRAMES = 3, 6, 0.1, 40
METHODS = snede.static.METHODS
STATES = ((1, "tab:blue", "stick"), (2, "tab:red", "slip"))


@dataclass
class Frame:
    """What a picture of the insertion needs: the mesh, displacement, node states, depth."""

    points: np.ndarray
    cells: np.ndarray
    displacement: np.ndarray
    state: np.ndarray
    depth: float


def draw_needle(ax, frame: Frame, legend: bool = True) -> None:
    """The needle (from 1 cm outside the entry to the tip) and its nodes coloured by state (on a
    picture of the deformed mesh, ``plotting.draw_2d``, which draws the mesh's edges)."""
    x = frame.points + frame.displacement
    entry, direction = np.asarray(ENTRY), np.asarray(DIRECTION)
    ends = np.array([entry - 0.01 * direction, entry + frame.depth * direction])
    ax.plot(ends[:, 0], ends[:, 1], color="k", linewidth=1.2)
    for value, colour, label in STATES:
        on = frame.state == value
        ax.plot(x[on, 0], x[on, 1], "o", markersize=3, color=colour, zorder=3, label=f"{label} ({on.sum()})")
    if legend:
        ax.legend(loc="upper right", fontsize=7)


class Insertion:
    """The scene's run (``evolve``): the insertion, the frames it writes, the needle on pictures."""

    def __init__(self, body, speed: float):
        self.body, self.speed = body, speed
        self.needle, self.frames = None, []

    def _record(self, writer) -> None:
        mesh, state = self.body.mesh, self.needle.node_state()
        writer.write(self.body, time=self.needle.depth, point_fields={"needle_state": state})
        self.frames.append(Frame(mesh.points, mesh.cells, self.body.displacement.copy(), state, self.needle.depth))

    def evolve(self, method: str, rtol: float, writer, folder, progress: bool) -> dict:
        from snede.app.run_scene import Progress

        self.needle = needle_for(self.body, H_REF, method=method, rtol=rtol)
        self._record(writer)
        bar = Progress(f"needle ({method})", progress, total=math.ceil(DEPTH / (self.speed * h(H_REF)) - 1e-9),
                       unit=" updates")

        def after(done, total, step):
            bar(done, f"{step.rearrangements} rearrangements, {self.body.mesh.n_cells} cells")
            if done % max(1, round(total / FRAMES)) == 0 and done < total:
                self._record(writer)

        flops = snede.PETSc.Log.getFlops()
        try:
            report = self.needle.insert(DEPTH, self.speed * h(H_REF), progress=after)
        finally:
            bar.close()
        flops = snede.PETSc.Log.getFlops() - flops
        self._record(writer)  # the final state
        self._largest = max(np.linalg.norm(f.displacement, axis=1).max() for f in self.frames)  # one colour scale
        gif = animate(self.frames, folder / "needle.gif", self._draw_frame)
        state = self.needle.node_state()
        counts = {name: int((state == value).sum()) for value, _, name in STATES}
        return {
            "converged": report.converged, "reason": report.reason,
            "iterations": sum(s.solver_iterations for s in report.steps), "linear_iterations": 0,
            "residual_norm": None, "seconds": report.seconds, "mflop": flops / 1e6,
            "updates": report.updates, "rearrangements": report.rearrangements,
            "update_rate_hz": report.update_rate, "mean_iterations": report.mean_iterations,
            "max_iterations": report.max_iterations, "frames": len(self.frames),
            "needle_nodes": len(self.needle.needle_nodes), **counts,
            "notes": f"{report}; needle nodes: {counts['stick']} stick, {counts['slip']} slip",
            "files": {"gif": str(gif)},
        }

    def _draw_frame(self, ax, frame: Frame) -> None:
        draw_2d(ax, frame.points, frame.cells, frame.displacement, vmax=max(self._largest, 1e-12))
        draw_needle(ax, frame, legend=False)
        ax.set(xlim=(-0.012, 0.105), ylim=(-0.006, 0.106))
        stick, slip = ((frame.state == value).sum() for value, _, _ in STATES)
        ax.text(0.02, 0.98, f"needle at {frame.depth * 1e3:.1f} mm: {stick} stick (blue), {slip} slip (red)",
                transform=ax.transAxes, fontsize=8, va="top")

    def decorate(self, ax) -> None:
        draw_needle(ax, self.frames[-1])


def _h_start(divisions: int | None) -> int:
    if divisions is None:
        return H_START
    if divisions <= 0:
        raise ValueError(f"--divisions must be positive, got {divisions}")
    k = round(math.log2(divisions)) if divisions > 0 else -1
    if not 1 <= k <= H_REF or 2 ** k != divisions:
        raise ValueError(f"--divisions for the needle must be a power of 2 from 2 to {2 ** H_REF}, got {divisions}")
    return k


def build(parameters: Parameters) -> Scene:
    name = parameters.material or "linear"
    h_start = _h_start(parameters.divisions)
    speed = parameters.speed or SPEED
    body = slab_body(h_start, material(name, YOUNG, POISSON), formulation=parameters.formulation or "p1")
    insertion = Insertion(body, speed)
    return Scene(
        methods=METHODS,
        name="needle", description=DESCRIPTION, body=body, default_method="cg" if name == "linear" else "newton",
        probe_name="needle force along shaft [N]", probe=lambda b: shaft_force(insertion.needle), default_rtol=1e-3,
        evolve=insertion.evolve, decorate=insertion.decorate, fixed=held,
        picture=lambda: {"loads": False},  # the needle and its nodes' states show the friction
        details={"h_start": h_start, "h_ref": H_REF, "speed_h_ref_per_update": speed, "depth_m": DEPTH})


def _tool_picture(tool: Needle) -> dict:
    mesh = tool.body.mesh
    frame = Frame(mesh.points, mesh.cells, tool.body.displacement.copy(), tool.needle.node_state(), tool.needle.depth)
    return {"decorate": lambda ax: draw_needle(ax, frame)}


@register("needle")
def tool(scene: Scene, method: str, rtol: float) -> Needle:
    """The needle of ``python -m snede view needle`` (its slab and needle: ``needle_slab``),
    entering at the slab's left side, in updates of the scene's speed × h_ref."""
    return Needle(scene.body, needle_for(scene.body, H_REF, method=method, rtol=rtol), ENTRY, DIRECTION,
                  scene.details["speed_h_ref_per_update"] * h(H_REF), DEPTH,
                  View((SIZE / 2, SIZE / 2, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0), height=1.3 * SIZE),
                  ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)), picture=_tool_picture)
