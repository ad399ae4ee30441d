"""§5.3 cutting surfaces in 3D (Figures 5.14 and 5.19) with a segment scalpel.

The bell: Figure 5.19's Gaussian bell z = 0.4 exp(−r²/0.08) over the unit square (392
triangles) as a neo-Hookean membrane (E = 100 kPa, ν = 0.3, 1 mm thick), its rim pulled 15 %
outward in x and y (see PULL) and relaxed (a static solve). A vertical scalpel (z from −1 to 1) then
makes two cuts in from the rim and a loop that crosses itself, in deformed coordinates; the
membrane relaxes every few moves, and the tension opens the lips behind the scalpel. Where
the loop crosses its own incision the scalpel leaves through one lip and enters through the
other (§5.3.2), cutting out the piece it enclosed, which is then held where it is.

The fold: a sheet folded over a half-cylinder crease (a bare mesh, not deformed), cut across
by a scalpel that meets the crease from outside and branches onto both layers (Figure 5.14);
both branches leave through the far edges and the sheet falls into two pieces. The scalpel
leans 0.2 per unit height in x: an upright one misses a branch on this mesh (see FOLD_TILT).

Writes the bell's XDMF series (a frame at every relaxation, with a new mesh when the cut
changed it, cell field ``incision``), the fold's (``membrane-cut_fold.xdmf``), pictures of
the cut bell and fold (lips in red) and a GIF of both cuts.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np

import snede
from snede.output import SeriesWriter
from snede.planar_cutting import PlanarCutResult, sample_path
from snede.app._extras import need
from snede.app.plotting import animate, draw_3d, highlighted, outline_edges, save_3d
from snede.app.scenes.scene import Parameters, Scene, briefly, material, solve_entries
from snede.app.scenes.incision import incision_cells, lips_gap

DIVISIONS = 14  # the bell's n × n squares: 2n² = 392 triangles, Figure 5.19
YOUNG, POISSON, THICKNESS = 1e5, 0.3, 1e-3
# The rim is pulled this much outward from the square's centre. The bell's area is 1.21: pulled
# less than 10 % the membrane stays slack, and Newton without a preconditioner crawls (5 %: up to
# 780 iterations, 40 s of solves); at 15 % (area 1.32) it is taut.
PULL = 0.15
RELAX_EVERY = 4  # scalpel moves between static solves
MAX_ITERATIONS = 1000  # Newton iterations per solve: a membrane that stalls is reported, not waited for
REACH = 1.0  # the vertical scalpel spans z in [−REACH, REACH]: through the whole bell
# The scalpel's paths over the bell, (x, y) in deformed coordinates. Two cuts in from the rim
# that stop inside (the membrane stays one piece), then a loop in from the right edge: left,
# up, right, and down across its own first leg at (0.85, 0.25), ending inside.
BELL_PATHS = (
    ("first cut", ((-0.15, 0.7), (0.3, 0.72), (0.45, 0.6))),
    ("second cut", ((0.35, -0.15), (0.38, 0.3), (0.5, 0.42))),
    ("loop", ((1.15, 0.25), (0.62, 0.25), (0.62, 0.45), (0.85, 0.45), (0.85, 0.1))),
)
# Across the fold at y = 0.45, from beyond the crease (x ≈ 0.55) past both layers' ends. An
# upright scalpel here cuts one layer only on folded_sheet()'s 10 × 8 mesh (1 entry, no branch,
# 1 exit, one piece, at every y from 0.3 to 0.65); leaning it by FOLD_TILT branches as §5.3.2 says.
FOLD_PATH = ((0.8, 0.45), (-0.2, 0.45))
FOLD_TILT = 0.2  # the scalpel's lean in x per unit height
OPTIONS = ("divisions",)  # the scene options it uses (the command line refuses the others)
DESCRIPTION = "§5.3 surface cuts: a stretched bell membrane cut twice and in a loop; a fold, branching"
METHODS = ("newton",)
VIEW = (35.0, -60.0)
FOLD_VIEW = (20.0, -35.0)  # lower, from the crease's side: both layers show
FOLD_APART = 0.2


def scalpels(path, tilt: float = 0.0) -> np.ndarray:
    """(n, 2, 3) scalpels from z = −REACH to REACH through the points of ``path`` ((n, 2)),
    leaning by ``tilt`` in x per unit height."""
    x, y = np.asarray(path, dtype=np.float64).T
    return np.stack([np.c_[x - tilt * REACH, y, np.full_like(x, -REACH)],
                     np.c_[x + tilt * REACH, y, np.full_like(x, REACH)]], axis=1)


def on_rim(points) -> np.ndarray:
    """The vertices on the unit square's edges (reference): the rim the scene holds."""
    x, y = points[:, 0], points[:, 1]
    return np.isclose(x, 0.0) | np.isclose(x, 1.0) | np.isclose(y, 0.0) | np.isclose(y, 1.0)


def lips(mesh, cutters) -> np.ndarray:
    """(m, 2) the lips' edges of every incision the ``cutters`` made, as the mesh has them now:
    those that are still boundary edges (a later cutter may have remeshed next to them)."""
    edges = np.concatenate([np.zeros((0, 2), dtype=np.int64)] + [c.incision_edges() for c in cutters])
    return edges[highlighted(edges, outline_edges(mesh.cells))]


def pieces(mesh) -> list[np.ndarray]:
    """The vertex ids of each connected piece of the mesh."""
    count, label = mesh.connected_components()
    cells = mesh.cells
    return [np.unique(cells[label == k]) for k in range(count)]


def report_entries(report: PlanarCutResult) -> dict:
    """The summary entries of a cut: its events, mesh sizes and seconds."""
    return {"moves": report.moves, "entries": report.entries, "exits": report.exits, "branches": report.branches,
            "annihilations": report.annihilations, "stuck": report.stuck, "flips": report.flips,
            "nodes_inserted": report.nodes_inserted, "nodes_removed": report.nodes_removed,
            "incision_splits": report.incision_splits, "triangles_before": report.triangles_before,
            "triangles_after": report.triangles_after, "cut_seconds": report.seconds}


@dataclass
class Frame:
    """A picture of the cut: the surface, its state, the lips, the scalpel."""

    part: str  # "bell" or "fold"
    points: np.ndarray
    cells: np.ndarray
    displacement: np.ndarray
    incision: np.ndarray  # (m, 2) vertex ids of the lips' edges
    scalpel: np.ndarray | None  # (2, 3) deformed coordinates; None before the cut
    label: str
    apart: float = 0.0  # the pieces drawn this far apart in y (m), to show the cut through the fold


class MembraneCut:
    """The scene's run (``evolve``): the bell stretched, cut and relaxed; the fold cut."""

    def __init__(self, body, fold):
        self.body, self.fold = body, fold
        self.cutters, self.fold_cutter, self.frames, self.results = [], None, [], []
        self.held = []  # the pieces cut free and held, vertex ids

    def incision(self) -> np.ndarray:
        return lips(self.body.mesh, self.cutters)

    def opening(self) -> float:
        return lips_gap(self.body, self.incision())

    def _hold_free_pieces(self) -> None:
        """Hold a piece the loop cut free where it is: with no rim vertex nothing else holds it,
        and a membrane's equilibrium is then not unique (as the tetrahedral cutter does, §3.3)."""
        mesh = self.body.mesh
        for piece in pieces(mesh):
            if not on_rim(mesh.points[piece]).any() and not any(np.array_equal(piece, h) for h in self.held):
                self.body.fix(piece, self.body.displacement[piece])
                self.held.append(piece)

    def _record(self, writer, part: str, mesh, displacement, incision, time: float, scalpel, label: str) -> None:
        cells = incision_cells(mesh, incision)
        if part == "bell":
            writer.write(self.body, time=time, incision=cells)
        else:
            writer.write_mesh(mesh, time=time, incision=cells)
        self.frames.append(Frame(part, mesh.points, mesh.cells, displacement.copy(), incision,
                                 None if scalpel is None else np.array(scalpel), label))

    def evolve(self, method: str, rtol: float, writer, folder, progress: bool) -> dict:
        say = print if progress else (lambda *args, **kwargs: None)
        body, mesh = self.body, self.body.mesh
        # mg, although the bell is below the 1 000 cells where "auto" takes it: 574 Newton
        # iterations over the bell's 26 solves where none took 2 789 (5 s of solves against 12).
        solver = snede.StaticSolver(body, "newton", rtol=rtol, preconditioner="mg", max_iterations=MAX_ITERATIONS)
        result = solver.solve()
        self.results.append(result)
        say(f"membrane-cut: bell's rim pulled {PULL:.0%} outward: {result}", flush=True)
        self._record(writer, "bell", mesh, body.displacement, self.incision(), 0.0, None,
                     f"bell, rim pulled {PULL:.0%} outward")

        triangles = mesh.n_cells
        total = PlanarCutResult(triangles_before=triangles, triangles_after=triangles)
        cuts, done, stopped = {}, 0, False
        for name, corners in BELL_PATHS:
            cutter = snede.SurfaceCutter(body)  # a new scalpel: placed, not swept, at the path's start
            self.cutters.append(cutter)
            path = scalpels(sample_path(corners, cutter.eps_edge))  # steps of ε_edge, as in §5.4
            report = PlanarCutResult(triangles_before=mesh.n_cells, triangles_after=mesh.n_cells)
            for k, scalpel in enumerate(path, start=1):
                if not result.converged:
                    say(f"membrane-cut: stopped the {name} before move {k}/{len(path)}: the relaxation did not "
                        f"converge ({result.reason})", flush=True)
                    stopped = True
                    break
                step = cutter.move(scalpel)
                report, done = report + step, done + 1
                relaxed = ""
                if k % RELAX_EVERY == 0 or k == len(path):
                    self._hold_free_pieces()
                    result = solver.solve()
                    self.results.append(result)
                    relaxed = f"; relaxed: {briefly(result)}"
                x, y = scalpel.mean(axis=0)[:2]
                say(f"membrane-cut: {name} move {k:>2}/{len(path)}, scalpel at ({x:5.2f}, {y:5.2f}): "
                    f"{step.flips} flips, {step.nodes_inserted} inserted, {step.nodes_removed} removed, "
                    f"{step.entries} entries, {step.exits} exits, {step.triangles_after} triangles{relaxed}",
                    flush=True)
                if relaxed:
                    self._record(writer, "bell", mesh, body.displacement, self.incision(), float(done), scalpel,
                                 f"{name}, move {k}/{len(path)}: lips up to {self.opening():.3f} m apart")
            cuts[name] = report_entries(report)
            total = total + report
            if stopped:
                break

        fold = self._cut_fold(folder, say)
        self._fit_frames()
        gif = animate(self.frames, folder / "membrane-cut.gif", self._draw_frame, fps=4, projection="3d")
        fold_png = save_3d(folder / "membrane-cut_fold.png", partial(self._draw_frame, frame=self.frames[-1]),
                           f"folded sheet cut across: {self.fold.n_cells} triangles, lips in red")
        solves, opening = solve_entries(self.results), self.opening()
        notes = (f"bell: {total}; {len(self.results)} solves in {solves['seconds']:.2f} s; the lips open by up to "
                 f"{opening:.3f} m; {len(self.held)} piece(s) cut free and held. fold: {fold['report']}; "
                 f"{fold['pieces']} pieces")
        return {
            **solves, "seconds": solves["seconds"] + total.seconds + fold["cut_seconds"],
            "solve_seconds": solves["seconds"], **report_entries(total),
            "cut_seconds": total.seconds + fold["cut_seconds"], "bell_cut_seconds": total.seconds,
            "cuts": cuts, "moves": done, "frames": len(self.frames), "eps_edge_m": self.cutters[0].eps_edge,
            "incision_edges": len(self.incision()), "opening_m": opening, "pieces": len(pieces(mesh)),
            "pieces_held": len(self.held), "fold": {k: v for k, v in fold.items() if k != "report"},
            "notes": notes,
            "files": {"gif": str(gif), "fold_png": str(fold_png), "fold_xdmf": fold["xdmf"], "fold_h5": fold["h5"]},
        }

    def _cut_fold(self, folder, say) -> dict:
        """The branching cut of Figure 5.14 on the folded sheet; its summary entries."""
        mesh = self.fold
        writer = SeriesWriter(folder / "membrane-cut_fold")
        still = np.zeros((mesh.n_points, 3))
        self.fold_cutter = cutter = snede.SurfaceCutter(mesh)
        self._record(writer, "fold", mesh, still, cutter.incision_edges(), 0.0, None, "fold")
        path = scalpels(sample_path(FOLD_PATH, cutter.eps_edge), FOLD_TILT)
        report = PlanarCutResult(triangles_before=mesh.n_cells, triangles_after=mesh.n_cells)
        for k, scalpel in enumerate(path, start=1):
            step = cutter.move(scalpel)
            report = report + step
            x = scalpel.mean(axis=0)[0]
            say(f"membrane-cut: fold move {k:>2}/{len(path)}, scalpel at x = {x:5.2f}: {step.flips} flips, "
                f"{step.entries} entries, {step.branches} branches, {step.exits} exits, "
                f"{step.triangles_after} triangles", flush=True)
            if k % 2 == 0 or k == len(path):
                still = np.zeros((mesh.n_points, 3))
                self._record(writer, "fold", mesh, still, cutter.incision_edges(), float(k), scalpel,
                             f"fold, move {k}/{len(path)}: {report.branches} branches, {report.exits} exits")
        # The last picture again with the pieces apart: the layers hide the cut between them.
        self.frames.append(Frame("fold", mesh.points, mesh.cells, still, cutter.incision_edges(), None,
                                 f"fold cut: {len(pieces(mesh))} pieces, drawn {FOLD_APART} m apart", FOLD_APART))
        return {**report_entries(report), "pieces": len(pieces(mesh)), "report": report,
                "xdmf": str(writer.xdmf_path), "h5": str(writer.h5_path)}

    def _fit_frames(self) -> None:
        """One colour scale for every frame, one box for each surface (over its frames' vertices)."""
        self._largest = max(float(np.linalg.norm(f.displacement, axis=1).max()) for f in self.frames)
        self._boxes = {}
        for part in ("bell", "fold"):
            every = np.concatenate([(f.points + f.displacement)[np.unique(f.cells)]
                                    for f in self.frames if f.part == part])
            self._boxes[part] = every.min(axis=0), every.max(axis=0)

    def _draw_frame(self, ax, frame: Frame) -> None:
        colors = need("matplotlib.colors", "snede's pictures")

        points = frame.points.copy()
        if frame.apart:
            for k, piece in enumerate(pieces(snede.Mesh(frame.points, frame.cells))):
                points[piece, 1] += k * frame.apart
        draw_3d(ax, points, frame.cells, frame.displacement, norm=colors.Normalize(0.0, max(self._largest, 1e-12)),
                highlight=frame.incision)
        low, high = self._boxes[frame.part]
        if frame.part == "fold":
            high = high + [0.0, FOLD_APART, 0.0]  # room for the pieces drawn apart
        if frame.scalpel is not None:  # clipped to the surface's box, where it cuts
            s = frame.scalpel
            t = np.clip((np.array([low[2], high[2]]) - s[0, 2]) / (s[1, 2] - s[0, 2]), 0.0, 1.0)
            ends = s[0] + t[:, None] * (s[1] - s[0])
            ax.plot(ends[:, 0], ends[:, 1], ends[:, 2], color="k", linewidth=1.5)
        for setter, a, b in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), low, high):
            setter(a, b)
        ax.set_box_aspect(high - low, zoom=1.2)
        ax.view_init(*(VIEW if frame.part == "bell" else FOLD_VIEW))
        ax.text2D(0.03, 0.95, frame.label, transform=ax.transAxes, fontsize=8)



def build(parameters: Parameters) -> Scene:
    n = DIVISIONS if parameters.divisions is None else parameters.divisions
    if n < 8:
        raise ValueError(f"--divisions for the membrane-cut sets the bell's n × n squares and must be at least 8 "
                         f"(the paths need a few triangles across the bell's flank), got {n}")
    name = parameters.material or "neohookean"
    if name == "linear":
        raise ValueError("the membrane-cut scene's membrane needs a nonlinear material (its bell turns and "
                         "stretches far beyond small strains): choose neohookean, stvk or veronda")
    mesh = snede.meshing.gaussian_bell(divisions=n)
    body = snede.Body(mesh, material(name, YOUNG, POISSON), thickness=THICKNESS)
    rim = np.flatnonzero(on_rim(mesh.points))
    pull = PULL * (mesh.points[rim] - [0.5, 0.5, 0.0])
    pull[:, 2] = 0.0  # outward in x and y only
    body.fix(rim, pull)
    run = MembraneCut(body, snede.meshing.folded_sheet())
    return Scene(
        methods=METHODS, methods_note=" (a membrane has no stiffness across itself until it is stretched)",
        name="membrane-cut", description=DESCRIPTION, body=body, default_method="newton",
        probe_name="widest gap between the bell's lips [m]", probe=lambda b: run.opening(),
        evolve=run.evolve, fixed=on_rim,
        picture=lambda: {"reference": False, "highlight": run.incision(), "view": VIEW, "loads": False},
        details={"divisions": [n, n], "pull": PULL, "relax_every": RELAX_EVERY,
                 "bell_paths": {k: [list(p) for p in v] for k, v in BELL_PATHS},
                 "fold_path": [list(p) for p in FOLD_PATH], "fold_tilt": FOLD_TILT})
