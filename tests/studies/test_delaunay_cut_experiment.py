"""The §5.4 Delaunay-cut experiment's quick version (Figures 5.8, 5.16, 5.17): it writes its page,
table and figures, and its numbers agree with checks made here without the experiment's own
helpers: counts from the meshes' cells, angles by the law of cosines, the subdivision count
from the path's crossings of the starting grid's edges, Euler's formula, the mean edge length
the engine uses, and path–incision distances sampled more finely."""
import csv
import math

import numpy as np
import pytest

import snede
from studies.experiments import delaunay_cut as experiment


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("delaunay_cut")
    return experiment.main(["--quick", "--out", str(out)]), out


def edge_counts(cells) -> dict:
    counts = {}
    for t in cells:
        for k in range(3):
            key = tuple(sorted((int(t[k]), int(t[(k + 1) % 3]))))
            counts[key] = counts.get(key, 0) + 1
    return counts


def cosine_angles(points, cells) -> np.ndarray:
    """Angles (degrees) from the side lengths, by the law of cosines."""
    x = points[cells]
    a = np.linalg.norm(x[:, 1] - x[:, 2], axis=1)
    b = np.linalg.norm(x[:, 2] - x[:, 0], axis=1)
    c = np.linalg.norm(x[:, 0] - x[:, 1], axis=1)
    alpha = np.arccos(np.clip((b * b + c * c - a * a) / (2 * b * c), -1, 1))
    beta = np.arccos(np.clip((a * a + c * c - b * b) / (2 * a * c), -1, 1))
    return np.degrees(np.c_[alpha, beta, np.pi - alpha - beta])


def components(cells) -> int:
    parent = {}

    def find(v):
        while parent.setdefault(v, v) != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    by_edge = {}  # triangles sharing an edge are in one piece (a shared vertex alone does not join them)
    for i, t in enumerate(cells):
        for k in range(3):
            by_edge.setdefault(tuple(sorted((int(t[k]), int(t[(k + 1) % 3])))), []).append(i)
    for shared in by_edge.values():
        for j in shared[1:]:
            parent[find(("t", shared[0]))] = find(("t", j))
    return len({find(("t", i)) for i in range(len(cells))})


def grid_crossings(n: int, path) -> tuple[int, int]:
    """Edges of the n × n starting grid the path crosses: (interior, on the square's sides)."""
    mesh = snede.meshing.rectangle((1, 1), (n, n))
    counts = edge_counts(mesh.cells)
    edges = np.array(list(counts))
    shared = np.array([counts[tuple(e)] == 2 for e in edges])
    a, b = mesh.points[edges[:, 0]], mesh.points[edges[:, 1]]
    inner = side = 0
    for p, q in zip(path[:-1], path[1:]):
        d, e = q - p, b - a
        with np.errstate(divide="ignore", invalid="ignore"):
            den = d[0] * e[:, 1] - d[1] * e[:, 0]
            s = ((a - p)[:, 0] * e[:, 1] - (a - p)[:, 1] * e[:, 0]) / den
            t = ((a - p)[:, 0] * d[1] - (a - p)[:, 1] * d[0]) / den
        hit = (den != 0) & (s >= 0) & (s < 1) & (t > 0) & (t < 1)
        inner += int(np.count_nonzero(hit & shared))
        side += int(np.count_nonzero(hit & ~shared))
    return inner, side


def test_the_page_table_and_figures_are_written(quick):
    results, out = quick
    page = (out / "delaunay_cut.md").read_text()
    for heading in ("## (a) Figure 5.16", "## (b) Figure 5.8", "## (c) Figure 5.17", "## (d)", "## (e)", "## (f)",
                    "## Smallest angles: where they come from", "### Regression cases"):
        assert heading in page
    for name in ("delaunay_cut_meshes.png", "delaunay_cut_722.png", "delaunay_cut_angles.png", "delaunay_cut_scan.png"):
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        assert f"({name})" in page
    with open(out / "delaunay_cut.csv") as stream:
        rows = list(csv.DictReader(stream))
    expected = (results["figure_5_16"] + results["figure_5_8"] + results["reference"] + results["variants"]
                + results["random"] + results["eps"] + results["regression"])
    assert len(rows) == len(expected)
    for written, row in zip(rows, expected):
        assert written["part"] == row["part"] and written["cut"] == row["cut"]
        assert int(written["triangles"]) == row["triangles"]
    if results["triangle"] is None:
        assert "left out" in page and not results["reference"]


def test_the_thesis_meshes_and_thresholds():
    for n, triangles in ((experiment.N_SMALL, 50), (experiment.N_LARGE, 722)):
        mesh = experiment.grid(n)
        assert mesh.n_cells == triangles
        angles = np.sort(cosine_angles(mesh.points, mesh.cells), axis=1)
        np.testing.assert_allclose(angles, np.tile([45, 45, 90], (triangles, 1)), atol=1e-9)  # Figure 5.17's peaks
        h = experiment.mean_edge_length(mesh.points, mesh.cells)
        # the engine's own h̄: its default ε_edge is h̄/3
        assert snede.DelaunayCutter(mesh).eps_edge == pytest.approx(h / 3, rel=1e-12)


def test_counts_and_angles_are_those_of_the_cut_meshes(quick):
    results, _ = quick
    for figure, rows in (("Figure 5.16", results["figure_5_16"]), ("Figure 5.8", results["figure_5_8"])):
        n = experiment.N_SMALL if figure == "Figure 5.16" else experiment.N_LARGE
        for row in rows:
            mesh = results["meshes"][figure][row["cut"]]
            cells, points = mesh.cells, mesh.points
            assert row["triangles"] == len(cells)
            assert row["added"] == len(cells) - 2 * n * n == row["triangles"] - row["triangles_before"]
            assert row["nodes"] == len(np.unique(cells))
            angles = cosine_angles(points, cells)
            assert row["min_angle"] == pytest.approx(angles.min(axis=1).min(), abs=1e-6)
            assert row["max_angle"] == pytest.approx(angles.max(axis=1).max(), abs=1e-6)
            assert row["below_20"] == int((angles.min(axis=1) < 20).sum())
            # Euler: T = 2V − B − 2C for C discs (the lips are boundary), counted from the cells
            counts = edge_counts(cells)
            boundary = {v for e, k in counts.items() if k == 1 for v in e}
            pieces = components(cells)
            assert pieces == row["components"] == 2  # every path enters and leaves: two pieces
            assert len(cells) == 2 * len(np.unique(cells)) - len(boundary) - 2 * pieces
            assert row["euler_ok"]


def test_subdivision_makes_each_sliced_triangle_three(quick):
    results, _ = quick
    rows = [row for part in ("figure_5_16", "figure_5_8", "variants", "random") for row in results[part]
            if row["cut"] == "subdivision"]
    assert rows
    paths = {("Figure 5.16", "S"): (experiment.N_SMALL, experiment.s_path()),
             ("Figure 5.8", "Figure 5.8 path"): (experiment.N_LARGE, experiment.fig_5_8_path())}
    for passes, turns in experiment.S_VARIANTS:
        paths["S variants", f"S {passes} {turns}"] = (experiment.N_SMALL, experiment.s_path(passes, turns))
    for row in rows:
        # every sliced triangle becomes three: +2 per interior edge split, +1 per edge on a side
        assert row["added"] == 2 * row["split_inside"] + row["split_on_sides"]
        if (row["part"], row["path"]) in paths:
            n, path = paths[row["part"], row["path"]]
            assert (row["split_inside"], row["split_on_sides"]) == grid_crossings(n, path)
            # a chain of sliced triangles from one side to the other: one more than the interior splits
            assert row["added"] == 2 * (row["split_inside"] + 1)
    s = next(row for row in results["figure_5_16"] if row["cut"] == "subdivision")
    assert abs(s["added"] - experiment.THESIS["subdivision"]) <= 4  # the S is about as long as the thesis's path


def test_path_to_incision_distances_agree_with_a_finer_sampling(quick):
    results, _ = quick
    path = experiment.s_path()
    along = np.r_[0, np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))]
    s = np.arange(0, along[-1], 1e-4)  # every 1e-4 along the path
    fine = np.c_[np.interp(s, along, path[:, 0]), np.interp(s, along, path[:, 1])]
    fine = fine[np.all((fine >= 0) & (fine <= 1), axis=1)]
    for row in results["figure_5_16"]:
        mesh = results["meshes"]["Figure 5.16"][row["cut"]]
        x = mesh.points
        counts = edge_counts(mesh.cells)
        lips = [e for e, k in counts.items() if k == 1
                and not any(np.isclose(x[list(e)][:, axis], value).all() for axis in (0, 1) for value in (0.0, 1.0))]
        a, b = x[[e[0] for e in lips]], x[[e[1] for e in lips]]
        d = b - a
        t = np.clip(np.einsum("pkj,kj->pk", fine[:, None] - a[None], d) / (d * d).sum(axis=1), 0, 1)
        nearest = np.linalg.norm(fine[:, None] - (a[None] + t[..., None] * d[None]), axis=2).min(axis=1)
        h = row["h_bar"]
        assert row["path_to_incision_max"] == pytest.approx(nearest.max() / h, abs=0.01)
        assert row["path_to_incision_mean"] == pytest.approx(nearest.mean() / h, abs=0.01)
        assert row["hausdorff"] >= row["path_to_incision_max"]
    by = {row["cut"]: row for row in results["figure_5_16"]}
    # subdivision's incision is made of chords inside single triangles: within a fraction of h̄
    assert by["subdivision"]["hausdorff"] < 0.25


def test_the_eps_scan_and_thesis_column(quick):
    results, _ = quick
    for row in results["eps"]:
        assert row["added"] == row["triangles"] - row["triangles_before"]
        assert row["cut"] == f"delaunay h̄/{1 / row['eps_edge_h']:g}"
    for row in results["figure_5_16"]:
        assert row["thesis"] == experiment.THESIS[row["cut"]]
    assert [row["thesis"] for row in results["figure_5_8"]] == [None, 57, None]


def test_the_worst_triangles_are_those_of_the_meshes(quick):
    results, _ = quick
    for figure, rows in (("Figure 5.16", results["figure_5_16"]), ("Figure 5.8", results["figure_5_8"])):
        for row in rows:
            mesh = results["meshes"][figure][row["cut"]]
            x, cells = mesh.points, mesh.cells
            worst = cells[np.argmin(cosine_angles(x, cells).min(axis=1))]
            shortest = min(np.linalg.norm(x[worst[k]] - x[worst[(k + 1) % 3]]) for k in range(3))
            assert row["worst_edge"] == pytest.approx(shortest / row["h_bar"], rel=1e-9)
    # the classification table counts every Delaunay cut of (a), (b) and (f) once
    delaunay = [row for part in ("figure_5_16", "figure_5_8", "variants", "random") for row in results[part]
                if row["cut"].startswith("delaunay")]
    table = experiment.worst_table(delaunay)
    assert sum(entry[f"n{f}"] for entry in table for f in experiment.FRACTIONS) == len(delaunay)


def test_the_regression_cases_agree_with_cuts_made_here(quick):
    results, _ = quick
    rows = {row["path"]: row for row in results["regression"]}
    # The straight exit case cut by DelaunayCutter.cut itself: the incision's end reported is its
    # vertex on x = 1 nearest to where the line leaves the square.
    mesh = snede.meshing.rectangle((1, 1), (5, 5))
    cutter = snede.DelaunayCutter(mesh)
    cutter.cut(np.array(experiment.EXIT_CASE))
    row = rows["straight exit case"]
    assert row["triangles"] == mesh.n_cells
    (x0, y0), (x1, y1) = experiment.EXIT_CASE
    leaves = np.array([1.0, y0 + (y1 - y0) * (1 - x0) / (x1 - x0)])
    ends = mesh.points[np.unique(cutter.incision_edges())]
    ends = ends[np.isclose(ends[:, 0], 1)]
    nearest = ends[np.argmin(np.linalg.norm(ends - leaves, axis=1))]
    assert (row["exit_end_x"], row["exit_end_y"]) == pytest.approx(tuple(nearest), abs=1e-12)
    assert row["exit_offset"] == pytest.approx(np.linalg.norm(nearest - leaves) / row["h_bar"], abs=1e-6)
    # The S split case: its closest distinct vertices and smallest angle, from a cut made here.
    mesh = snede.meshing.rectangle((1, 1), (5, 5))
    snede.DelaunayCutter(mesh).cut(experiment.s_path(*experiment.SPLIT_CASE))
    row = rows["S split case"]
    points = mesh.points[np.unique(mesh.cells)]
    gaps = np.linalg.norm(points[:, None] - points[None], axis=2)
    assert row["closest"] * row["h_bar"] == pytest.approx(gaps[gaps > 1e-12].min(), rel=1e-9)
    assert row["min_angle"] == pytest.approx(cosine_angles(mesh.points, mesh.cells).min(), abs=1e-6)
    # Subdivision through a path vertex on (or a rounding error short of) a grid edge: every
    # crossing of the starting grid is split, one node each, and the square comes apart.
    paths = {"first S (turns at x = 0.2, 0.8)": experiment.s_path(experiment.S_PASSES, experiment.FIRST_S_TURNS),
             "straight, vertex at x = 0.2": np.array([[-0.1, 0.5], [0.2, 0.5], [1.1, 0.5]]),
             "straight, vertex at x = 0.2 − 2⁻⁵⁵": np.array([[-0.1, 0.5], [0.2 - 2.0 ** -55, 0.5], [1.1, 0.5]])}
    for name, path in paths.items():
        inner, side = grid_crossings(experiment.N_SMALL, path)
        row = rows[name]
        assert (row["split_inside"], row["split_on_sides"]) == (inner, side), name
        assert row["added"] == 2 * inner + side and row["nodes_inserted"] == inner + side, name
        assert row["components"] == 2, name


def test_the_reference_remeshing_is_optional(monkeypatch):
    mesh = experiment.grid(3)
    monkeypatch.setattr(experiment, "triangle_module", lambda: None)
    assert experiment.reference_rows("reference", "none", 3, {"uncut": mesh}) == ([], {})


def test_the_reference_cdt_triangulates_the_cut_boundary(quick):
    pytest.importorskip("triangle")
    results, _ = quick
    for row in results["reference"]:
        if row["switches"] != "p":
            continue
        points, cells = results["reference_meshes"][row["grid"], row["cut"], row["remesh"]]
        assert len(cells) == row["triangles"]
        # no Steiner points: the vertices are the cut's boundary vertices, the lips' pairs merged
        assert len(points) == row["boundary_vertices"]
        # a triangulated convex polygon (the square) with vertices on its sides and inside:
        # T = 2V − (vertices on the sides) − 2
        on_sides = np.any(np.isclose(points, 0) | np.isclose(points, 1), axis=1).sum()
        assert len(cells) == 2 * len(points) - on_sides - 2
        assert cosine_angles(points, cells).min() == pytest.approx(row["min_angle"], abs=1e-6)
