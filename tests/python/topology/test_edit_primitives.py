"""The local mesh edits seen from Python with a Body on the mesh: each primitive keeps an
affine displacement field exact (new and moved vertices get it by their parents), keeps the
elastic energy of that field (constant strain over an unchanged domain), leaves a mesh on which
a static solve converges, and a refusal changes nothing — cells, points, revision."""
import numpy as np
import pytest

import snede

A2 = np.array([[0.010, -0.004], [0.003, 0.007]])
A3 = np.array([[0.010, 0.002, 0.0], [0.0, -0.004, 0.003], [0.001, 0.0, 0.005]])


def affine(points):
    A = A2 if points.shape[1] == 2 else A3
    return points @ A.T + 0.01


def body_on(mesh):
    body = snede.Body(mesh, snede.LinearElastic(E=1e4, nu=0.3), thickness=0.01 if mesh.dim == 2 else None)
    body.displacement = affine(mesh.points)
    return body


def sheet(n=6):
    mesh = snede.meshing.rectangle((1.0, 1.0), (n, n))
    return mesh, body_on(mesh)


def edges_of(mesh):
    """{sorted edge: number of cells around it}."""
    count = {}
    k = mesh.cells.shape[1]
    for cell in mesh.cells:
        for i in range(k):
            for j in range(i + 1, k):
                edge = tuple(sorted((int(cell[i]), int(cell[j]))))
                count[edge] = count.get(edge, 0) + 1
    return count


def boundary_vertices(mesh):
    return set(np.unique(mesh.boundary_faces()).tolist())


def interior_edge(mesh):
    """An edge with both ends inside the domain."""
    boundary = boundary_vertices(mesh)
    return next(e for e in sorted(edges_of(mesh)) if e[0] not in boundary and e[1] not in boundary)


def interior_vertex(mesh):
    boundary = boundary_vertices(mesh)
    return next(v for v in range(mesh.n_points) if mesh.live_vertices[v] and v not in boundary)


def assert_carried_exactly(mesh, body, energy):
    mesh.validate()
    live = mesh.live_vertices
    np.testing.assert_allclose(body.displacement[live], affine(mesh.points)[live], rtol=0, atol=1e-15)
    np.testing.assert_allclose(body.energy(body.displacement), energy, rtol=1e-12)


def assert_solve_converges(mesh, body):
    """Clamp x = 0, pull x = max: a static CG solve must converge on the edited mesh."""
    x = mesh.points[:, 0]
    live = mesh.live_vertices
    body.displacement = np.zeros((mesh.n_points, mesh.dim))
    body.fix(np.isclose(x, 0.0) & live)
    body.add_nodal_force(np.flatnonzero(np.isclose(x, x[live].max()) & live), (1.0,) + (0.0,) * (mesh.dim - 1))
    result = snede.StaticSolver(body, "cg", rtol=1e-8).solve()
    assert result.converged, result
    assert np.all(np.isfinite(body.displacement))


def edits_2d(mesh):
    """name → an edit of a 6 × 6 sheet that must succeed, with the cell-count change."""
    a, b = interior_edge(mesh)
    v = interior_vertex(mesh)
    neighbour = next(w for e in edges_of(mesh) if v in e for w in e if w != v)
    return {
        "flip_edge": (lambda: mesh.flip_edge(a, b), 0),
        "split_edge": (lambda: mesh.split_edge(a, b, 0.3), +2),
        "insert_vertex": (lambda: mesh.insert_vertex(mesh.cell_ids[5], [0.2, 0.3, 0.5]), +2),
        "collapse_edge": (lambda: mesh.collapse_edge(a, b, 0.5), -2),
        "remove_vertex_by_flips": (lambda: mesh.remove_vertex_by_flips(v), -2),
        "snap_vertex": (lambda: mesh.snap_vertex(v, [v, neighbour], [0.7, 0.3]), 0),
    }


@pytest.mark.parametrize("name", ["flip_edge", "split_edge", "insert_vertex", "collapse_edge",
                                  "remove_vertex_by_flips", "snap_vertex"])
def test_each_edit_carries_an_affine_field_keeps_its_energy_and_a_solve_converges(name):
    mesh, body = sheet()
    energy = body.energy(body.displacement)
    n_cells = mesh.n_cells
    edit, cell_change = edits_2d(mesh)[name]
    result = edit()
    assert result and result.done and result.reason == "", result
    assert mesh.n_cells == n_cells + cell_change
    assert body.displacement.shape == (mesh.n_points, 2)
    assert_carried_exactly(mesh, body, energy)
    assert_solve_converges(mesh, body)


def test_split_and_insert_report_the_new_vertex_where_its_parents_put_it():
    mesh, body = sheet()
    a, b = interior_edge(mesh)
    x_a, x_b = mesh.points[a], mesh.points[b]
    split = mesh.split_edge(a, b, 0.25)
    np.testing.assert_array_equal(mesh.points[split.vertex], 0.75 * x_a + 0.25 * x_b)
    element = mesh.cell_ids[3]
    corners = mesh.element_vertices(element)
    np.testing.assert_array_equal(corners, mesh.cells[3])
    inserted = mesh.insert_vertex(element, [0.5, 0.25, 0.25])
    np.testing.assert_allclose(mesh.points[inserted.vertex], mesh.points[corners].T @ [0.5, 0.25, 0.25], rtol=1e-15)
    assert "vertex=" in repr(inserted)


def test_flip_makes_a_non_delaunay_edge_delaunay():
    # The long edge (0, 1) of two flat triangles: the far corner lies in the other's circumcircle.
    mesh = snede.Mesh([[0, 0], [2, 0], [1, 0.3], [1, -0.3]], [[0, 1, 2], [1, 0, 3]])
    assert not mesh.is_locally_delaunay(0, 1)
    assert mesh.flip_edge(0, 1)
    assert sorted(edges_of(mesh)) == [(0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    assert mesh.is_locally_delaunay(2, 3)
    np.testing.assert_allclose(mesh.quality().volume.sum(), 0.6, rtol=1e-15)
    assert mesh.flip_edge(2, 3)  # and back
    assert not mesh.is_locally_delaunay(0, 1)


def snapshot(mesh):
    return mesh.cells.copy(), mesh.points.copy(), mesh.n_points, mesh._impl.revision


def assert_unchanged(mesh, before):
    cells, points, n_points, revision = before
    np.testing.assert_array_equal(mesh.cells, cells)
    np.testing.assert_array_equal(mesh.points, points)
    assert mesh.n_points == n_points and mesh._impl.revision == revision


def test_refusals_say_why_and_change_nothing():
    mesh, body = sheet()
    u = body.displacement.copy()
    boundary = sorted(boundary_vertices(mesh))
    corner = int(np.flatnonzero(np.all(mesh.points == 0.0, axis=1))[0])
    v = interior_vertex(mesh)
    far = max(range(mesh.n_points), key=lambda w: np.linalg.norm(mesh.points[w] - mesh.points[v]))
    # An interior edge joining two boundary vertices: collapsing it would pinch the sheet.
    chord = next(e for e, n in edges_of(mesh).items() if n == 2 and e[0] in boundary and e[1] in boundary)
    a, b = interior_edge(mesh)
    refusals = {
        "boundary": lambda: mesh.flip_edge(0, 1),
        "not an edge": lambda: mesh.split_edge(0, mesh.n_points - 1, 0.5),
        "t": lambda: mesh.split_edge(a, b, 1.0),
        "edge": lambda: mesh.insert_vertex(mesh.cell_ids[0], [0.5, 0.5, 0.0]),
        "link": lambda: mesh.collapse_edge(*chord),
        "corner": lambda: mesh.remove_vertex_by_flips(corner),
        "flat|inverted": lambda: mesh.snap_vertex(v, [far], [1.0]),
    }
    for expected, edit in refusals.items():
        before = snapshot(mesh)
        result = edit()
        assert not result and not result.done, (expected, result)
        assert result.reason and result.vertex is None
        assert "refused" in repr(result)
        assert_unchanged(mesh, before)
    np.testing.assert_array_equal(body.displacement, u)
    mesh.validate()


def test_bad_arguments_raise_value_errors_naming_the_argument():
    mesh, _ = sheet(2)
    with pytest.raises(ValueError, match="a 99 does not exist"):
        mesh.flip_edge(99, 0)
    with pytest.raises(ValueError, match="b must be an integer"):
        mesh.split_edge(0, 1.5)
    with pytest.raises(ValueError, match="t must be finite"):
        mesh.split_edge(0, 4, float("nan"))
    with pytest.raises(ValueError, match="weights must have shape"):
        mesh.insert_vertex(0, [0.5, 0.5])
    with pytest.raises(ValueError, match="element 1000 .*(not|dead)"):
        mesh.insert_vertex(1000, [0.2, 0.3, 0.5])
    with pytest.raises(ValueError, match="element must be an integer"):
        mesh.insert_vertex(0.0, [0.2, 0.3, 0.5])
    with pytest.raises(ValueError, match="sum to|barycentric"):
        mesh.insert_vertex(0, [0.5, 0.5, 0.5])
    with pytest.raises(ValueError, match="sum to"):
        mesh.snap_vertex(4, [4, 1], [0.5, 0.6])
    with pytest.raises(ValueError, match="tetrahedral|triangle"):
        snede.meshing.box((1, 1, 1), (1, 1, 1)).flip_edge(0, 7)


def test_tetrahedral_split_insert_collapse_and_snap_keep_volume_and_the_field():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (3, 3, 3))
    body = body_on(mesh)
    energy = body.energy(body.displacement)
    a, b = interior_edge(mesh)
    ring = edges_of(mesh)[(a, b)]
    n = mesh.n_cells
    assert mesh.split_edge(a, b, 0.5)
    assert mesh.n_cells == n + ring
    assert mesh.insert_vertex(mesh.cell_ids[0], [0.1, 0.2, 0.3, 0.4])  # inside a cell: one tet → 4
    assert mesh.insert_vertex(mesh.cell_ids[7], [0.0, 0.3, 0.3, 0.4])  # on a face: its two tets → 3 each
    assert mesh.n_cells == n + ring + 3 + 4
    assert_carried_exactly(mesh, body, energy)
    v = interior_vertex(mesh)
    neighbour = next(w for e in edges_of(mesh) if v in e for w in e if w != v and w not in boundary_vertices(mesh))
    assert mesh.collapse_edge(v, neighbour, 0.5), "an interior edge between interior vertices collapses"
    assert not mesh.live_vertices[neighbour]
    assert_carried_exactly(mesh, body, energy)
    np.testing.assert_allclose(mesh.quality().volume.sum(), 1.0, rtol=1e-13)
    assert_solve_converges(mesh, body)


def test_surface_edits_fold_nothing_and_keep_the_area_of_a_cube():
    box = snede.meshing.box((1.0, 1.0, 1.0), (3, 3, 3))
    surface, _ = snede.meshing.boundary_surface(box)
    x = surface.points
    area = surface.quality().volume.sum()
    np.testing.assert_allclose(area, 6.0, rtol=1e-14)
    edges = edges_of(surface)
    assert set(edges.values()) == {2}  # closed
    # An edge along the cube's edge x = y = 0: flipping it would fold two faces onto each other.
    along = next(e for e in edges if np.all(x[list(e), :2] == 0.0))
    before = snapshot(surface)
    assert not surface.flip_edge(*along)
    assert_unchanged(surface, before)
    # A diagonal inside the face z = 0 flips; an edge there splits; a cell takes a vertex.
    in_face = next(e for e in edges if np.all(x[list(e), 2] == 0.0) and np.all(x[e[0], :2] != x[e[1], :2]))
    assert surface.flip_edge(*in_face)
    assert in_face not in edges_of(surface)
    n = surface.n_cells
    assert surface.split_edge(*next(e for e in edges_of(surface) if np.all(x[list(e), 2] == 0.0)), 0.5)
    assert surface.n_cells == n + 2
    assert surface.insert_vertex(surface.cell_ids[0], [0.2, 0.3, 0.5])
    # The vertex (1/3, 1/3, 0) has a planar star: removing it keeps the area. Removing the
    # cube corner (0, 0, 0) is allowed too (its link can be triangulated without folding) but
    # cuts the corner off: the area shrinks.
    centre = int(np.flatnonzero(np.all(np.isclose(x, [1 / 3, 1 / 3, 0.0]), axis=1))[0])
    corner = int(np.flatnonzero(np.all(x == 0.0, axis=1))[0])
    n = surface.n_cells
    assert surface.remove_vertex_by_flips(centre)
    assert surface.n_cells == n - 2 and not surface.live_vertices[centre]
    surface.validate()
    np.testing.assert_allclose(surface.quality().volume.sum(), area, rtol=1e-13)
    assert surface.remove_vertex_by_flips(corner)
    surface.validate()
    assert surface.quality().volume.sum() < area - 1e-3


def test_a_batch_of_edits_is_one_change_for_the_body():
    mesh, body = sheet(8)
    energy = body.energy(body.displacement)
    generation = body._model.generation
    with mesh.batch():
        for element in mesh.cell_ids[::7].tolist():
            assert mesh.insert_vertex(element, [0.2, 0.3, 0.5])
        a, b = interior_edge(mesh)
        assert mesh.split_edge(a, b)
        assert mesh.remove_vertex_by_flips(interior_vertex(mesh))
    assert body._model.generation == generation + 1
    assert_carried_exactly(mesh, body, energy)
    assert_solve_converges(mesh, body)
