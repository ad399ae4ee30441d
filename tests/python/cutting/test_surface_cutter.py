"""The surface cutter (§5.3.1) on triangulated surfaces in 3D: validity after every move on a
flat square and a Gaussian bell (random paths, scalpels tilted towards the surface or lying
flat on it, paths through vertices and along edges), the 2D Delaunay cutter's result on a flat
square, a pre-tensioned membrane that opens, and bad input. Multiple incisions (§5.3.2) are
in test_surface_incisions.py."""
import math

import numpy as np
import pytest

import snede
from surface_checks import along, bell, bell_normal, check_surface, flat_square, mean_edge, random_path, up, \
    vertical_scalpels


@pytest.mark.parametrize("surface, normal, seed", [
    *[pytest.param(flat_square, up, seed, id=f"flat-{seed}") for seed in range(12)],
    *[pytest.param(bell, bell_normal, seed, id=f"bell-{seed}") for seed in range(12)],
])
def test_random_paths_keep_the_surface_valid(surface, normal, seed):
    mesh = surface()
    cutter = snede.SurfaceCutter(mesh)
    h = mean_edge(mesh)
    rng = np.random.default_rng(seed)
    tilt = rng.uniform(-1, 1, 2) * (seed % 2)  # odd seeds lean the scalpel by up to 55°
    total = snede.PlanarCutResult()
    for scalpel in vertical_scalpels(along(random_path(rng), cutter.eps_edge), tilt=tilt):
        total = total + cutter.move(scalpel)
        check_surface(mesh, cutter, normal, h)
    assert total.entries >= 1 and total.incision_splits >= 1
    assert cutter.incision_edges().size > 0


def test_paths_through_vertices_and_along_edges():
    """The scalpel passes exactly through mesh vertices (the diagonal of the square grid's
    triangles) and along a row of edges: intersections on vertices and edges are exact."""
    mesh = flat_square()
    cutter = snede.SurfaceCutter(mesh)
    h = mean_edge(mesh)
    for path in ([[-0.125, -0.125], [1.125, 1.125]], [[0.5, -0.2], [0.5, 1.2]]):
        cutter.lift()
        for scalpel in vertical_scalpels(along(np.array(path), cutter.eps_edge / 2)):
            cutter.move(scalpel)
            check_surface(mesh, cutter, up, h)
    assert cutter.incision_edges().size > 0


def test_scalpel_nearly_parallel_and_flat_on_the_surface():
    """A scalpel leaning 85° from the normal (its hit moves 11 times as fast as its ends,
    Figure 5.11's large movements), then one lying in the surface's plane (the sweep is
    coplanar with every edge, equation (5.1) has no isolated roots)."""
    mesh = flat_square()
    cutter = snede.SurfaceCutter(mesh)
    h = mean_edge(mesh)
    lean = math.tan(math.radians(85))
    path = along(np.array([[-0.2, 0.3], [1.2, 0.4]]), cutter.eps_edge)
    for scalpel in vertical_scalpels(path, bottom=-0.05, top=0.05, tilt=(0.0, lean)):
        cutter.move(scalpel)
        check_surface(mesh, cutter, up, h)
    assert cutter.incision_edges().size > 0
    cutter.lift()
    flat = [[[x, 0.7 - 0.05, 0.0], [x, 0.7 + 0.05, 0.0]] for x in np.linspace(-0.2, 1.2, 60)]
    for scalpel in flat:
        cutter.move(scalpel)
        check_surface(mesh, cutter, up, h)


def boundary_length(mesh):
    b = mesh.boundary_faces()
    return np.linalg.norm(mesh.points[b[:, 0]] - mesh.points[b[:, 1]], axis=1).sum()


@pytest.mark.parametrize("x, same_points", [(0.43, True), (0.5, True), (0.61, False)])
def test_flat_cut_equals_the_2d_delaunay_cut(x, same_points):
    """A straight cut across a flat square (z = 0) with a vertical segment scalpel, against
    snede.DelaunayCutter on the same planar mesh and path. "Equal" means the same events
    (entries, exits, splits, removals), the same numbers of triangles and vertices, and the
    same boundary length: the perimeter plus two lips of length 1, to 1e-12 (rounding in the
    sum) when the path stays clear of the grid's nodes, where both cutters also put every
    vertex at the same position (to 1e-12: the hit of a segment and a point scalpel round
    differently). At x = 0.61 the path passes within ε_edge of the nodes at x = 0.625, which
    both remove; the 2D cutter then moves its new incision nodes onto the scalpel's path, this
    one leaves them on the cut edges (a chord of it): the lips differ by less than 1e-3 of
    their length, and neither is more than 5e-3 longer than straight."""
    path = np.linspace([x, -0.2], [x, 1.2], 60)
    mesh = flat_square()
    report = snede.SurfaceCutter(mesh).cut(vertical_scalpels(path))
    planar = snede.meshing.rectangle((1.0, 1.0), (8, 8))
    planar_report = snede.DelaunayCutter(planar).cut(path, step=np.linalg.norm(path[1] - path[0]))
    for event in ("entries", "exits", "incision_splits", "nodes_removed", "nodes_inserted"):
        assert getattr(report, event) == getattr(planar_report, event), event
    assert report.entries == 1 and report.exits == 1
    assert mesh.n_cells == planar.n_cells and len(mesh.live_vertices) == len(planar.live_vertices)
    ours, theirs = boundary_length(mesh), boundary_length(planar)
    if same_points:
        a = np.array(sorted(map(tuple, np.round(mesh.points[mesh.live_vertices][:, :2], 12))))
        b = np.array(sorted(map(tuple, np.round(planar.points[planar.live_vertices], 12))))
        np.testing.assert_allclose(a, b, atol=1e-12)
        assert ours == pytest.approx(6, abs=1e-12) and theirs == pytest.approx(6, abs=1e-12)
    else:
        assert abs(ours - theirs) <= 1e-3 * 2 and 6 <= ours <= 6 + 5e-3 and 6 <= theirs <= 6 + 5e-3
    assert not np.any(mesh.points[mesh.live_vertices][:, 2])  # the cut stays in the plane


def test_pretensioned_membrane_opens_when_cut():
    """A flat neo-Hookean membrane, its rim pulled out by 10 %, cut along x = 0.5 in deformed
    coordinates: after a static solve (Newton, no preconditioner) the two lips separate."""
    mesh = flat_square()
    body = snede.Body(mesh, snede.NeoHookean(1e5, 0.3), thickness=0.001)
    X = mesh.points
    rim = np.unique(mesh.boundary_faces())
    stretch = 0.1 * (X - [0.5, 0.5, 0.0])
    stretch[:, 2] = 0
    body.fix(rim, stretch[rim])
    solver = snede.StaticSolver(body, "newton", preconditioner="none", rtol=1e-10)
    assert solver.solve().converged
    cutter = snede.SurfaceCutter(body)
    # deformed x = 1.1 X − 0.05: the line X = 0.43 is at x = 0.423, from y = 0.2 to 0.8 inside.
    path = np.linspace([0.423, 0.1], [0.423, 0.6], 40)
    for scalpel in vertical_scalpels(path, bottom=-0.5, top=0.5):
        cutter.move(scalpel)
        mesh.validate()
    assert cutter.active_node is not None
    u = body.displacement
    live = mesh.live_vertices
    # The body followed the edits: the untouched stretch field everywhere, before solving.
    np.testing.assert_allclose(u[live][:, :2], 0.1 * (mesh.points[live][:, :2] - 0.5), atol=1e-12)
    assert solver.solve().converged
    u = body.displacement
    pairs = {}
    for v in np.unique(cutter.incision_edges()):
        pairs.setdefault(tuple(mesh.points[v]), []).append(v)
    gaps = [abs(u[a, 0] - u[b, 0]) for pair in pairs.values() if len(pair) == 2 for a, b in [pair]]
    assert gaps and max(gaps) > 0.005


@pytest.mark.parametrize("segment, message", [
    (np.zeros((3, 3)), "segment must have shape"), (np.zeros(6), "segment must have shape"),
    ([[0.5, 0.5, -1], [0.5, float("nan"), 1]], "non-finite"), ([[0.5, 0.5, 0], [0.5, 0.5, 0]], "coincide")])
def test_bad_segments_are_refused_before_anything_changes(segment, message):
    mesh = flat_square(3)
    cutter = snede.SurfaceCutter(mesh)
    cutter.move([[-0.1, 0.5, -1], [-0.1, 0.5, 1]])
    cells = mesh.cells.copy()
    with pytest.raises(ValueError, match=message):
        cutter.move(segment)
    cutter.move([[0.3, 0.5, -1], [0.3, 0.5, 1]])  # the refused move did not count as a position
    np.testing.assert_array_equal(mesh.cells[: len(cells)] if mesh.n_cells >= len(cells) else cells, mesh.cells[: len(cells)])


@pytest.mark.parametrize("segments, message", [
    (np.zeros((1, 2, 3)), "segments must be"), (np.zeros((4, 3, 3)), "segments must be"),
    (np.full((3, 2, 3), np.inf), "non-finite"), (np.zeros((3, 2, 3)), "coinciding")])
def test_bad_paths_are_refused_before_anything_changes(segments, message):
    mesh = flat_square(3)
    cells = mesh.cells.copy()
    with pytest.raises(ValueError, match=message):
        snede.SurfaceCutter(mesh).cut(segments)
    np.testing.assert_array_equal(mesh.cells, cells)


@pytest.mark.parametrize("options, message", [({"eps_edge": float("inf")}, "eps_edge"), ({"eps_entry": -1}, "eps_entry"),
                                              ({"eps_exit": float("nan")}, "eps_exit")])
def test_bad_thresholds_are_refused(options, message):
    with pytest.raises(ValueError, match=message):
        snede.SurfaceCutter(flat_square(3), **options)


def test_planar_and_volume_meshes_are_refused():
    with pytest.raises(ValueError, match="surface mesh"):
        snede.SurfaceCutter(snede.meshing.rectangle((1, 1), (3, 3)))
    with pytest.raises(TypeError, match="Body or snede.Mesh"):
        snede.SurfaceCutter("mesh")
