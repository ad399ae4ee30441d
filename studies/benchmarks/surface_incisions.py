"""Benchmark: multiple incisions on surfaces (§5.3.2) with snede.SurfaceCutter: what each
scripted cut does (events, pieces, triangles, angles) and what a move costs, plus random
scalpels over three surfaces.

    .venv/bin/python studies/benchmarks/surface_incisions.py [--quick] [--out DIR]

Scripted cuts (the scenes of tests/python/cutting/test_surface_incisions.py):
  fold, both layers   a vertical scalpel through both layers of snede.meshing.folded_sheet()
                      (160 triangles) along y, in at y = 0 and out at y = 1;
  fold, crease        a vertical scalpel at y = 0.45 pushed against the crease of the folded
                      sheet at twice the resolution (640 triangles): Figure 5.14;
  ridge, crest        a horizontal scalpel (along x at y = 0.47) lowered onto the ridge
                      z = 0.3 − 1.2 (x − ½)² (512 triangles): an entry at the crest, a branch;
  valley              the same scalpel lowered into z = 1.2 (x − ½)²: two entries meeting;
  bell, cap           a horizontal scalpel at z = 0.2 pushed across Figure 5.19's bell (392
                      triangles): crest entry, branch, annihilation behind the top;
  bell, self-crossing a vertical scalpel along the self-crossing path of
                      studies/benchmarks/surface_cut_quality.py: out through its own lip and in again.
Random scalpels: both ends along random polylines through a box around the unit square
(seeds 0..15, 8 with --quick) over the bell, the ridge and the coarse fold.

Coarse closed surfaces (issue 32 item 4), where the active node used to stick at creases:
  leaning paths       a scalpel through the 276 triangles bounding a 3 × 3 × 10 grid of the
                      unit box, from (0.2, −0.5, z − lean) to (0.6, 1.5, z + lean), moved along
                      the box's length (z from −0.1 to 1.1 in 35 steps of 0.034, shorter than
                      any edge); counted: the moves in which the scalpel moved while a tip (an
                      active node with lips) was cutting, and those after which every such tip
                      still active has moved (advancing_moves);
  random sweeps       10 sweeps of 35 moves over each of SOFA's liver2 (the boundary of
                      organ_mesh("liver2", 600), 326 triangles), a gmsh ellipsoid and the unit
                      box (192 triangles): a scalpel twice the body's diagonal, along a random
                      direction, translated across the body perpendicular to it through a random
                      point near its centre; counted: the moves after which the scalpel meets the
                      surface while a tip is cutting, those that leave a tip off the scalpel, and
                      those that leave one farther than ε_edge/4 from it (a node on a crease
                      waits until the scalpel is that far, so that no cut edge is shorter).
With --quick: the leaning paths only.

Columns: triangles before and after, the events of the cut (entries, branches, annihilations,
exits, stuck moves), the pieces the surface falls into (Mesh.connected_components), the
smallest angle and the triangles with one below 20°, and the time per move (the engine's
PlanarCutResult.seconds, the shortest of 5 runs per move for the scripted cuts, one run for
the random ones). Writes surface_incisions.csv and surface_incisions.png (the scripted cuts
in 3D, pieces pulled apart) in docs/results/. No assertions.
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.append(str(Path(__file__).resolve().parents[2]))  # the repository root: studies.experiments

import snede
from studies.experiments.common import Column, markdown_table, parse_arguments, pyplot, save_figure, write_csv
from studies.experiments.delaunay_cut import angle_columns, arc, resample
from organ_meshes import organ_mesh

REPEATS = 5


def ridge():
    return snede.meshing.height_field(lambda x, y: 0.3 - 1.2 * (x - 0.5) ** 2, divisions=(16, 16))


def valley():
    return snede.meshing.height_field(lambda x, y: 1.2 * (x - 0.5) ** 2, divisions=(16, 16))


def fine_fold():
    return snede.meshing.folded_sheet(divisions=(20, 16))


def vertical(points_xy, bottom=-1.0, top=1.0):
    return np.array([[[x, y, bottom], [x, y, top]] for x, y in points_xy])


def lowered(y0):
    return np.array([[[-0.1, y0, z], [1.1, y0, z]] for z in np.linspace(0.5, -0.1, 80)])


SELF_CROSSING = np.r_[[[-0.2, 0.35]], arc((0.6, 0.55), 0.2, -math.pi / 2, math.pi, 60), [[0.4, -0.2]]]
SCRIPTED = {
    "fold, both layers": (snede.meshing.folded_sheet,
                          lambda step: vertical(resample(np.array([[0.2, -0.2], [0.25, 0.5], [0.2, 1.2]]), step))),
    "fold, crease": (fine_fold, lambda step: vertical([(x, 0.45) for x in np.linspace(0.8, -0.2, 100)])),
    "ridge, crest": (ridge, lambda step: lowered(0.47)),
    "valley": (valley, lambda step: lowered(0.47)),
    "bell, cap": (snede.meshing.gaussian_bell,
                  lambda step: np.array([[[-0.1, y, 0.2], [1.1, y, 0.2]] for y in np.linspace(-0.2, 1.2, 120)])),
    "bell, self-crossing": (snede.meshing.gaussian_bell, lambda step: vertical(resample(SELF_CROSSING, step))),
}
RANDOM_SURFACES = {"bell": snede.meshing.gaussian_bell, "ridge": ridge, "fold": snede.meshing.folded_sheet}
EVENTS = ("entries", "branches", "annihilations", "exits", "stuck", "flips", "nodes_removed", "nodes_inserted")


def random_sweep(rng, step):
    """Both ends of the scalpel along random polylines through a box around the unit square."""
    corners = rng.uniform([-0.3, -0.3, -0.3], [1.3, 1.3, 0.6], (2, 5, 3))
    ends = [resample(c, step) for c in corners]
    n = min(map(len, ends))
    scalpels = np.stack([ends[0][:n], ends[1][:n]], axis=1)
    return scalpels[np.linalg.norm(scalpels[:, 0] - scalpels[:, 1], axis=1) > 0]


def cut(make, scalpels):
    mesh = make()
    cutter = snede.SurfaceCutter(mesh)
    reports = [cutter.move(s) for s in scalpels]
    return mesh, reports


def row_for(name, before, mesh, reports, seconds) -> dict:
    total = sum(reports[1:], reports[0])
    return {"cut": name, "triangles_before": before, **angle_columns(mesh.points, mesh.cells),
            **{event: getattr(total, event) for event in EVENTS}, "pieces": mesh.connected_components()[0],
            "moves": len(reports), "mean_ms": 1e3 * float(np.mean(seconds)), "max_ms": 1e3 * float(np.max(seconds))}


def scripted_rows(repeats: int):
    rows, meshes = [], {}
    for name, (make, scalpels_for) in SCRIPTED.items():
        step = snede.SurfaceCutter(make()).eps_edge
        scalpels = scalpels_for(step)
        best = None
        for _ in range(repeats):
            mesh, reports = cut(make, scalpels)
            seconds = np.array([r.seconds for r in reports])
            best = seconds if best is None else np.minimum(best, seconds)
        rows.append(row_for(name, make().n_cells, mesh, reports, best))
        meshes[name] = mesh
    return rows, meshes


def random_rows(seeds: int):
    rows = []
    for name, make in RANDOM_SURFACES.items():
        step = snede.SurfaceCutter(make()).eps_edge
        runs = [cut(make, random_sweep(np.random.default_rng(seed), step)) for seed in range(seeds)]
        reports = [r for _, rs in runs for r in rs]
        angles = [angle_columns(mesh.points, mesh.cells) for mesh, _ in runs]
        rows.append({"cut": f"random, {name} ({seeds} runs)", "triangles_before": make().n_cells,
                     "triangles": round(float(np.mean([a["triangles"] for a in angles]))),
                     "min_angle": min(a["min_angle"] for a in angles),
                     "below_20": round(float(np.mean([a["below_20"] for a in angles]))),
                     **{event: sum(getattr(r, event) for r in reports) for event in EVENTS},
                     "pieces": round(float(np.mean([mesh.connected_components()[0] for mesh, _ in runs]))),
                     "moves": len(reports), "mean_ms": 1e3 * float(np.mean([r.seconds for r in reports])),
                     "max_ms": 1e3 * float(np.max([r.seconds for r in reports]))})
    return rows


COLUMNS = [Column("cut", "cut"), Column("triangles_before", "triangles before"), Column("triangles", "after"),
           Column("entries", "entries"), Column("branches", "branches"), Column("annihilations", "annihilations"),
           Column("exits", "exits"), Column("stuck", "stuck moves"), Column("pieces", "pieces"),
           Column("min_angle", "min angle [°]", "{:.1f}"), Column("below_20", "< 20°"), Column("moves", "moves"),
           Column("mean_ms", "mean ms/move", "{:.3f}"), Column("max_ms", "max ms/move", "{:.3f}")]


LEANS = (0.0, 0.05, 0.1, 0.15, 0.2, 0.3)


def coarse_box():
    """A coarse closed surface: the 276 triangles bounding a 3 × 3 × 10 grid of the unit box."""
    return snede.meshing.boundary_surface(snede.meshing.box((1, 1, 1), (3, 3, 10)))[0]


def leaning_scalpels(lean: float) -> np.ndarray:
    """A scalpel through the coarse box, leaning by `lean` along its length and moved along it:
    incisions on the faces y = 0 and y = 1, entering across the bottom face's edge."""
    return np.array([[[0.2, -0.5, z - lean], [0.6, 1.5, z + lean]] for z in np.linspace(-0.1, 1.1, 36)])


def cutting_tips(mesh, cutter) -> list:
    """The active nodes that have lips (entry nodes, which have cut nothing yet, aside)."""
    lipped = set(np.unique(mesh.boundary_faces()))
    return [v for v in cutter.active_nodes if v in lipped]


def advancing_moves(mesh, scalpels, check=lambda mesh, cutter, scalpel: None):
    """(moves, advanced): the moves in which the scalpel moved while an incision was cutting
    (its tip has lips), and those after which every such tip that is still active has moved.
    From the scalpels and the mesh alone, not the cutter's report; `check` runs after each move."""
    cutter = snede.SurfaceCutter(mesh)
    eps = 1e-9
    moves = advanced = 0
    previous = None
    for scalpel in scalpels:
        tips = {v: mesh.points[v].copy() for v in cutting_tips(mesh, cutter)}
        cutter.move(scalpel)
        check(mesh, cutter, scalpel)
        if tips and np.abs(scalpel - previous).max() > eps:
            moves += 1
            advanced += all(np.abs(mesh.points[v] - x).max() > eps for v, x in tips.items() if v in cutter.active_nodes)
        previous = scalpel
    return moves, advanced


def segment_distances(points, scalpel) -> np.ndarray:
    head, tail = np.asarray(scalpel, dtype=float)
    along = tail - head
    t = np.clip((points - head) @ along / (along @ along), 0, 1)
    return np.linalg.norm(head + t[:, None] * along - points, axis=1)


def meets_surface(mesh, scalpel) -> bool:
    """Whether the scalpel meets a triangle of the mesh (Möller and Trumbore's test)."""
    head, tail = np.asarray(scalpel, dtype=float)
    a, b, c = (mesh.points[mesh.cells[:, k]] for k in range(3))
    along, e1, e2 = tail - head, b - a, c - a
    p = np.cross(along, e2)
    det = np.einsum("ij,ij->i", e1, p)
    safe = np.where(det != 0, det, 1)
    s = head - a
    q = np.cross(s, e1)
    u, v, t = np.einsum("ij,ij->i", s, p) / safe, q @ along / safe, np.einsum("ij,ij->i", e2, q) / safe
    return bool(np.any((det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0) & (t <= 1)))


def random_sweeps(mesh, rng, sweeps: int = 10, moves: int = 35) -> list:
    """Sweeps of a scalpel twice the body's diagonal, along a random direction, translated
    across the body perpendicular to it through a random point near its centre."""
    low, high = mesh.points.min(axis=0), mesh.points.max(axis=0)
    size = np.linalg.norm(high - low)
    out = []
    for _ in range(sweeps):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        across = np.cross(axis, rng.normal(size=3))
        across /= np.linalg.norm(across)
        centre = low + rng.uniform(0.3, 0.7, 3) * (high - low)
        out.append(np.array([[centre + s * across - size * axis, centre + s * across + size * axis]
                             for s in np.linspace(-0.6 * size, 0.6 * size, moves)]))
    return out


def tips_left_behind(make, sweeps, check=lambda mesh, cutter, scalpel: None):
    """(moves, off, far): over the sweeps (each on a new surface from `make`), the moves after
    which the scalpel meets the surface while a tip is cutting, those that leave a tip off the
    scalpel (by more than 1e-9 of the mean edge) and farther than ε_edge/4 from it."""
    moves = off = far = 0
    for scalpels in sweeps:
        mesh = make()
        cutter = snede.SurfaceCutter(mesh)
        for scalpel in scalpels:
            cutter.move(scalpel)
            check(mesh, cutter, scalpel)
            tips = cutting_tips(mesh, cutter)
            if tips and meets_surface(mesh, scalpel):
                distance = segment_distances(mesh.points[tips], scalpel).max()
                moves += 1
                off += distance > 3e-9 * cutter.eps_edge
                far += distance > cutter.eps_edge / 4
    return moves, off, far


def liver2_surface():
    """The boundary of SOFA's liver2 filled with about 600 tetrahedra (studies/benchmarks/organ_meshes.py)."""
    return snede.meshing.boundary_surface(organ_mesh("liver2", 600))[0]


CLOSED_SURFACES = {
    "liver2": liver2_surface,
    "ellipsoid, axes 1, 0.7, 0.5 (gmsh, h = 0.35)":
        lambda: snede.meshing.boundary_surface(snede.meshing.ellipsoid((1.0, 0.7, 0.5), h=0.35, seed=1))[0],
    "unit box, 4 × 4 × 4": lambda: snede.meshing.boundary_surface(snede.meshing.box((1, 1, 1), (4, 4, 4)))[0],
}


def coarse_rows(quick: bool):
    rows = []
    for lean in LEANS:
        moves, advanced = advancing_moves(coarse_box(), leaning_scalpels(lean))
        rows.append({"surface": "coarse box (276)", "scalpels": f"leaning by {lean}", "moves": moves, "advanced": advanced})
    if quick:
        return rows
    for name, make in CLOSED_SURFACES.items():
        moves, off, far = tips_left_behind(make, random_sweeps(make(), np.random.default_rng(0)))
        rows.append({"surface": f"{name} ({make().n_cells})", "scalpels": "10 random sweeps", "moves": moves,
                     "off": off, "far": far})
    return rows


COARSE_COLUMNS = [Column("surface", "surface (triangles)"), Column("scalpels", "scalpels"), Column("moves", "moves counted"),
                  Column("advanced", "node advanced"), Column("off", "tip off the scalpel"),
                  Column("far", "tip > ε_edge/4 off")]


def plot(meshes: dict, out) -> None:
    """Each scripted cut in 3D, its pieces pulled apart from the surface's centre and coloured."""
    plt = pyplot()
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    columns = 3
    rows = math.ceil(len(meshes) / columns)
    figure = plt.figure(figsize=(4.2 * columns, 4 * rows))
    colours = plt.get_cmap("tab10")
    for k, (name, mesh) in enumerate(meshes.items()):
        axis = figure.add_subplot(rows, columns, k + 1, projection="3d")
        count, label = mesh.connected_components()
        centre = mesh.points[np.unique(mesh.cells)].mean(axis=0)
        for piece in range(count):
            triangles = mesh.points[mesh.cells[label == piece]]
            away = triangles.reshape(-1, 3).mean(axis=0) - centre
            shift = 0.12 * away / max(np.linalg.norm(away), 1e-12) if count > 1 else 0 * away
            axis.add_collection3d(Poly3DCollection(triangles + shift, facecolor=colours(piece % 10), edgecolor="0.2",
                                                   linewidth=0.3, alpha=0.85))
        axis.set(xlim=(-0.1, 1.1), ylim=(-0.1, 1.1), zlim=(-0.1, 0.6), title=f"{name}\n{count} pieces")
        axis.view_init(elev=28, azim=-60)
        axis.set_axis_off()
    save_figure(figure, out, 100)


def main(argv=None) -> list[dict]:
    start = time.perf_counter()
    arguments = parse_arguments(__doc__, argv)
    scripted, meshes = scripted_rows(1 if arguments.quick else REPEATS)
    rows = scripted + random_rows(8 if arguments.quick else 16)
    print(markdown_table(rows, COLUMNS))
    print(markdown_table(coarse_rows(arguments.quick), COARSE_COLUMNS))
    out = arguments.out
    write_csv(out / "surface_incisions.csv", [{key: float(f"{value:.6g}") if isinstance(value, float) else value
                                              for key, value in row.items()} for row in rows])
    plot(meshes, out / "surface_incisions.png")
    print(f"wrote {out / 'surface_incisions.csv'} and surface_incisions.png in {time.perf_counter() - start:.0f} s")
    return rows


if __name__ == "__main__":
    main()
