"""Benchmark: multiple incisions on surfaces (§5.3.2) with snede.SurfaceCutter: what each
scripted cut does (events, pieces, triangles, angles) and what a move costs, plus random
scalpels over three surfaces.

    .venv/bin/python benchmarks/surface_incisions.py [--quick] [--out DIR]

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
                      benchmarks/surface_cut_quality.py: out through its own lip and in again.
Random scalpels: both ends along random polylines through a box around the unit square
(seeds 0..15, 8 with --quick) over the bell, the ridge and the coarse fold.

Columns: triangles before and after, the events of the cut (entries, branches, annihilations,
exits, stuck moves), the pieces the surface falls into (Mesh.connected_components), the
smallest angle and the triangles with one below 20°, and the time per move (the engine's
PlanarCutReport.seconds, the shortest of 5 runs per move for the scripted cuts, one run for
the random ones). Writes surface_incisions.csv and surface_incisions.png (the scripted cuts
in 3D, pieces pulled apart) in docs/results/. No assertions.
"""
from __future__ import annotations

import math
import time

import numpy as np

import snede
from snede.experiments.common import Column, markdown_table, parse_arguments, pyplot, write_csv
from snede.experiments.delaunay_cut import angle_columns, arc, resample

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
    figure.tight_layout()
    figure.savefig(out, dpi=100)
    plt.close(figure)


def main(argv=None) -> list[dict]:
    start = time.perf_counter()
    arguments = parse_arguments(__doc__, argv)
    scripted, meshes = scripted_rows(1 if arguments.quick else REPEATS)
    rows = scripted + random_rows(8 if arguments.quick else 16)
    print(markdown_table(rows, COLUMNS))
    out = arguments.out
    write_csv(out / "surface_incisions.csv", [{key: float(f"{value:.6g}") if isinstance(value, float) else value
                                              for key, value in row.items()} for row in rows])
    plot(meshes, out / "surface_incisions.png")
    print(f"wrote {out / 'surface_incisions.csv'} and surface_incisions.png in {time.perf_counter() - start:.0f} s")
    return rows


if __name__ == "__main__":
    main()
