"""Cutters watch the mesh (issue 32 item 5, §7.4): edits made by others between the cutter's
moves (collapses, splits, flips, bisection, vertex removals, dissections) keep the cutter's
state right, or its next move raises IncisionLost naming what changed.

Also the tetrahedral cutter's incision across refinement. The surface cutter's active node on
coarse closed surfaces (issue 32 item 4) is in test_surface_creases.py.

The references are independent of the cutters' books: the lips and cut faces are found from
the cells alone (boundary edges or faces off the square's or the box's sides), the path from
the scalpel's own positions, whether a node advanced from its coordinates."""
import numpy as np
import pytest

import snede
from snede.planar_cutting import IncisionLost, sample_path

from surface_checks import flat_square, vertical_scalpels


def on_rim(x) -> np.ndarray:
    """Which points lie on a side of the unit square (x, y coordinates)."""
    return np.isclose(x[:, 0], 0) | np.isclose(x[:, 0], 1) | np.isclose(x[:, 1], 0) | np.isclose(x[:, 1], 1)


def lips(mesh) -> set:
    """The edges with one triangle that are not a piece of the square's rim, as sorted pairs:
    the incisions' lips, from the cells alone."""
    count = {}
    for t in mesh.cells:
        for k in range(3):
            edge = tuple(sorted((int(t[k]), int(t[(k + 1) % 3]))))
            count[edge] = count.get(edge, 0) + 1
    rim = on_rim(mesh.points)
    x = mesh.points[:, :2]
    along_a_side = lambda a, b: rim[a] and rim[b] and (np.isclose(x[a], x[b]).any())
    return {e for e, n in count.items() if n == 1 and not along_a_side(*e)}


def pairs(edges) -> set:
    return {tuple(sorted(map(int, e))) for e in edges}


def check_tip(mesh, node, incision_edges):
    """An active node is a live vertex; one with a lip (an incision's tip, not an entry node
    still waiting) has exactly two boundary edges, both lips of the cut."""
    assert (mesh.cells == node).any(), node
    own = {e for e in pairs(mesh.boundary_faces()) if node in e}
    if own & incision_edges:
        assert len(own) == 2 and own <= incision_edges, (node, own)


def check_cutter(mesh, cutter):
    """Valid mesh; the cutter's incision edges are exactly the lips; its active nodes are tips."""
    mesh.validate()
    edges = pairs(cutter.incision_edges())
    assert edges == lips(mesh)
    for node in getattr(cutter, "active_nodes", [cutter.active_node]):
        if node is not None:
            check_tip(mesh, node, edges)


def cut_down(mesh, cutter, x=0.43, start=1.2, stop=0.5):
    for p in sample_path([[x, start], [x, stop]], cutter.eps_edge):
        cutter.move(p)


def interior_neighbour_merging(mesh, node) -> int:
    """Collapses `node` into an interior neighbour (which stays where it is) and returns it."""
    rim_or_lip = set(np.unique(mesh.boundary_faces()))
    neighbours = sorted(set(mesh.cells[np.any(mesh.cells == node, axis=1)].ravel()) - {node} - rim_or_lip)
    for w in neighbours:
        if mesh.collapse_edge(w, node):
            return w
    pytest.fail(f"no interior neighbour of {node} could take it")


def test_a_collapsed_active_node_whose_id_is_reused_hands_the_tip_to_the_vertex_it_merged_into():
    mesh = snede.meshing.rectangle((1, 1), (8, 8))
    cutter = snede.DelaunayCutter(mesh)
    cut_down(mesh, cutter)
    tip = cutter.active_node
    heir = interior_neighbour_merging(mesh, tip)
    assert cutter.active_node == heir
    check_cutter(mesh, cutter)
    # A split far from the cut takes the freed id: the cut must not go on from there.
    corner = mesh.cells[np.argmin(mesh.points[mesh.cells].mean(axis=1).sum(axis=1))]
    reused = mesh.split_edge(corner[0], corner[1]).vertex
    assert reused == tip
    at = mesh.points[reused].copy()
    assert cutter.active_node == heir
    for p in sample_path([[0.43, 0.5], [0.43, 0.25]], cutter.eps_edge):
        report = cutter.move(p)
        check_cutter(mesh, cutter)
        if report.stuck == 0:
            np.testing.assert_allclose(mesh.points[cutter.active_node], p, atol=1e-12)
    assert cutter.active_node == heir
    np.testing.assert_array_equal(mesh.points[reused], at)
    y = mesh.points[np.unique(list(lips(mesh)))][:, 1]
    assert y.min() == pytest.approx(0.25) and y.max() == pytest.approx(1.0)


def test_an_active_node_a_dissection_leaves_no_tip_makes_the_next_move_raise_naming_it():
    mesh = snede.meshing.rectangle((1, 1), (8, 8))
    cutter = snede.DelaunayCutter(mesh)
    cut_down(mesh, cutter)
    tip = cutter.active_node
    boundary = set(np.unique(mesh.boundary_faces()))
    ahead = next(v for v in mesh.cells[np.any(mesh.cells == tip, axis=1)].ravel() if v not in boundary)
    mesh.dissect([[tip, ahead]])
    points, cells = mesh.points.copy(), mesh.cells.copy()
    with pytest.raises(IncisionLost, match=rf"active node {tip}\b.*dissect"):
        cutter.move([0.43, 0.45])
    assert isinstance(IncisionLost("x"), RuntimeError)
    assert snede.IncisionLost is IncisionLost  # catchable as snede.IncisionLost too
    np.testing.assert_array_equal(mesh.points, points)
    np.testing.assert_array_equal(mesh.cells, cells)
    assert cutter.active_node is None
    cutter.move([0.43, 0.4])  # lifted: this move only places the scalpel
    mesh.validate()


@pytest.mark.parametrize("by", ["mesh", "body"])
def test_refinement_mid_cut_keeps_every_lip_edge_in_the_incision(by):
    mesh = snede.meshing.rectangle((1, 1), (8, 8))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3), thickness=0.01) if by == "body" else None
    cutter = snede.DelaunayCutter(body if body else mesh)
    cut_down(mesh, cutter)
    before = len(lips(mesh))
    (body or mesh).refine_around([0.43, 0.7], 0.04)
    assert len(lips(mesh)) > before
    check_cutter(mesh, cutter)
    cut_down(mesh, cutter, start=0.5, stop=0.3)
    check_cutter(mesh, cutter)
    # The incision is the cut path: every lip edge on the line x = 0.43 from the top down to
    # the scalpel, both lips together twice its length.
    ends = mesh.points[np.array(sorted(pairs(cutter.incision_edges())))]
    np.testing.assert_allclose(ends[:, :, 0], 0.43, atol=1e-9)
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1).sum()
    assert length == pytest.approx(2 * (1.0 - 0.3), rel=1e-9)


def random_outside_edit(mesh, rng, near):
    """One of the edits another part of a simulation might make between two moves, near the
    cut: a collapse (of an interior vertex, or of a lip vertex into an interior one), a split,
    a flip, a bisection around a point (not on a surface, where refine_around has no point
    location), the removal of an interior vertex."""
    boundary = set(np.unique(mesh.boundary_faces()))
    rim = on_rim(mesh.points)
    centroids = mesh.points[mesh.cells].mean(axis=1)[:, :2]
    close = np.flatnonzero(np.linalg.norm(centroids - near, axis=1) < 0.25)
    cell = mesh.cells[rng.choice(close) if close.size else rng.integers(mesh.n_cells)]
    a, b = (int(v) for v in rng.choice(cell, 2, replace=False))
    kind = rng.choice(["collapse", "split", "flip", "refine", "remove"])
    if kind == "collapse":
        if rim[b] or (b not in boundary and a in boundary):
            a, b = b, a
        if not rim[b]:  # the square keeps its shape; lips and interior vertices may go
            mesh.collapse_edge(a, b)
    elif kind == "split":
        mesh.split_edge(a, b, rng.uniform(0.2, 0.8))
    elif kind == "flip":
        mesh.flip_edge(a, b)
    elif kind == "refine" and not mesh.is_surface:
        mesh.refine_around(np.clip(near + rng.uniform(-0.05, 0.05, 2), 0.02, 0.98), 0.06)
    elif kind == "remove" and a not in boundary:
        mesh.remove_vertex_by_flips(a)
    return kind


def zigzag(rng, step):
    """A path across the unit square through three random points, sampled every `step`."""
    corners = np.r_[[[-0.2, rng.uniform(0.3, 0.7)]], rng.uniform(0.15, 0.85, (3, 2)), [[1.2, rng.uniform(0.3, 0.7)]]]
    return sample_path(corners, step)


def move_checked(mesh, cutter, scalpel):
    """One move, then the checks; a lost incision is allowed if the error names its node."""
    try:
        cutter.move(scalpel)
    except IncisionLost as lost:
        assert "active node" in str(lost)
    check_cutter(mesh, cutter)


@pytest.mark.parametrize("seed", range(6))
def test_random_outside_edits_between_moves_on_a_square(seed):
    rng = np.random.default_rng(seed)
    mesh = snede.meshing.rectangle((1, 1), (8, 8))
    cutter = snede.DelaunayCutter(mesh)
    for point in zigzag(rng, cutter.eps_edge):
        if cutter.active_node is not None:
            random_outside_edit(mesh, rng, point)
            check_cutter(mesh, cutter)
        move_checked(mesh, cutter, point)


@pytest.mark.parametrize("seed", range(6))
def test_random_outside_edits_between_moves_on_a_surface(seed):
    rng = np.random.default_rng(seed)
    mesh = flat_square()
    cutter = snede.SurfaceCutter(mesh)
    for scalpel in vertical_scalpels(zigzag(rng, cutter.eps_edge)):
        if cutter.active_nodes:
            random_outside_edit(mesh, rng, scalpel[0, :2])
            check_cutter(mesh, cutter)
        move_checked(mesh, cutter, scalpel)


def cut_faces(mesh) -> set:
    """The boundary faces of a unit box's tetrahedral mesh that are not on its sides, from the
    cells alone: the incision's faces (both lips)."""
    faces = mesh.boundary_faces()
    x = mesh.points[faces]
    on_a_side = np.any(np.all(np.isclose(x, 0) | np.isclose(x, 1), axis=1) & np.all(np.isclose(x, x[:, :1]), axis=1), axis=1)
    return pairs(faces[~on_a_side])


def test_refinement_mid_cut_keeps_every_face_of_a_tetrahedral_incision():
    mesh = snede.meshing.box((1, 1, 1), (6, 6, 6))
    cutter = snede.TetrahedralCutter(mesh)
    for y in (-0.5, 0.2, 0.6):  # into the face y = 0, stopping inside on the plane x = 0.43
        cutter.move([[0.43, y, -1.0], [0.43, y, 2.0]])
    assert pairs(cutter.incision_faces()) == cut_faces(mesh)
    before = len(cut_faces(mesh))
    mesh.refine_around([0.43, 0.3, 0.5], 0.08)
    mesh.validate()
    assert len(cut_faces(mesh)) > before
    assert pairs(cutter.incision_faces()) == cut_faces(mesh)
    cutter.move([[0.43, 0.8, -1.0], [0.43, 0.8, 2.0]])
    mesh.validate()
    assert pairs(cutter.incision_faces()) == cut_faces(mesh)
