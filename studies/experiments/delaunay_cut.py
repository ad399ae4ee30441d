"""§5.2 and §5.4 cutting in 2D: the Delaunay cut against subdivision (Figures 5.8, 5.16, 5.17),
how far the incision lies from the scalpel's path, and a complete constrained-Delaunay
remeshing of the cut domain as the best-possible reference.

    .venv/bin/python -m studies.experiments.delaunay_cut [--quick] [--out DIR]

The thesis's meshes are uniform grids of the square, each square split into two right
isosceles triangles (§5.4: "uniform meshes on a square grid"; Figure 5.17's peaks at 45° and
90°): snede.meshing.rectangle((1, 1), (5, 5)) has its 50 triangles (Figure 5.16) and
rectangle((1, 1), (19, 19)) its 722 (Figure 5.8). The cutters are snede.SubdivisionCutter
(each sliced triangle becomes three, Figure 5.2) and snede.DelaunayCutter with the thesis's
thresholds ε_edge = h̄/3 or h̄/8 and ε_entry = ε_exit = h̄/6 (h̄ the mean edge length of the
starting mesh); the Delaunay cutter's scalpel moves in steps of ε_edge along the path.

* (a) Figure 5.16: one S-shaped path across the 50-triangle mesh (the thesis draws its path
  but does not give it), cut by subdivision and by the Delaunay cutter at h̄/3 and h̄/8.
* (b) Figure 5.8: a curved path with hairpin turns across the 722-triangle mesh.
* (c) Figure 5.17: histograms of the smallest and largest angle of every triangle.
* (d) The distance between the sampled path and the incision (the boundary edges the cut
  made), both ways, in units of h̄.
* (e) The reference: the cut domain's boundary (the square's sides and both lips, with the
  same boundary vertices) remeshed by the ``triangle`` package (Shewchuk's Triangle), as a
  constrained Delaunay triangulation without Steiner points ('p') and as a quality mesh with
  a 30° minimum angle and no Steiner points on the boundary or the incision ('pq30YY').
  ``triangle`` is not a dependency of snede: without it these columns are left out.
* (f) Sensitivity: the S path shifted by a fraction of an element, random paths on both
  meshes, and ε_edge from h̄/8 to h̄.
* Smallest angles, where they come from (the last section): the worst triangle of every
  Delaunay cut classified by what its shortest edge joins; the faults this experiment's first
  run found, fixed since, with their reproducers as regression cases (``part`` 'regression').

Writes delaunay_cut.md, delaunay_cut.csv (one row per cut or remeshing, column ``part``),
delaunay_cut_meshes.png, delaunay_cut_722.png, delaunay_cut_angles.png and
delaunay_cut_scan.png into docs/results/.
"""
from __future__ import annotations

import math
import statistics
import time
from pathlib import Path

import numpy as np

import snede
from studies.experiments.common import Column, PageTemplate, markdown_table, parse_arguments, pyplot, save_figure, write_csv
from snede.planar_cutting import PlanarCutResult, sample_path
from snede.subdivision_cutting import SubdivisionCutter

N_SMALL, N_LARGE = 5, 19  # 2·5² = 50 triangles (Figure 5.16), 2·19² = 722 (Figure 5.8)
FRACTIONS = (3, 8)  # ε_edge = h̄/3 and h̄/8 (§5.4)
# The thesis's numbers: triangles added by each cut, §5.4 and the captions of Figures 5.8 and 5.16.
THESIS = {"subdivision": 62, "delaunay h̄/3": 10, "delaunay h̄/8": 12}
THESIS_722 = {"delaunay h̄/3": 57}

# (a) The S path: enters at the left at height S_PASSES[0], turns back (a half circle) at
# x = S_TURNS[1] to the middle pass, back again at x = S_TURNS[0] to the lower pass and leaves
# at the right. Its heights and turning points avoid the grid lines (multiples of 0.2) and
# diagonals, so that no vertex of the path lies on an edge of the grid (a special case, kept
# in the regression cases below).
S_PASSES = (0.83, 0.5, 0.17)
S_TURNS = (0.25, 0.75)
# (f) The same S shifted: every combination of these passes and turning points.
S_VARIANTS = [(passes, turns) for passes in ((0.83, 0.5, 0.17), (0.85, 0.51, 0.17), (0.87, 0.53, 0.19),
                                             (0.81, 0.47, 0.13))
              for turns in ((0.22, 0.78), (0.25, 0.75), (0.3, 0.7))]
# (b) The Figure 5.8 path: a Catmull-Rom curve through these points, with two hairpin turns
# and two tighter hooks of about an element's size (the thesis's "strongly curved segments").
FIG_5_8_POINTS = ((-0.08, 0.64), (0.15, 0.66), (0.3, 0.55), (0.36, 0.35), (0.42, 0.24), (0.47, 0.23), (0.49, 0.3),
                  (0.48, 0.5), (0.5, 0.72), (0.56, 0.76), (0.6, 0.7), (0.6, 0.5), (0.64, 0.34), (0.72, 0.3),
                  (0.8, 0.38), (0.82, 0.55), (0.86, 0.62), (0.92, 0.58), (0.95, 0.45), (1.08, 0.4))
RANDOM_PATHS = 40  # per mesh in (f); 2 in --quick
RANDOM_SEED = 516
EPS_SCAN = (8, 6, 4, 3, 2, 1.5, 1)  # ε_edge = h̄/f in (f)
# The last section's regression cases, each the reproducer of a fault this experiment's first run
# found (fixed since): an S of (f) whose h̄/3 cut split the incision 0.018 h̄ from a grid vertex;
# the straight cut of tests/python/cutting/test_delaunay_cutter.py, which exited on the
# neighbouring side edge; for subdivision, the first S (turns on the grid lines x = 0.2, 0.8) and
# a straight path with a vertex a rounding error short of x = 0.2, both once left in one piece.
SPLIT_CASE = ((0.87, 0.53, 0.19), (0.3, 0.7))
EXIT_CASE = ((-0.1, 0.43), (1.1, 0.61))
FIRST_S_TURNS = (0.2, 0.8)
BEFORE_FIXES, AFTER_FIXES = "62d92a5", "c19f2c0"  # the commits the fixes' record was measured at
BEFORE_PATH_NODES, AFTER_PATH_NODES = "adbb126", "8e87d63"  # incision nodes on the chord, then on the path
# split_incision removes an interior node within ε_edge/2 of a new incision node instead of
# splitting; the threshold was chosen from full runs of this experiment on the engine with each
# (measured once at AFTER_FIXES, when new incision nodes still went on the chord; not
# regenerated): for the S of (a) and the Figure 5.8 path at h̄/3, triangles added, smallest
# angle [°] and path–incision distance [h̄].
SPLIT_THRESHOLDS = (("0 (before)", (10, 27), (6.2, 6.5), (0.71, 0.98)),
                    ("ε_edge/2 (chosen)", (6, 21), (8.7, 15.7), (0.71, 0.98)),
                    ("ε_edge", (-2, 7), (16.5, 16.2), (0.97, 1.39)))
REMESH = {"CDT 'p'": "p", "quality 'pq30YY'": "pq30YY"}  # (e): triangle's switches
SMALL_ANGLE, LARGE_ANGLE = 20.0, 120.0  # degrees: the counts of poor triangles in the tables
TOLERANCE = 1e-9  # on the square's sides (coordinates 0 or 1)


# --- meshes, paths, angles -------------------------------------------------------------------
def grid(n: int):
    return snede.meshing.rectangle((1.0, 1.0), (n, n))


def mean_edge_length(points, cells) -> float:
    """h̄ of §5.4: the mean length of the distinct edges."""
    edges = np.unique(np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1), axis=0)
    return float(np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1).mean())


def triangle_angles(points, cells) -> np.ndarray:
    """(m, 3) interior angles in degrees, from the coordinates: triangles in the plane or in
    space (a planar point is taken as z = 0)."""
    x = np.asarray(points, dtype=float)[np.asarray(cells)]
    if x.shape[-1] == 2:
        x = np.concatenate([x, np.zeros(x.shape[:-1] + (1,))], axis=-1)
    angles = []
    for k in range(3):
        u, v = x[:, (k + 1) % 3] - x[:, k], x[:, (k + 2) % 3] - x[:, k]
        angles.append(np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), (u * v).sum(axis=1)))
    return np.degrees(np.array(angles).T)


def angle_columns(points, cells) -> dict:
    angles = triangle_angles(points, cells)
    smallest, largest = angles.min(axis=1), angles.max(axis=1)
    return {"triangles": len(cells), "min_angle": float(smallest.min()), "max_angle": float(largest.max()),
            "mean_min_angle": float(smallest.mean()), "below_20": int((smallest < SMALL_ANGLE).sum()),
            "above_120": int((largest > LARGE_ANGLE).sum())}


def arc(centre, radius, start, stop, points=48) -> np.ndarray:
    angle = np.linspace(start, stop, points)
    return np.c_[centre[0] + radius * np.cos(angle), centre[1] + radius * np.sin(angle)]


def s_path(passes=S_PASSES, turns=S_TURNS) -> np.ndarray:
    """Three passes joined by half circles: in at (−0.1, passes[0]), out at (1.1, passes[2])."""
    top, middle, bottom = passes
    left, right = turns
    first, second = (top - middle) / 2, (middle - bottom) / 2
    return np.r_[[[-0.1, top]], arc((right, top - first), first, math.pi / 2, -math.pi / 2),
                 arc((left, middle - second), second, math.pi / 2, 3 * math.pi / 2), [[1.1, bottom]]]


def catmull_rom(points, per_segment: int = 30) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    p = np.r_[[2 * p[0] - p[1]], p, [2 * p[-1] - p[-2]]]
    t = np.linspace(0, 1, per_segment, endpoint=False)[:, None]
    pieces = []
    for i in range(1, len(p) - 2):
        p0, p1, p2, p3 = p[i - 1], p[i], p[i + 1], p[i + 2]
        pieces.append(0.5 * (2 * p1 + (p2 - p0) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t ** 2
                             + (3 * p1 - p0 - 3 * p2 + p3) * t ** 3))
    return np.r_[np.concatenate(pieces), [p[-2]]]


def fig_5_8_path() -> np.ndarray:
    return catmull_rom(FIG_5_8_POINTS)


def random_path(rng) -> np.ndarray:
    """In at the left, through two random points (in increasing x, so it never crosses itself),
    out at the right."""
    xs = np.sort(rng.uniform(0.15, 0.85, 2))
    return np.r_[[[-0.2, rng.uniform(0.2, 0.8)]], np.c_[xs, rng.uniform(0.15, 0.85, 2)], [[1.2, rng.uniform(0.2, 0.8)]]]


def densify(path, step: float) -> np.ndarray:
    """The polyline ``path`` with points at most ``step`` apart (vectorised; its vertices kept)."""
    path = np.asarray(path, dtype=float)
    pieces = np.maximum(1, np.ceil(np.linalg.norm(np.diff(path, axis=0), axis=1) / step).astype(int))
    segment = np.repeat(np.arange(len(pieces)), pieces)
    t = (np.arange(pieces.sum()) - np.repeat(np.cumsum(pieces) - pieces, pieces)) / np.repeat(pieces, pieces)
    return np.r_[path[segment] + t[:, None] * (path[segment + 1] - path[segment]), path[-1:]]


def resample(path, step: float) -> np.ndarray:
    """Points equally spaced along the polyline (at most ``step`` apart; in the plane or in
    space), so that means over them are means over the path's length."""
    path = np.asarray(path, dtype=float)
    along = np.r_[0, np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))]
    s = np.linspace(0, along[-1], int(math.ceil(along[-1] / step)) + 1)
    return np.stack([np.interp(s, along, path[:, k]) for k in range(path.shape[1])], axis=1)


def inside(points) -> np.ndarray:
    return np.all((points >= 0) & (points <= 1), axis=1)


def path_length_inside(path) -> float:
    points = densify(path, 1e-3)
    keep = inside(points[:-1]) & inside(points[1:])
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1)[keep].sum())


# --- cuts ----------------------------------------------------------------------------------
def cut(n: int, method: str, path, fraction: float | None = None, origins: dict | None = None):
    """(mesh, report, h̄) after cutting the n × n grid along ``path`` by ``method``
    ('subdivision' or 'delaunay', the latter with ε_edge = h̄/fraction, default h̄/3, moving the
    scalpel in steps of ε_edge as ``DelaunayCutter.cut`` does). ``origins``, if given, receives
    for each vertex a Delaunay move created: 'incision split', 'entry', 'exit' or 'entry fix-up'
    (what else that move did, in this order of precedence)."""
    mesh = grid(n)
    h = mean_edge_length(mesh.points, mesh.cells)
    if method == "subdivision":
        return mesh, SubdivisionCutter(mesh).cut(path), h
    cutter = snede.DelaunayCutter(mesh, eps_edge=h / (fraction or 3))
    report = PlanarCutResult()
    for point in sample_path(path, cutter.eps_edge):
        before = mesh.live_vertices
        step = cutter.move(point)
        report = report + step
        if origins is not None:
            after = mesh.live_vertices
            made = np.flatnonzero(after & ~np.r_[before, np.zeros(len(after) - len(before), dtype=bool)])
            kind = ("incision split" if step.incision_splits else "entry" if step.entries else
                    "exit" if step.exits else "entry fix-up")
            origins.update({int(v): kind for v in made})
    return mesh, report, h


def on_square_side(points) -> np.ndarray:
    return np.any(np.isclose(points, 0.0, atol=TOLERANCE) | np.isclose(points, 1.0, atol=TOLERANCE), axis=1)


def incision_segments(mesh) -> tuple[np.ndarray, np.ndarray]:
    """The boundary edges not on the square's sides, found from the geometry (both lips,
    whichever cutter made them): ((k, 2, 2) coordinates, (k, 2) vertex ids)."""
    x = mesh.points
    edges = mesh.boundary_faces()
    a, b = x[edges[:, 0]], x[edges[:, 1]]
    same_side = np.zeros(len(edges), dtype=bool)
    for axis in (0, 1):
        for value in (0.0, 1.0):
            same_side |= np.isclose(a[:, axis], value, atol=TOLERANCE) & np.isclose(b[:, axis], value, atol=TOLERANCE)
    return np.stack([a[~same_side], b[~same_side]], axis=1), edges[~same_side]


def distance_to_segments(points, segments) -> np.ndarray:
    """Distance from each point (m, 2) to the nearest of the segments (k, 2, 2)."""
    if len(segments) == 0:
        return np.full(len(points), np.inf)
    a, b = segments[:, 0][None], segments[:, 1][None]
    p = points[:, None]
    d = b - a
    length2 = np.maximum((d * d).sum(axis=2), 1e-300)
    t = np.clip(((p - a) * d).sum(axis=2) / length2, 0, 1)
    return np.linalg.norm(p - (a + t[..., None] * d), axis=2).min(axis=1)


def path_incision_distances(path, mesh, h: float) -> dict:
    """Path → incision: from the path's samples inside the square to the nearest incision edge;
    incision → path: from points along the incision edges to the path polyline; in units of h̄."""
    segments, _ = incision_segments(mesh)
    samples = resample(path, h / 50)
    samples = samples[inside(samples)]
    to_incision = distance_to_segments(samples, segments) / h
    polyline = np.stack([path[:-1], path[1:]], axis=1)
    along = [a + (b - a) * t for a, b in segments for t in np.linspace(0, 1, 11)]
    to_path = distance_to_segments(np.array(along), polyline) / h if along else np.array([np.inf])
    return {"path_to_incision_max": float(to_incision.max()), "path_to_incision_mean": float(to_incision.mean()),
            "incision_to_path_max": float(to_path.max()), "hausdorff": float(max(to_incision.max(), to_path.max()))}


def boundary_crossings(path) -> list[np.ndarray]:
    """Where the path crosses the square's sides, in order."""
    points = densify(path, 1e-3)
    flags = inside(points)
    found = []
    for k in np.flatnonzero(flags[1:] != flags[:-1]):
        a, b = points[k], points[k + 1]
        lo, hi = 0.0, 1.0
        for _ in range(60):  # bisection to the side
            mid = (lo + hi) / 2
            if inside((a + mid * (b - a))[None])[0] == flags[k]:
                lo = mid
            else:
                hi = mid
        found.append(a + lo * (b - a))
    return found


def end_offsets(path, mesh, h: float) -> dict:
    """How far (in h̄) the incision's ends on the square's sides lie from where the path enters
    and leaves (for each crossing, the nearest incision vertex on a side), and that end at the exit."""
    _, edges = incision_segments(mesh)
    x = mesh.points
    ends = np.unique(edges)
    ends = x[ends[on_square_side(x[ends])]]
    crossings = boundary_crossings(path)
    if len(crossings) < 2 or not len(ends):
        return {"entry_offset": math.nan, "exit_offset": math.nan, "exit_end_x": math.nan, "exit_end_y": math.nan}
    distances = [np.linalg.norm(ends - c, axis=1) for c in (crossings[0], crossings[-1])]
    exit_end = ends[np.argmin(distances[1])]
    return {"entry_offset": float(distances[0].min() / h), "exit_offset": float(distances[1].min() / h),
            "exit_end_x": float(exit_end[0]), "exit_end_y": float(exit_end[1])}


def worst_triangle(mesh, path, h: float, origins: dict | None) -> dict:
    """The triangle with the smallest angle: its shortest edge (in h̄) and what joins it —
    'old vertex next to the incision' (an incision vertex inside the square and a vertex not on
    the incision), 'short side edge' (both ends on the square's sides: entry or exit),
    'short incision edge' (both on the incision), or 'other' — and where it is ('entry' or
    'exit' within h̄ of where the path crosses the sides, else 'inside'). With ``origins`` (see
    ``cut``), an old vertex's incision vertex is traced to the move that made it."""
    x, cells = mesh.points, mesh.cells
    angles = triangle_angles(x, cells)
    k = int(np.argmin(angles.min(axis=1)))
    corners = cells[k]
    pairs = [(corners[i], corners[(i + 1) % 3]) for i in range(3)]
    u, v = min(pairs, key=lambda e: np.linalg.norm(x[e[0]] - x[e[1]]))
    _, edges = incision_segments(mesh)
    on_incision = set(np.unique(edges).tolist())
    side = on_square_side(x[[u, v]])
    if side.all():
        kind = "short side edge"
    elif (u in on_incision) and (v in on_incision):
        kind = "short incision edge"
    elif (u in on_incision) != (v in on_incision):
        kind = "old vertex next to the incision"
    else:
        kind = "other"
    centre = x[corners].mean(axis=0)
    crossings = boundary_crossings(path)
    where = "inside"
    if crossings and np.linalg.norm(centre - crossings[0]) < h:
        where = "entry"
    elif len(crossings) > 1 and np.linalg.norm(centre - crossings[-1]) < h:
        where = "exit"
    made_by = None
    if kind == "old vertex next to the incision" and origins is not None:
        made_by = origins.get(int(u if u in on_incision else v), "starting mesh")
    return {"worst_edge": float(np.linalg.norm(x[u] - x[v]) / h), "worst_kind": kind, "worst_where": where,
            "worst_made_by_move": made_by}


def subdivision_crossings(mesh, n: int) -> tuple[int, int]:
    """Edges the subdivision split: the new vertex positions (not grid points; the lips' copies
    counted once), (inside the square, on its sides)."""
    x = mesh.points[mesh.live_vertices]
    grid_point = np.all(np.isclose(x * n, np.round(x * n), atol=1e-9), axis=1)
    new = np.unique(np.round(x[~grid_point], 12), axis=0)
    side = on_square_side(new)
    return int((~side).sum()), int(side.sum())


def cut_row(part: str, path_name: str, n: int, method: str, path, fraction=None) -> tuple[dict, object]:
    origins = {}
    mesh, report, h = cut(n, method, path, fraction, origins)
    mesh.validate()
    name = "subdivision" if method == "subdivision" else f"delaunay h̄/{fraction:g}"
    pieces, boundary = mesh.connected_components()[0], len(np.unique(mesh.boundary_faces()))
    row = {"part": part, "path": path_name, "grid": f"{n}×{n}", "cut": name,
           "triangles_before": report.triangles_before, **angle_columns(mesh.points, mesh.cells),
           "added": mesh.n_cells - report.triangles_before, "nodes": mesh.n_live_points,
           # T = 2V − B − 2C for C discs of V vertices, B on the boundary (the lips too)
           "components": pieces, "euler_ok": mesh.n_cells == 2 * mesh.n_live_points - boundary - 2 * pieces,
           "h_bar": h, "path_length_h": path_length_inside(path) / h, "moves": report.moves,
           "flips": report.flips, "nodes_removed": report.nodes_removed, "nodes_inserted": report.nodes_inserted,
           "incision_splits": report.incision_splits, "edges_contracted": report.edges_contracted,
           "entries": report.entries, "exits": report.exits, "stuck": report.stuck, "cut_ms": report.seconds * 1e3,
           **path_incision_distances(path, mesh, h), **end_offsets(path, mesh, h),
           **worst_triangle(mesh, path, h, origins if method == "delaunay" else None)}
    if method == "subdivision":
        row["split_inside"], row["split_on_sides"] = subdivision_crossings(mesh, n)
        row["sliced"] = row["added"] / 2
    return row, mesh


# --- the reference remeshing ---------------------------------------------------------------
def triangle_module():
    try:
        import triangle
    except ImportError:
        return None
    return triangle


def remesh(mesh, switches: str):
    """The cut domain's boundary (the square's sides and the incision, the two lips' coinciding
    vertices merged into one interior segment) triangulated by Triangle: (points, cells), or
    None without the ``triangle`` package."""
    triangle = triangle_module()
    if triangle is None:
        return None
    x = mesh.points
    edges = mesh.boundary_faces()
    used = np.unique(edges)
    keys, index = np.unique(np.round(x[used], 12), axis=0, return_inverse=True)
    position = np.full(len(x), -1)
    position[used] = index.ravel()
    segments = np.unique(np.sort(position[edges], axis=1), axis=0)
    segments = segments[segments[:, 0] != segments[:, 1]]
    result = triangle.triangulate({"vertices": keys, "segments": segments}, switches)
    return result["vertices"], result["triangles"]


def reference_rows(part: str, path_name: str, n: int, cuts: dict) -> tuple[list[dict], dict]:
    rows, meshes = [], {}
    for name, mesh in cuts.items():
        for title, switches in REMESH.items():
            made = remesh(mesh, switches)
            if made is None:
                continue
            points, cells = made
            meshes[name, title] = made
            boundary = np.unique(np.round(mesh.points[np.unique(mesh.boundary_faces())], 12), axis=0)
            worst = cells[np.argmin(triangle_angles(points, cells).min(axis=1))]
            on_boundary = sum(bool(np.any(np.all(np.isclose(boundary, points[v], atol=1e-12), axis=1))) for v in worst)
            rows.append({"part": part, "path": path_name, "grid": f"{n}×{n}", "cut": name, "remesh": title,
                         "switches": switches, **angle_columns(points, cells), "nodes": len(points),
                         "boundary_vertices": int(len(boundary)), "worst_boundary_corners": on_boundary})
    return rows, meshes


# --- the parts -----------------------------------------------------------------------------
def figure_rows(part: str, path_name: str, n: int, path) -> tuple[list[dict], dict]:
    rows, meshes = [], {}
    for method, fraction in (("subdivision", None), ("delaunay", 3), ("delaunay", 8)):
        row, mesh = cut_row(part, path_name, n, method, path, fraction)
        rows.append(row)
        meshes[row["cut"]] = mesh
    return rows, meshes


def s_variant_rows(quick: bool) -> list[dict]:
    return [row for passes, turns in (S_VARIANTS[:2] if quick else S_VARIANTS)
            for row in figure_rows("S variants", f"S {passes} {turns}", N_SMALL, s_path(passes, turns))[0]]


def random_rows(quick: bool) -> list[dict]:
    rows = []
    for n in (N_SMALL, N_LARGE):
        rng = np.random.default_rng(RANDOM_SEED + n)
        paths = [random_path(rng) for _ in range(2 if quick else RANDOM_PATHS)]
        rows += [row for k, path in enumerate(paths) for row in figure_rows("random paths", f"random {k}", n, path)[0]]
    return rows


def eps_rows(quick: bool) -> list[dict]:
    rows = []
    for path_name, n, path in (("S", N_SMALL, s_path()), ("Figure 5.8 path", N_LARGE, fig_5_8_path())):
        for fraction in (8, 3, 1) if quick else EPS_SCAN:
            row, _ = cut_row("ε_edge scan", path_name, n, "delaunay", path, fraction)
            row["eps_edge_h"] = 1 / fraction
            rows.append(row)
    return rows


def regression_rows() -> list[dict]:
    straight = [(f"straight, vertex at x = 0.2{' − 2⁻⁵⁵' if nudge else ''}", "subdivision",
                 np.array([[-0.1, 0.5], [0.2 - nudge, 0.5], [1.1, 0.5]]), None) for nudge in (2.0 ** -55, 0.0)]
    rows = []
    for name, method, path, fraction in [("S split case", "delaunay", s_path(*SPLIT_CASE), 3),
                                         ("straight exit case", "delaunay", np.array(EXIT_CASE), 3),
                                         ("first S (turns at x = 0.2, 0.8)", "subdivision",
                                          s_path(S_PASSES, FIRST_S_TURNS), None), *straight]:
        row, mesh = cut_row("regression", name, N_SMALL, method, path, fraction)
        x = mesh.points[np.unique(mesh.cells)]
        gaps = np.linalg.norm(x[:, None] - x[None], axis=2)
        row["closest"] = float(gaps[gaps > 1e-12].min() / row["h_bar"])  # the lips' copies coincide
        rows.append(row)
    return rows


# --- figures -------------------------------------------------------------------------------
def draw_mesh(axis, points, cells, path, title: str, incision=None, worst: bool = True) -> None:
    axis.triplot(points[:, 0], points[:, 1], cells, color="0.55", linewidth=0.5)
    if worst:
        angles = triangle_angles(points, cells).min(axis=1)
        k = int(np.argmin(angles))
        axis.fill(*points[cells[k], :2].T, color="tab:orange", alpha=0.8, zorder=3)  # a top view in 3D
        title += f"\nsmallest angle {angles[k]:.1f}° (orange)"
    if incision is not None:
        for a, b in incision:
            axis.plot([a[0], b[0]], [a[1], b[1]], color="tab:red", linewidth=1.6, zorder=4)
    axis.plot(path[:, 0], path[:, 1], ":", color="black", linewidth=1.0, zorder=5)
    axis.set_xlim(-0.03, 1.03)
    axis.set_ylim(-0.03, 1.03)
    axis.set_aspect("equal")
    axis.set_xticks([])
    axis.set_yticks([])
    axis.set_title(title, fontsize=9)


def plot_meshes(rows, meshes, references, path, out: Path, reference_of: str | None) -> None:
    plt = pyplot()
    panels = len(rows) + (1 if reference_of else 0)
    figure, axes = plt.subplots(1, panels, figsize=(3.6 * panels, 4.2))
    for axis, row in zip(axes, rows):
        mesh = meshes[row["cut"]]
        segments, _ = incision_segments(mesh)
        draw_mesh(axis, mesh.points, mesh.cells, path, f"{row['cut']}: {row['triangles_before']} → "
                  f"{row['triangles']} ({row['added']:+d})", segments)
    if reference_of:
        points, cells = references[reference_of, "quality 'pq30YY'"]
        segments, _ = incision_segments(meshes[reference_of])
        draw_mesh(axes[-1], points, cells, path, f"Triangle 'pq30YY' of the {reference_of} domain: "
                  f"{len(cells)}", segments)
    save_figure(figure, out, 120)


def plot_angles(groups: dict, out: Path) -> None:
    """groups: column title -> {label: (points, cells)}; rows: smallest angle, largest angle."""
    plt = pyplot()
    figure, axes = plt.subplots(2, len(groups), figsize=(6.2 * len(groups), 6.4), squeeze=False)
    colours = ["tab:red", "tab:blue", "tab:cyan", "tab:green", "tab:olive"]
    for column, (title, meshes) in enumerate(groups.items()):
        for row, (which, bins) in enumerate((("smallest", np.arange(0, 61, 5)), ("largest", np.arange(60, 181, 10)))):
            axis = axes[row, column]
            width = (bins[1] - bins[0]) / (len(meshes) + 1)
            for k, (name, (points, cells)) in enumerate(meshes.items()):
                angles = triangle_angles(points, cells)
                values = angles.min(axis=1) if which == "smallest" else angles.max(axis=1)
                counts, _ = np.histogram(np.clip(values, bins[0], bins[-1] - 1e-9), bins)
                axis.bar(bins[:-1] + (k + 0.5) * width, counts, width, color=colours[k % len(colours)], label=name,
                         align="edge")
            axis.set_xticks(bins)
            axis.set_xlabel(f"{which} angle of a triangle [°]")
            axis.set_ylabel("triangles")
            axis.set_yscale("log")
            if row == 0:
                axis.set_title(title, fontsize=10)
                axis.legend(fontsize=8)
    save_figure(figure, out, 110)


def plot_scan(eps, random, out: Path) -> None:
    plt = pyplot()
    figure, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    for path_name, marker in (("S", "o"), ("Figure 5.8 path", "s")):
        rows = [row for row in eps if row["path"] == path_name]
        x = [row["eps_edge_h"] for row in rows]
        left.plot(x, [row["added"] for row in rows], marker=marker, label=f"{path_name}: triangles added")
        left.plot(x, [row["min_angle"] for row in rows], marker=marker, linestyle="--",
                  label=f"{path_name}: smallest angle [°]")
    left.axhline(0, color="0.6", linewidth=0.8)
    left.axvline(0.5, color="0.6", linewidth=0.8, linestyle=":")
    left.set_xlabel("ε_edge / h̄")
    left.set_title("Delaunay cut against ε_edge", fontsize=10)
    left.legend(fontsize=8)
    names = list(dict.fromkeys(row["cut"] for row in random))
    for k, grid_name in enumerate(dict.fromkeys(row["grid"] for row in random)):
        for j, name in enumerate(names):
            values = [row["min_angle"] for row in random if row["cut"] == name and row["grid"] == grid_name]
            position = k * (len(names) + 1) + j
            right.scatter(np.full(len(values), position) + np.linspace(-0.25, 0.25, len(values)), values, s=12,
                          color=["tab:red", "tab:blue", "tab:cyan"][j % 3], label=name if k == 0 else None)
    right.set_xticks([k * (len(names) + 1) + 1 for k in range(2)])
    right.set_xticklabels([f"{g} grid" for g in dict.fromkeys(row["grid"] for row in random)])
    right.set_ylabel("smallest angle after the cut [°]")
    right.set_title("random paths", fontsize=10)
    right.legend(fontsize=8)
    save_figure(figure, out, 110)


# --- the page ------------------------------------------------------------------------------
CUT_COLUMNS = [
    Column("cut", "cut"), Column("triangles", "triangles"), Column("added", "added", "{:+d}"),
    Column("thesis", "thesis added", "{:+d}"), Column("nodes", "nodes"),
    Column("min_angle", "min angle [°]", "{:.1f}"), Column("max_angle", "max angle [°]", "{:.1f}"),
    Column("below_20", "< 20°"), Column("above_120", "> 120°"),
    Column("path_to_incision_max", "path → incision max [h̄]", "{:.3f}"),
    Column("path_to_incision_mean", "mean [h̄]", "{:.3f}"),
    Column("incision_to_path_max", "incision → path max [h̄]", "{:.3f}"),
    Column("exit_offset", "exit offset [h̄]", "{:.3f}"),
    Column("worst_edge", "worst triangle's shortest edge [h̄]", "{:.3f}"), Column("worst_kind", "made by"),
    Column("worst_where", "where"), Column("moves", "moves"), Column("flips", "flips"),
    Column("nodes_removed", "removed"), Column("incision_splits", "splits"), Column("cut_ms", "time [ms]", "{:.1f}"),
]
REFERENCE_COLUMNS = [
    Column("grid", "grid"), Column("cut", "domain of"), Column("remesh", "remeshing"),
    Column("boundary_vertices", "boundary vertices (lips merged)"), Column("triangles", "triangles"), Column("nodes", "nodes"),
    Column("min_angle", "min angle [°]", "{:.1f}"), Column("max_angle", "max angle [°]", "{:.1f}"),
    Column("mean_min_angle", "mean smallest angle [°]", "{:.1f}"), Column("below_20", "< 20°"),
    Column("above_120", "> 120°"), Column("worst_boundary_corners", "worst triangle's corners on the boundary"),
]
SCAN_COLUMNS = [
    Column("eps", "ε_edge"), Column("triangles", "triangles"), Column("added", "added", "{:+d}"),
    Column("min_angle", "min angle [°]", "{:.1f}"), Column("max_angle", "max angle [°]", "{:.1f}"),
    Column("below_20", "< 20°"), Column("path_to_incision_max", "path → incision max [h̄]", "{:.3f}"),
    Column("incision_to_path_max", "incision → path max [h̄]", "{:.3f}"), Column("worst_kind", "worst made by"),
]
VARIANT_COLUMNS = [
    Column("path", "path (passes, turns)"), Column("sub_added", "subdivision added", "{:+d}"),
    Column("d3_added", "h̄/3 added", "{:+d}"), Column("d3_min", "h̄/3 min angle [°]", "{:.1f}"),
    Column("d3_hausdorff", "h̄/3 distance [h̄]", "{:.2f}"), Column("d3_kind", "h̄/3 worst made by"),
    Column("d8_added", "h̄/8 added", "{:+d}"), Column("d8_min", "h̄/8 min angle [°]", "{:.1f}"),
    Column("d8_hausdorff", "h̄/8 distance [h̄]", "{:.2f}"), Column("sub_min", "subdivision min angle [°]", "{:.1f}"),
    Column("sub_hausdorff", "subdivision distance [h̄]", "{:.2f}"),
]
RANDOM_COLUMNS = [
    Column("grid", "grid"), Column("cut", "cut"), Column("runs", "paths"),
    Column("added_median", "added (median)", "{:+.0f}"), Column("added_range", "added (range)"),
    Column("min_angle_median", "min angle median [°]", "{:.1f}"), Column("min_angle_low", "min angle lowest [°]", "{:.1f}"),
    Column("under_10", "runs < 10°"), Column("max_angle_high", "max angle highest [°]", "{:.1f}"),
    Column("hausdorff_median", "distance median [h̄]", "{:.2f}"), Column("hausdorff_max", "distance max [h̄]", "{:.2f}"),
    Column("exit_late", "exits > ε_exit off"), Column("kinds", "worst triangle made by (runs)"),
]


def variant_table(rows) -> list[dict]:
    table = []
    for name in dict.fromkeys(row["path"] for row in rows):
        by = {row["cut"]: row for row in rows if row["path"] == name}
        table.append({"path": name[2:], "sub_added": by["subdivision"]["added"], "sub_min": by["subdivision"]["min_angle"],
                      "sub_hausdorff": by["subdivision"]["hausdorff"],
                      **{f"d{f}_{key}": by[f"delaunay h̄/{f}"][column] for f in FRACTIONS
                         for key, column in (("added", "added"), ("min", "min_angle"), ("hausdorff", "hausdorff"),
                                             ("kind", "worst_kind"))}})
    return table


def random_table(rows) -> list[dict]:
    table = []
    for grid_name in dict.fromkeys(row["grid"] for row in rows):
        for name in dict.fromkeys(row["cut"] for row in rows):
            chosen = [row for row in rows if row["grid"] == grid_name and row["cut"] == name]
            if not chosen:
                continue
            added = [row["added"] for row in chosen]
            angles = [row["min_angle"] for row in chosen]
            kinds = {}
            for row in chosen:
                key = f"{row['worst_kind']} ({row['worst_where']})"
                kinds[key] = kinds.get(key, 0) + 1
            eps_exit = 1 / 6  # in h̄
            table.append({"grid": grid_name, "cut": name, "runs": len(chosen), "added_median": statistics.median(added),
                          "added_range": f"{min(added):+d} … {max(added):+d}",
                          "min_angle_median": statistics.median(angles), "min_angle_low": min(angles),
                          "under_10": sum(a < 10 for a in angles),
                          "max_angle_high": max(row["max_angle"] for row in chosen),
                          "hausdorff_median": statistics.median(row["hausdorff"] for row in chosen),
                          "hausdorff_max": max(row["hausdorff"] for row in chosen),
                          "exit_late": (sum(row["exit_offset"] > eps_exit + 1e-6 for row in chosen)
                                        if name != "subdivision" else None),
                          "kinds": ", ".join(f"{k}: {v}" for k, v in sorted(kinds.items(), key=lambda kv: -kv[1]))})
    return table


def figure_summary(rows, thesis: dict, template: PageTemplate) -> str:
    by = {row["cut"]: row for row in rows}
    sub = by["subdivision"]
    compared = "; ".join(template.snippet("thesis_added", name=name, ours=by[name]["added"], theirs=value,
                                          difference=template.snippet("the_same") if by[name]["added"] == value
                                          else f"{by[name]['added'] - value:+d}")
                         for name, value in thesis.items())
    split = ""
    if sub.get("sliced") is not None:
        split = template.snippet("sliced", sub=sub, total=2 * sub["split_inside"] + sub["split_on_sides"],
                                 thesis_added=thesis["subdivision"], thesis_sliced=thesis["subdivision"] // 2)
    return template.snippet("figure_summary", compared=compared, split=split, sub=sub, d3=by["delaunay h̄/3"],
                            d8=by["delaunay h̄/8"])


def describe(results, quick: bool, minutes: float, triangle_version) -> str:
    """delaunay_cut.md: studies/templates/delaunay_cut.md filled with the tables and summaries."""
    from studies.experiments.cutting import engine_version

    template = PageTemplate("delaunay_cut")
    small, large = results["figure_5_16"], results["figure_5_8"]
    references, variants, random, eps = results["reference"], results["variants"], results["random"], results["eps"]
    by_small = {row["cut"]: row for row in small}
    by_large = {row["cut"]: row for row in large}
    return template.page(
        quick_flag=" --quick" if quick else "",
        run=template.snippet("quick_run", engine=engine_version()) if quick else
        template.snippet("full_run", minutes=minutes, engine=engine_version()),
        triangle=template.snippet("triangle", version=triangle_version) if triangle_version else
        template.snippet("no_triangle"),
        n_small=N_SMALL, n_large=N_LARGE, h_small=by_small["subdivision"]["h_bar"],
        h_large=by_large["subdivision"]["h_bar"], sub_added=by_small["subdivision"]["added"],
        path_length=by_large["subdivision"]["path_length_h"],
        small_table=markdown_table(small, CUT_COLUMNS), figure_summary=figure_summary(small, THESIS, template),
        large_table=markdown_table(large, CUT_COLUMNS), large_summary=large_summary(large, template),
        histogram_summary=histogram_summary(results, template),
        distance_summary=distance_summary(small, large, variants, template),
        reference_intro=reference_intro(triangle_version, template),
        reference_table=markdown_table(references, REFERENCE_COLUMNS) if references else "",
        reference_summary=reference_summary(references, small + large, template) if references else "",
        variant_table=markdown_table(variant_table(variants), VARIANT_COLUMNS),
        variant_summary=variant_summary(variants, template),
        n_random=len([r for r in random if r["cut"] == "subdivision"]) // 2,
        random_table=markdown_table(random_table(random), RANDOM_COLUMNS), random_summary=random_summary(random, template),
        eps_table=markdown_table([{**row, "eps": f"{row['path']}, h̄/{1 / row['eps_edge_h']:g}"} for row in eps],
                                 SCAN_COLUMNS),
        eps_summary=eps_summary(eps, template), worst_summary=worst_summary(results, template),
        fixes_summary=fixes_summary(results, template))


def large_summary(rows, template: PageTemplate) -> str:
    by = {row["cut"]: row for row in rows}
    sub, d3, d8 = by["subdivision"], by["delaunay h̄/3"], by["delaunay h̄/8"]
    return template.snippet("large_summary", sub=sub, d3=d3, d8=d8, d3_per_h=d3["added"] / d3["path_length_h"],
                            d8_per_h=d8["added"] / d8["path_length_h"], sub_per_h=sub["added"] / sub["path_length_h"])


def histogram_summary(results, template: PageTemplate) -> str:
    def grid_shaped(points, cells) -> int:  # triangles with angles 45°, 45°, 90°
        return int(np.all(np.abs(np.sort(triangle_angles(points, cells), axis=1) - [45, 45, 90]) < 1e-6, axis=1).sum())

    sentences = [template.snippet("grid_shapes", title=title, counts=", ".join(
        template.snippet("grid_shaped", name=name, n=grid_shaped(*mesh), total=len(mesh[1]))
        for name, mesh in group.items())) for title, group in results["angle_meshes"].items()]
    small = {row["cut"]: row for row in results["figure_5_16"]}
    sub, d3 = small["subdivision"], small["delaunay h̄/3"]
    fewer = d3["below_20"] < sub["below_20"] and d3["above_120"] <= sub["above_120"]
    sentences.append(template.snippet("histogram_verdict", sub=sub, d3=d3,
                                      verdict=template.snippet("fewer_extremes" if fewer else "not_everywhere")))
    return " ".join(sentences)


def distance_summary(small, large, variants, template: PageTemplate) -> str:
    s = {row["cut"]: row for row in small}
    table = variant_table(variants)
    closer = sum(row["d3_hausdorff"] < row["d8_hausdorff"] for row in table)
    shifted = template.snippet("shifted", n=len(table), closer=closer,
                               remark=template.snippet("remark_sometimes" if closer else "remark_never")) if table else ""
    return template.snippet("distance_summary", sub=s["subdivision"]["hausdorff"], d3=s["delaunay h̄/3"]["hausdorff"],
                            d8=s["delaunay h̄/8"]["hausdorff"], shifted=shifted)


def reference_intro(version, template: PageTemplate) -> str:
    return template.snippet("reference_intro" if version else "reference_missing")


def reference_summary(references, cuts, template: PageTemplate) -> str:
    by_cut = {(row["grid"], row["cut"]): row for row in cuts}
    lines = []
    for grid_name in dict.fromkeys(row["grid"] for row in references):
        for name in ("subdivision", "delaunay h̄/3", "delaunay h̄/8"):
            quality = next((row for row in references if row["grid"] == grid_name and row["cut"] == name
                            and row["remesh"].startswith("quality")), None)
            cdt = next((row for row in references if row["grid"] == grid_name and row["cut"] == name
                        and row["remesh"].startswith("CDT")), None)
            cut_row_ = by_cut.get((grid_name, name))
            if not (quality and cdt and cut_row_):
                continue
            lines.append(template.snippet("reference_line", grid=grid_name, name=name, cut=cut_row_, cdt=cdt,
                                          quality=quality))
    if not lines:
        return ""
    quality = [row for row in references if row["remesh"].startswith("quality")]
    short = [row for row in quality if row["min_angle"] < 30]
    pinned = [row for row in short if row["worst_boundary_corners"] >= 2]
    return template.snippet("reference_summary", lines="\n".join(lines), quality=template.snippet(
        "below_30", n_short=len(short), n_quality=len(quality), n_pinned=len(pinned)) if short else
        template.snippet("reaches_30"))


def variant_summary(variants, template: PageTemplate) -> str:
    table = variant_table(variants)
    if not table:
        return ""
    subs = [row["sub_added"] for row in table]
    d3 = [row["d3_added"] for row in table]
    d8 = [row["d8_added"] for row in table]
    m3 = [row["d3_min"] for row in table]
    m8 = [row["d8_min"] for row in table]
    ms = [row["sub_min"] for row in table]
    return template.snippet(
        "variant_summary", n=len(table), sub_min=min(subs), sub_max=max(subs), d3_min=min(d3), d3_max=max(d3),
        d8_min=min(d8), d8_max=max(d8), m3_min=min(m3), m3_max=max(m3), m8_min=min(m8), m8_max=max(m8),
        ms_min=min(ms), ms_max=max(ms), d8_low=min(d8) / 12, d8_high=max(d8) / 12,
        more=sum(b > a for a, b in zip(d3, d8)))


def random_summary(random, template: PageTemplate) -> str:
    table = random_table(random)
    pairs = []
    for grid_name in dict.fromkeys(row["grid"] for row in random):
        runs = {}
        for row in random:
            if row["grid"] == grid_name:
                runs.setdefault(row["path"], {})[row["cut"]] = row
        pairs.append(template.snippet(
            "paired", grid=grid_name, n=len(runs),
            fewer=sum(r["delaunay h̄/3"]["added"] < r["subdivision"]["added"] for r in runs.values()),
            better=sum(r["delaunay h̄/3"]["min_angle"] > r["subdivision"]["min_angle"] for r in runs.values()),
            better8=sum(r["delaunay h̄/8"]["min_angle"] > r["subdivision"]["min_angle"] for r in runs.values())))
    late = sum(row["exit_late"] or 0 for row in table)
    return template.snippet("random_summary", pairs="; ".join(pairs),
                            exits=template.snippet("late_exits", n=late) if late else template.snippet("exits_within"))


def eps_summary(eps, template: PageTemplate) -> str:
    parts = []
    for path_name in dict.fromkeys(row["path"] for row in eps):
        rows = [row for row in eps if row["path"] == path_name]
        parts.append(f"{path_name}: " + ", ".join(f"h̄/{1 / row['eps_edge_h']:g} {row['added']:+d}" for row in rows))
    above = [row for row in eps if row["eps_edge_h"] > 0.5]
    reduced = [row for row in above if row["added"] < 0]
    return template.snippet(
        "eps_summary", added="; ".join(parts),
        reduced=template.snippet("reduces", n_reduced=len(reduced), n_above=len(above)) if above else "",
        lowest=" and ".join(
            f"h̄/{1 / min((r for r in eps if r['path'] == name), key=lambda r: r['min_angle'])['eps_edge_h']:g} "
            f"({name})" for name in dict.fromkeys(row["path"] for row in eps)))


WORST_COLUMNS = [Column("kind", "shortest edge of the worst triangle joins"), Column("where", "where")] + [
    column for f in FRACTIONS for column in (
        Column(f"n{f}", f"h̄/{f}: cuts"), Column(f"low{f}", "lowest angle [°]", "{:.1f}"),
        Column(f"median{f}", "median [°]", "{:.1f}"), Column(f"edge{f}", "shortest edge [ε_edge]", "{:.2f}"))]
THRESHOLD_COLUMNS = [Column("threshold", "removal within"), Column("added", "added (S, Figure 5.8 path)"),
                     Column("angle", "smallest angle [°]"), Column("distance", "path–incision distance [h̄]")]
REGRESSION_COLUMNS = [
    Column("path", "case"), Column("cut", "cut"), Column("added", "added", "{:+d}"),
    Column("nodes_inserted", "nodes inserted"), Column("components", "pieces"),
    Column("min_angle", "min angle [°]", "{:.1f}"), Column("worst_kind", "worst made by"),
    Column("worst_where", "where"),
    Column("closest", "closest vertices [h̄]", "{:.3f}"), Column("hausdorff", "path–incision distance [h̄]", "{:.2f}"),
    Column("exit_end", "incision's end at the exit"), Column("exit_offset", "exit offset [h̄]", "{:.3f}"),
]


def worst_table(rows) -> list[dict]:
    groups = {}
    for row in rows:
        groups.setdefault((row["worst_kind"], row["worst_where"]), []).append(row)
    table = []
    for (kind, where), chosen in sorted(groups.items(), key=lambda item: -len(item[1])):
        entry = {"kind": kind, "where": where}
        for f in FRACTIONS:
            at = [row for row in chosen if row["cut"] == f"delaunay h̄/{f}"]
            if at:
                entry.update({f"n{f}": len(at), f"low{f}": min(row["min_angle"] for row in at),
                              f"median{f}": statistics.median(row["min_angle"] for row in at),
                              f"edge{f}": min(row["worst_edge"] * f for row in at)})
            else:
                entry[f"n{f}"] = 0
        table.append(entry)
    return table


def worst_summary(results, template: PageTemplate) -> str:
    snippet = template.snippet
    rows = [row for part in ("figure_5_16", "figure_5_8", "variants", "random") for row in results[part]
            if row["cut"].startswith("delaunay")]  # the ε_edge scan left out
    by = {f: [row for row in rows if row["cut"] == f"delaunay h̄/{f}"] for f in FRACTIONS}
    old = {f: [row for row in by[f] if row["worst_kind"] == "old vertex next to the incision"] for f in FRACTIONS}
    split = {f: [row for row in old[f] if row["worst_made_by_move"] == "incision split"] for f in FRACTIONS}
    shortest = {f: min((row["worst_edge"] * f for row in split[f]), default=math.nan) for f in FRACTIONS}
    side = {f: sum(row["worst_kind"] == "short side edge" for row in by[f]) for f in FRACTIONS}
    exit_edges = [row["worst_edge"] for row in by[8] if (row["worst_kind"], row["worst_where"])
                  == ("short incision edge", "exit")]
    low = {f: min(row["min_angle"] for row in by[f]) for f in FRACTIONS}
    return snippet(
        "worst_summary", n_cuts=len(rows), table=markdown_table(worst_table(rows), WORST_COLUMNS),
        old=" and ".join(snippet("cuts_at", n=len(old[f]), total=len(by[f]), f=f) for f in FRACTIONS),
        split=" and ".join(str(len(split[f])) for f in FRACTIONS),
        bound=snippet("at_least" if min(shortest.values()) >= 0.5 - 1e-6 else "not_always"),
        shortest=", ".join(snippet("edge_at", edge=shortest[f], f=f) for f in FRACTIONS),
        lowest=snippet("h8_smaller" if low[8] < low[3] else "lowest_angles", low3=low[3], low8=low[8]),
        side3=side[3], side8=side[8],
        exit=snippet("exit_edges", n=len(exit_edges), low=min(exit_edges), high=max(exit_edges)) if exit_edges else "")


def fixes_summary(results, template: PageTemplate) -> str:
    regression = {row["path"]: row for row in results["regression"]}
    now = [next(row for row in results[part] if row["cut"] == "delaunay h̄/3")
           for part in ("figure_5_16", "figure_5_8")]
    thresholds = [{"threshold": name, "added": f"{added[0]:+d}, {added[1]:+d}", "angle": f"{angle[0]}, {angle[1]}",
                   "distance": f"{distance[0]}, {distance[1]}"} for name, added, angle, distance in SPLIT_THRESHOLDS]
    thresholds.append({"threshold": "ε_edge/2, this run", "added": ", ".join(f"{row['added']:+d}" for row in now),
                       "angle": ", ".join(f"{row['min_angle']:.1f}" for row in now),
                       "distance": ", ".join(f"{row['hausdorff']:.2f}" for row in now)})
    return template.snippet(
        "fixes_summary", before_fixes=BEFORE_FIXES, after_fixes=AFTER_FIXES, before_path=BEFORE_PATH_NODES,
        after_path=AFTER_PATH_NODES, thresholds_table=markdown_table(thresholds, THRESHOLD_COLUMNS),
        regression_table=markdown_table([{**row, "exit_end": f"({row['exit_end_x']:.4g}, {row['exit_end_y']:.4g})"}
                                         for row in results["regression"]], REGRESSION_COLUMNS),
        split=regression["S split case"], exit=regression["straight exit case"],
        first=regression["first S (turns at x = 0.2, 0.8)"],
        short=next(row for path, row in regression.items() if "2⁻⁵⁵" in path))


# --- main ----------------------------------------------------------------------------------
def main(argv=None) -> dict:
    start = time.perf_counter()
    arguments = parse_arguments(__doc__, argv)
    quick, out = arguments.quick, arguments.out
    triangle = triangle_module()
    version = getattr(triangle, "__version__", "installed") if triangle else None

    s = s_path()
    small, small_meshes = figure_rows("Figure 5.16", "S", N_SMALL, s)
    large_path = fig_5_8_path()
    large, large_meshes = figure_rows("Figure 5.8", "Figure 5.8 path", N_LARGE, large_path)
    for rows, thesis in ((small, THESIS), (large, THESIS_722)):
        for row in rows:
            row["thesis"] = thesis.get(row["cut"])
    ref_small, ref_small_meshes = reference_rows("reference", "S", N_SMALL, small_meshes)
    ref_large, ref_large_meshes = reference_rows("reference", "Figure 5.8 path", N_LARGE, large_meshes)
    variants = s_variant_rows(quick)
    random = random_rows(quick)
    eps = eps_rows(quick)
    regression = regression_rows()

    plot_meshes(small, small_meshes, ref_small_meshes, s, out / "delaunay_cut_meshes.png",
                "delaunay h̄/3" if ref_small_meshes else None)
    plot_meshes(large, large_meshes, ref_large_meshes, large_path, out / "delaunay_cut_722.png", None)
    angle_meshes = {}
    for title, meshes, refs in (("Figure 5.16 cut (50 triangles)", small_meshes, ref_small_meshes),
                                ("Figure 5.8 cut (722 triangles)", large_meshes, ref_large_meshes)):
        group = {name: (mesh.points, mesh.cells) for name, mesh in meshes.items()}
        if ("delaunay h̄/3", "quality 'pq30YY'") in refs:
            group["Triangle pq30YY (h̄/3 domain)"] = refs["delaunay h̄/3", "quality 'pq30YY'"]
        angle_meshes[title] = group
    plot_angles(angle_meshes, out / "delaunay_cut_angles.png")
    plot_scan(eps, random, out / "delaunay_cut_scan.png")

    results = {"figure_5_16": small, "figure_5_8": large, "reference": ref_small + ref_large, "variants": variants,
               "random": random, "eps": eps, "regression": regression, "angle_meshes": angle_meshes,
               "meshes": {"Figure 5.16": small_meshes, "Figure 5.8": large_meshes},
               "reference_meshes": {(f"{n}×{n}", *key): value for n, refs in ((N_SMALL, ref_small_meshes),
                                                                               (N_LARGE, ref_large_meshes))
                                    for key, value in refs.items()}, "triangle": version}
    rows = small + large + ref_small + ref_large + variants + random + eps + regression
    write_csv(out / "delaunay_cut.csv", [{key: float(f"{value:.6g}") if isinstance(value, float) else value
                                          for key, value in row.items()} for row in rows])
    minutes = (time.perf_counter() - start) / 60
    (out / "delaunay_cut.md").write_text(describe(results, quick, minutes, version))
    print(f"wrote {out / 'delaunay_cut.md'}, delaunay_cut.csv and the PNGs in {time.perf_counter() - start:.0f} s"
          + ("" if version else " (no triangle package: reference remeshings left out)"))
    return results


if __name__ == "__main__":
    main()
