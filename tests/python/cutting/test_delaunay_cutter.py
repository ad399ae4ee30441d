"""The Delaunay cutter (§5.2.2) on 2D triangle meshes: validity, the empty-circle property and
the active node at the scalpel after every move of random paths (straight, curved, closed
loops that cross the incision, entering and leaving, stopping inside); separation into pieces;
the count of added triangles against the path length; a plane-stress body cut while it is
stretched (solves converge, an affine field is carried exactly, the cut opens); bad input.
References independent of the cutter: an in-circle determinant evaluated here in numpy, the
mesh's own validation, connected components, analytic affine fields and PETSc's reasons."""
import math

import numpy as np
import pytest

import snede
from snede.planar_cutting import sample_path


def non_delaunay_edges(mesh) -> int:
    """Interior edges whose opposite vertex lies strictly inside the other triangle's
    circumcircle (relative tolerance 1e-10: grid squares are cocircular)."""
    points, cells = mesh.points, mesh.cells
    opposite = {}
    for t in cells:
        for k in range(3):
            a, b = sorted((t[k], t[(k + 1) % 3]))
            opposite.setdefault((a, b), []).append(t[(k + 2) % 3])
    bad = 0
    for (a, b), across in opposite.items():
        if len(across) != 2:
            continue
        c, d = across
        rows = np.array([[*(points[x] - points[d]), (points[x] - points[d]) @ (points[x] - points[d])] for x in (a, b, c)])
        orientation = np.sign(np.cross(points[b] - points[a], points[c] - points[a]))
        if np.linalg.det(rows) * orientation > 1e-10 * np.abs(rows).max() ** 2:
            bad += 1
    return bad


def random_path(rng, kind: str) -> np.ndarray:
    if kind == "straight":
        return np.array([[-0.2, rng.uniform(0.2, 0.8)], [1.2, rng.uniform(0.2, 0.8)]])
    if kind == "stops inside":
        return np.array([[rng.uniform(0.2, 0.8), 1.2], rng.uniform(0.3, 0.7, 2)])
    if kind == "curved":
        angle = np.linspace(-0.4, rng.uniform(2.5, 4.0), 40)
        radius = rng.uniform(0.25, 0.4)
        return np.r_[[[0.5 + 0.7, 0.5 - 0.3]], np.c_[0.5 + radius * np.cos(angle), 0.5 + radius * np.sin(angle)]]
    if kind == "loop":  # a closed loop through the body: the path crosses its own incision
        angle = np.linspace(0, 2.3 * math.pi, 60)
        return np.r_[[[-0.2, 0.5]], np.c_[0.5 - 0.3 * np.cos(angle), 0.5 + 0.3 * np.sin(angle)]]
    return np.r_[[[-0.2, rng.uniform(0.2, 0.8)]], rng.uniform(0.1, 0.9, (3, 2)), [[1.2, rng.uniform(0.2, 0.8)]]]


@pytest.mark.parametrize("kind", ["straight", "stops inside", "curved", "loop", "zigzag"])
def test_every_move_keeps_a_valid_delaunay_mesh_with_the_active_node_at_the_scalpel(kind):
    rng = np.random.default_rng(sum(map(ord, kind)))
    for trial in range(4):
        n = int(rng.integers(4, 11))
        mesh = snede.meshing.rectangle((1, 1), (n, n))
        cutter = snede.DelaunayCutter(mesh)
        points = sample_path(random_path(rng, kind), cutter.eps_edge * rng.uniform(0.3, 1.5))
        entered = 0
        for point in points:
            report = cutter.move(point)
            entered += report.entries
            mesh.validate()
            assert mesh.quality().volume.min() > 0
            if cutter.active_node is not None and report.stuck == 0:
                np.testing.assert_allclose(mesh.points[cutter.active_node], point, atol=1e-12)
        assert entered > 0, f"{kind} trial {trial}: the scalpel never entered"
        assert non_delaunay_edges(mesh) == 0
        edges = cutter.incision_edges()
        boundary = {tuple(sorted(e)) for e in mesh.boundary_faces()}
        assert len(edges) > 0 and all(tuple(sorted(e)) in boundary for e in edges)


def test_a_cut_across_separates_and_one_that_stops_leaves_one_piece():
    mesh = snede.meshing.rectangle((1, 1), (8, 8))
    cutter = snede.DelaunayCutter(mesh)
    report = cutter.cut([[0.43, 1.2], [0.43, 0.5]])
    assert report.entries == 1 and report.exits == 0 and cutter.active_node is not None
    assert mesh.connected_components()[0] == 1
    report = report + cutter.cut([[0.43, 0.5], [0.47, -0.2]])
    assert report.exits == 1 and cutter.active_node is None
    assert mesh.connected_components()[0] == 2
    # The incision follows the path: every incision vertex within a third of an edge of it.
    x = mesh.points[np.unique(cutter.incision_edges())]
    along = np.clip((x[:, 1] - 1.2) / (-0.7), 0, 1)
    path_x = np.where(x[:, 1] >= 0.5, 0.43, 0.43 + 0.04 * (0.5 - x[:, 1]) / 0.7)
    assert np.abs(x[:, 0] - path_x).max() < cutter.eps_edge
    assert along.size > 0


def test_a_straight_cut_enters_and_leaves_where_its_line_crosses_the_sides():
    # The entry and exit nodes are made on the crossing or picked within ε_entry / ε_exit of
    # it (Figures 5.6, 5.7); even when the exit sees two collinear boundary edges at once.
    rng = np.random.default_rng(11)
    paths = [np.array([[-0.1, 0.43], [1.1, 0.61]])] + [
        np.array([[-0.2, rng.uniform(0.1, 0.9)], [1.2, rng.uniform(0.1, 0.9)]]) for _ in range(24)]
    for path in paths:
        n = 5 if path is paths[0] else int(rng.integers(4, 12))
        mesh = snede.meshing.rectangle((1, 1), (n, n))
        cutter = snede.DelaunayCutter(mesh)
        report = cutter.cut(path)
        assert report.entries == 1 and report.exits == 1, (path, report)
        direction = (path[1] - path[0]) / np.linalg.norm(path[1] - path[0])
        ends = mesh.points[np.unique(cutter.incision_edges())]
        ends = ends[np.isclose(ends[:, 0], 0) | np.isclose(ends[:, 0], 1)]
        assert len(ends) >= 3, (path, ends)  # the entry node, and the exit node on both lips
        off_line = np.abs(np.cross(ends - path[0], direction))
        assert off_line.max() <= max(cutter.eps_entry, cutter.eps_exit) * (1 + 1e-9), (path, ends)
        assert mesh.connected_components()[0] == 2


def test_no_incision_node_is_made_next_to_an_old_vertex():
    # An S-shaped path (two half turns of radius 0.17) whose incision split once put a node
    # 0.004 (0.018 h̄) from the grid vertex (0.6, 0.6), a 1.1° sliver: the interior vertex is
    # removed instead. No two distinct vertices end up closer than ε_edge/4.
    mesh = snede.meshing.rectangle((1, 1), (5, 5))
    cutter = snede.DelaunayCutter(mesh)
    turn = np.linspace(0.5 * math.pi, -0.5 * math.pi, 48)
    back = np.linspace(0.5 * math.pi, 1.5 * math.pi, 48)
    cutter.cut(np.r_[[[-0.1, 0.87]], np.c_[0.7 + 0.17 * np.cos(turn), 0.70 + 0.17 * np.sin(turn)],
                     np.c_[0.3 + 0.17 * np.cos(back), 0.36 + 0.17 * np.sin(back)], [[1.1, 0.19]]])
    points = mesh.points[np.unique(mesh.cells)]
    gaps = np.linalg.norm(points[:, None] - points[None], axis=2)
    distinct = gaps[gaps > 1e-12]
    assert distinct.min() > cutter.eps_edge / 4, distinct.min()


def distance_to_polyline(x, polyline) -> float:
    a, b = polyline[:-1], polyline[1:]
    d = b - a
    t = np.clip(((x - a) * d).sum(axis=1) / np.maximum((d * d).sum(axis=1), 1e-300), 0, 1)
    return float(np.linalg.norm(a + t[:, None] * d - x, axis=1).min())


def test_incision_splits_put_their_nodes_on_the_scalpels_path():
    # §5.2.2: the new nodes go where the line through the opposite nodes crosses the path (the
    # active node's trail); only where that line misses the trail do they fall on the chord.
    rng = np.random.default_rng(5)
    made, on_path = 0, 0
    for trial in range(12):
        n = int(rng.integers(4, 12))
        mesh = snede.meshing.rectangle((1, 1), (n, n))
        cutter = snede.DelaunayCutter(mesh)
        trail = []
        for point in sample_path(random_path(rng, "curved"), cutter.eps_edge):
            before = mesh.live_vertices.copy()
            report = cutter.move(point)
            if cutter.active_node is not None:
                trail.append(mesh.points[cutter.active_node].copy())
            if report.incision_splits:
                after = mesh.live_vertices
                new = np.flatnonzero(after & ~np.r_[before, np.zeros(len(after) - len(before), dtype=bool)])
                for v in new:
                    made += 1
                    on_path += distance_to_polyline(mesh.points[v], np.array(trail)) < 1e-12
    assert made > 50
    assert on_path >= 0.9 * made, (on_path, made)


def test_triangles_added_grow_with_the_path_not_with_the_number_of_moves():
    # The thesis's 50-triangle mesh (Figure 5.16): +10 triangles at h/3 for its cut.
    added = {}
    for moves_per_edge in (1, 4):
        mesh = snede.meshing.rectangle((1, 1), (5, 5))
        cutter = snede.DelaunayCutter(mesh)
        report = cutter.cut([[-0.1, 0.43], [1.1, 0.61]], step=cutter.eps_edge / moves_per_edge)
        assert report.exits == 1
        added[moves_per_edge] = report.triangles_after - report.triangles_before
    h = 0.2
    length = math.hypot(1.0, 0.15)  # the part of the path inside the square
    for count in added.values():
        assert 0 < count <= 4 * length / h
    assert abs(added[4] - added[1]) <= 4


def test_scale_free_threshold_cuts_like_the_distance_one():
    mesh = snede.meshing.rectangle((1, 1), (6, 6))
    cutter = snede.DelaunayCutter(mesh, short_edge_angle=math.radians(25))
    report = cutter.cut([[-0.1, 0.37], [1.1, 0.52]])
    mesh.validate()
    assert report.exits == 1 and mesh.connected_components()[0] == 2
    assert non_delaunay_edges(mesh) == 0


def test_an_affine_displacement_is_carried_exactly_to_every_node_the_cut_makes():
    mesh = snede.meshing.rectangle((1, 1), (7, 7))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3), thickness=0.01)
    gradient = np.array([[0.03, -0.01], [0.02, 0.05]])

    def affine(x):
        return x @ gradient.T + np.array([0.01, -0.02])

    body.displacement = affine(mesh.points)
    cutter = snede.DelaunayCutter(body)
    # A path given in deformed coordinates: the images of reference points.
    reference_path = np.array([[0.31, 1.2], [0.45, 0.6], [0.7, 0.35]])
    path = reference_path + affine(reference_path)
    for point in sample_path(path, cutter.eps_edge / 2):
        cutter.move(point)
        mesh.validate()
        live = mesh.live_vertices  # removed nodes' rows are free slots
        np.testing.assert_allclose(body.displacement[live], affine(mesh.points[live]), atol=1e-12)
        if cutter.active_node is not None:  # the active node's deformed position is the scalpel
            x = mesh.points[cutter.active_node]
            np.testing.assert_allclose(x + affine(x), point, atol=1e-9)
    assert cutter.incision_edges().size > 0


def test_stretched_sheet_opens_as_it_is_cut_and_every_solve_converges():
    mesh = snede.meshing.rectangle((1, 1), (8, 8))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3), thickness=0.01)
    x = mesh.points
    body.fix(np.flatnonzero(x[:, 0] == 0))
    body.fix(np.flatnonzero(x[:, 0] == 1), (0.1, 0.0))
    solver = snede.StaticSolver(body, "cg", rtol=1e-10)
    assert solver.solve().converged
    cutter = snede.DelaunayCutter(body)
    middle = 0.5 + body.displacement[np.argmin(np.abs(x[:, 0] - 0.5) + np.abs(x[:, 1] - 1.0)), 0]
    for point in sample_path([[middle, 1.2], [middle, 0.4]], cutter.eps_edge):
        cutter.move(point)
        mesh.validate()
        result = solver.solve()
        assert result.converged, result.reason
    assert cutter.active_node is not None
    # The lips, two nodes at each reference point of the incision, are pulled apart.
    u = body.displacement
    at = {}
    for v in np.unique(cutter.incision_edges()):
        at.setdefault(tuple(np.round(mesh.points[v], 12)), []).append(v)
    gaps = [abs(u[a, 0] - u[b, 0]) for pair in at.values() if len(pair) == 2 for a, b in [pair]]
    assert gaps and max(gaps) > 0.01


@pytest.mark.parametrize("options, message", [
    ({"eps_edge": float("inf")}, "eps_edge"), ({"eps_entry": -1}, "eps_entry"), ({"eps_exit": float("nan")}, "eps_exit"),
    ({"short_edge_angle": 2.0}, "short_edge_angle")])
def test_bad_thresholds_are_refused(options, message):
    with pytest.raises(ValueError, match=message):
        snede.DelaunayCutter(snede.meshing.rectangle((1, 1), (3, 3)), **options)


def test_bad_points_and_paths_are_refused_before_anything_changes():
    mesh = snede.meshing.rectangle((1, 1), (3, 3))
    cutter = snede.DelaunayCutter(mesh)
    cells = mesh.cells.copy()
    with pytest.raises(ValueError, match="non-finite"):
        cutter.move([float("nan"), 0.5])
    with pytest.raises(ValueError, match="2 coordinates"):
        cutter.move([0.5, 0.5, 0.5])
    with pytest.raises(ValueError, match="n >= 2"):
        cutter.cut([[0.5, 0.5]])
    with pytest.raises(ValueError, match="2D triangle mesh"):
        snede.DelaunayCutter(snede.meshing.box((1, 1, 1), (2, 2, 2)))
    np.testing.assert_array_equal(mesh.cells, cells)
