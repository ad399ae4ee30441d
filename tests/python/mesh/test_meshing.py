"""Generators (box, rectangle, cylinder), quality measures, star, connected components and
dissect, checked against facts computed here independently of the engine."""
import itertools
import math

import numpy as np
import pytest

import snede
from snede import meshing


# -- independent geometry -------------------------------------------------------------------
def signed_volumes(points, cells):
    corners = np.asarray(points, dtype=float)[np.asarray(cells)]
    edges = corners[:, 1:, :] - corners[:, :1, :]
    return np.linalg.det(edges) / (2.0 if corners.shape[2] == 2 else 6.0)


def face_normals(points, faces):
    """3D: area vector ½ (b − a) × (c − a) of each face, from its vertex order."""
    a, b, c = (points[faces[:, k]] for k in range(3))
    return 0.5 * np.cross(b - a, c - a)


def enclosed_volume(mesh):
    """Divergence theorem over the boundary faces: V = (1/d) Σ centroid · (area normal).
    Equals the mesh volume only if every boundary face is oriented outward."""
    points, faces = mesh.points, mesh.boundary_faces()
    if mesh.dim == 3:
        return float(np.sum(points[faces].mean(axis=1) * face_normals(points, faces)) / 3.0)
    a, b = points[faces[:, 0]], points[faces[:, 1]]
    return float(0.5 * np.sum(a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1]))  # shoelace


def boundary_measure(mesh):
    points, faces = mesh.points, mesh.boundary_faces()
    if mesh.dim == 3:
        return float(np.linalg.norm(face_normals(points, faces), axis=1).sum())
    return float(np.linalg.norm(points[faces[:, 1]] - points[faces[:, 0]], axis=1).sum())


def interior_angles_tet(x):
    """The six dihedral angles of tetrahedron x (4×3), from outward face normals:
    angle at edge (i, j) = π − angle between the normals of the faces opposite k and l."""
    normals = []
    for m in range(4):
        a, b, c = (x[i] for i in range(4) if i != m)
        n = np.cross(b - a, c - a)
        if np.dot(n, x[m] - a) > 0:
            n = -n
        normals.append(n / np.linalg.norm(n))
    angles = []
    for i, j in itertools.combinations(range(4), 2):
        k, l = (m for m in range(4) if m not in (i, j))
        angles.append(math.pi - math.acos(np.clip(np.dot(normals[k], normals[l]), -1, 1)))
    return sorted(angles)


def interior_angles_triangle(x):
    angles = []
    for i in range(3):
        u, w = x[(i + 1) % 3] - x[i], x[(i + 2) % 3] - x[i]
        angles.append(math.acos(np.dot(u, w) / np.linalg.norm(u) / np.linalg.norm(w)))
    return sorted(angles)


def rows_containing(cells, v):
    return np.flatnonzero(np.any(cells == v, axis=1))


def vertex_index(points, coordinate):
    (index,) = np.flatnonzero(np.all(np.isclose(points, coordinate), axis=1))
    return int(index)


# -- box ------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def unit_box_10():
    return meshing.box((1.0, 1.0, 1.0), (10, 10, 10))


def test_box_counts_volume_and_validity(unit_box_10):
    mesh = unit_box_10
    assert mesh.n_cells == 6000 and mesh.n_points == 1331 and mesh.dim == 3
    assert mesh.n_reoriented == 0  # the generator orients its cells itself
    volumes = signed_volumes(mesh.points, mesh.cells)
    assert np.all(volumes > 0)
    np.testing.assert_allclose(volumes, 1e-3 / 6, rtol=1e-10)  # every Kuhn tet is 1/6 of a cube
    assert abs(volumes.sum() - 1.0) < 1e-12
    assert abs(mesh.quality().volume.sum() - 1.0) < 1e-12
    mesh.validate()
    assert mesh.connected_components()[0] == 1


def test_box_points_are_the_grid():
    mesh = meshing.box((2.0, 3.0, 1.5), (2, 3, 1))
    assert mesh.n_points == 3 * 4 * 2 and mesh.n_cells == 6 * 6
    expected = {(x, y, z) for x in (0, 1, 2) for y in (0, 1, 2, 3) for z in (0, 1.5)}
    assert {tuple(p) for p in mesh.points.round(12)} == expected
    assert abs(signed_volumes(mesh.points, mesh.cells).sum() - 9.0) < 1e-12


@pytest.mark.parametrize("n", [1, 2, 3, 10])
def test_box_boundary_faces(n):
    mesh = meshing.box((1.0, 1.0, 1.0), (n, n, n))
    faces = mesh.boundary_faces()
    assert faces.shape == (2 * 6 * n * n, 3)  # each boundary square split in two
    points = mesh.points
    normals = face_normals(points, faces)
    areas = np.linalg.norm(normals, axis=1)
    np.testing.assert_allclose(areas, 0.5 / n**2, rtol=1e-12)
    assert abs(areas.sum() - 6.0) < 1e-12
    # Every boundary face lies on a side of the cube, its normal along that side's axis and
    # pointing away from the centre.
    centroids = points[faces].mean(axis=1)
    assert np.all(np.sum(normals * (centroids - 0.5), axis=1) > 0)
    unit = normals / areas[:, None]
    axis = np.argmax(np.abs(unit), axis=1)
    np.testing.assert_allclose(np.abs(unit[np.arange(len(unit)), axis]), 1.0, atol=1e-12)
    on_side = points[faces][np.arange(len(faces)), :, axis]  # (n_faces, 3) coordinate along the axis
    side = np.where(unit[np.arange(len(unit)), axis] > 0, 1.0, 0.0)
    np.testing.assert_allclose(on_side, np.repeat(side[:, None], 3, axis=1), atol=1e-12)
    assert abs(enclosed_volume(mesh) - 1.0) < 1e-12
    assert len({tuple(sorted(f)) for f in faces}) == len(faces)  # no face listed twice


def test_box_boundary_faces_are_faces_of_cells():
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    cell_faces = {}
    for row, cell in enumerate(mesh.cells):
        for k in range(4):
            cell_faces.setdefault(frozenset(np.delete(cell, k)), []).append(row)
    boundary = {key for key, rows in cell_faces.items() if len(rows) == 1}
    assert {frozenset(f) for f in mesh.boundary_faces()} == boundary
    assert all(len(rows) <= 2 for rows in cell_faces.values())


def test_box_rejects_bad_arguments():
    with pytest.raises(ValueError, match="positive"):
        meshing.box((1.0, -1.0, 1.0), (2, 2, 2))
    with pytest.raises(ValueError, match="at least 1"):
        meshing.box((1.0, 1.0, 1.0), (2, 0, 2))
    with pytest.raises(ValueError, match="3 entries"):
        meshing.box((1.0, 1.0), (2, 2))


# -- rectangle ------------------------------------------------------------------------------
@pytest.mark.parametrize("size, divisions", [((1.0, 1.0), (1, 1)), ((2.0, 1.0), (2, 1)), ((3.0, 0.5), (7, 4))])
def test_rectangle(size, divisions):
    mesh = meshing.rectangle(size, divisions)
    nx, ny = divisions
    area = size[0] * size[1]
    assert mesh.dim == 2 and mesh.n_cells == 2 * nx * ny and mesh.n_points == (nx + 1) * (ny + 1)
    assert mesh.n_reoriented == 0
    volumes = signed_volumes(mesh.points, mesh.cells)
    assert np.all(volumes > 0)
    np.testing.assert_allclose(volumes, area / (2 * nx * ny), rtol=1e-12)
    assert mesh.quality().volume.sum() == pytest.approx(area, rel=1e-12)
    faces = mesh.boundary_faces()
    assert faces.shape == (2 * (nx + ny), 2)
    assert boundary_measure(mesh) == pytest.approx(2 * (size[0] + size[1]), rel=1e-12)
    # Counter-clockwise: the shoelace sum over the boundary edges is +area, and the outward
    # normal (dy, -dx) of every edge points away from the centre.
    assert enclosed_volume(mesh) == pytest.approx(area, rel=1e-12)
    points = mesh.points
    a, b = points[faces[:, 0]], points[faces[:, 1]]
    outward = np.column_stack([b[:, 1] - a[:, 1], a[:, 0] - b[:, 0]])
    assert np.all(np.sum(outward * ((a + b) / 2 - np.array(size) / 2), axis=1) > 0)
    # The boundary edges form one closed loop: each vertex starts one edge and ends one.
    assert sorted(faces[:, 0]) == sorted(faces[:, 1])
    mesh.validate()


# -- cylinder -------------------------------------------------------------------------------
def test_cylinder_geometry():
    length, radius = 0.1, 0.03
    mesh = meshing.cylinder(length, radius, 0.015, seed=1)
    mesh.validate()
    points = mesh.points
    assert points[:, 0].min() == pytest.approx(0.0, abs=1e-12)
    assert points[:, 0].max() == pytest.approx(length, abs=1e-12)
    assert np.all(np.hypot(points[:, 1], points[:, 2]) <= radius * (1 + 1e-9))
    # Inscribed polyhedron: a little less than the cylinder's volume and area.
    volume = math.pi * radius**2 * length
    total = mesh.quality().volume.sum()
    assert 0.9 * volume < total < volume
    assert enclosed_volume(mesh) == pytest.approx(total, rel=1e-10)
    area = 2 * math.pi * radius * length + 2 * math.pi * radius**2
    assert 0.9 * area < boundary_measure(mesh) < area
    assert mesh.connected_components()[0] == 1
    assert len(np.unique(mesh.cells)) == mesh.n_points  # no unused points


def test_cylinder_is_deterministic():
    a = meshing.cylinder(0.1, 0.03, 0.015, seed=3)
    b = meshing.cylinder(0.1, 0.03, 0.015, seed=3)
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.cells, b.cells)


def test_cylinder_rejects_bad_arguments():
    with pytest.raises(ValueError, match="h must be positive"):
        meshing.cylinder(0.1, 0.03, 0.0)
    with pytest.raises(ValueError, match="radius"):
        meshing.cylinder(0.1, float("nan"), 0.01)


# -- quality --------------------------------------------------------------------------------
def regular_tetrahedron(edge=1.0):
    x = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])
    return x * edge / (2 * math.sqrt(2))  # edge of the ±1 corners is 2√2


def test_regular_tetrahedron_quality():
    x = regular_tetrahedron(2.0) + [3.0, -1.0, 0.5]
    distances = [np.linalg.norm(x[i] - x[j]) for i, j in itertools.combinations(range(4), 2)]
    np.testing.assert_allclose(distances, 2.0, rtol=1e-14)  # really regular
    np.testing.assert_allclose(interior_angles_tet(x), math.acos(1 / 3), rtol=1e-12)
    q = snede.Mesh(x, [[0, 1, 2, 3]]).quality()
    assert q.volume[0] == pytest.approx(2.0**3 / (6 * math.sqrt(2)), rel=1e-13)
    assert q.aspect_ratio[0] == pytest.approx(math.sqrt(2 / 3), rel=1e-13)
    assert q.aspect_ratio[0] == pytest.approx(0.8165, abs=5e-5)
    assert q.min_dihedral[0] == pytest.approx(math.acos(1 / 3), rel=1e-13)
    assert q.max_dihedral[0] == pytest.approx(math.acos(1 / 3), rel=1e-13)


def test_equilateral_triangle_quality():
    x = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, math.sqrt(3) / 2]]) * 3.0
    q = snede.Mesh(x, [[0, 2, 1]]).quality()  # given clockwise
    assert q.volume[0] == pytest.approx(9 * math.sqrt(3) / 4, rel=1e-13)
    assert q.aspect_ratio[0] == pytest.approx(math.sqrt(3) / 2, rel=1e-13)
    assert q.min_dihedral[0] == pytest.approx(math.pi / 3, rel=1e-13)
    assert q.max_dihedral[0] == pytest.approx(math.pi / 3, rel=1e-13)


def test_right_kuhn_tetrahedron_quality():
    """Path tetrahedron 000 → 100 → 110 → 111 of the unit cube, by hand: volume 1/6; edges
    1, 1, 1, √2, √2, √3; faces opposite the corners have areas 1/2, √2/2, √2/2, 1/2, so the
    heights 3V/A are 1, 1/√2, 1/√2, 1 and the aspect ratio is (1/√2)/√3 = 1/√6. Dihedral
    angles: 60° at the main diagonal 000-111 (six tetrahedra around it); 45° at 000-100 and
    110-111 (two tetrahedra share the cube's right angle there); 90° at the other three."""
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]])
    np.testing.assert_allclose(
        interior_angles_tet(x), np.radians([45, 45, 60, 90, 90, 90]), rtol=1e-12
    )
    q = snede.Mesh(x, [[0, 1, 2, 3]]).quality()
    assert q.volume[0] == pytest.approx(1 / 6, rel=1e-14)
    assert q.aspect_ratio[0] == pytest.approx(1 / math.sqrt(6), rel=1e-13)
    assert q.min_dihedral[0] == pytest.approx(math.pi / 4, rel=1e-13)
    assert q.max_dihedral[0] == pytest.approx(math.pi / 2, rel=1e-13)


def test_right_triangle_quality():
    x = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]])
    q = snede.Mesh(x, [[0, 1, 2]]).quality()
    assert q.volume[0] == pytest.approx(2.0)
    # heights 2A/edge: 2, 2, √2; longest edge 2√2.
    assert q.aspect_ratio[0] == pytest.approx(0.5, rel=1e-14)
    assert q.min_dihedral[0] == pytest.approx(math.pi / 4, rel=1e-14)
    assert q.max_dihedral[0] == pytest.approx(math.pi / 2, rel=1e-14)


def test_quality_of_random_cells_matches_independent_computation():
    rng = np.random.default_rng(11)
    for dim in (2, 3):
        for _ in range(20):
            x = rng.normal(size=(dim + 1, dim))
            q = snede.Mesh(x, [list(range(dim + 1))]).quality()
            volume = abs(signed_volumes(x, [list(range(dim + 1))])[0])
            angles = interior_angles_tet(x) if dim == 3 else interior_angles_triangle(x)
            longest = max(np.linalg.norm(x[i] - x[j]) for i, j in itertools.combinations(range(dim + 1), 2))
            facets = []
            for m in range(dim + 1):
                rest = np.delete(x, m, axis=0)
                facets.append(
                    np.linalg.norm(rest[1] - rest[0])
                    if dim == 2
                    else 0.5 * np.linalg.norm(np.cross(rest[1] - rest[0], rest[2] - rest[0]))
                )
            assert q.volume[0] == pytest.approx(volume, rel=1e-10)
            assert q.aspect_ratio[0] == pytest.approx(dim * volume / max(facets) / longest, rel=1e-10)
            assert q.min_dihedral[0] == pytest.approx(angles[0], rel=1e-9, abs=1e-12)
            assert q.max_dihedral[0] == pytest.approx(angles[-1], rel=1e-9)
            if dim == 2:
                assert sum(angles) == pytest.approx(math.pi)


def test_box_quality_is_that_of_kuhn_tetrahedra(unit_box_10):
    q = unit_box_10.quality()
    np.testing.assert_allclose(q.aspect_ratio, 1 / math.sqrt(6), rtol=1e-10)
    np.testing.assert_allclose(q.min_dihedral, math.pi / 4, rtol=1e-10)
    np.testing.assert_allclose(q.max_dihedral, math.pi / 2, rtol=1e-10)


# -- star and components --------------------------------------------------------------------
@pytest.mark.parametrize("make", [lambda: meshing.rectangle((2.0, 1.0), (2, 1)), lambda: meshing.box((1, 1, 1), (2, 2, 2))])
def test_star_is_every_cell_containing_the_vertex(make):
    mesh = make()
    cells, ids = mesh.cells, mesh.cell_ids
    for v in range(mesh.n_points):
        expected = sorted(ids[rows_containing(cells, v)])
        assert sorted(mesh.star(v)) == expected, v
    # Sizes known by hand. In 3D, a corner at offset (a, b, c) of its cube lies on the Kuhn
    # paths that take its m = a + b + c unit steps first: m! (3 - m)! of the 6 tetrahedra.
    if mesh.dim == 2:
        corner_01 = vertex_index(mesh.points, (0.0, 1.0))  # one triangle
        middle_bottom = vertex_index(mesh.points, (1.0, 0.0))  # three triangles
        assert len(mesh.star(corner_01)) == 1 and len(mesh.star(middle_bottom)) == 3
    else:
        centre = vertex_index(mesh.points, (0.5, 0.5, 0.5))
        assert len(mesh.star(centre)) == 6 + 3 * 2 + 3 * 2 + 6  # 8 cubes, m = 0, 1 (×3), 2 (×3), 3
        assert len(mesh.star(vertex_index(mesh.points, (0.0, 0.0, 0.0)))) == 6  # m = 0
        assert len(mesh.star(vertex_index(mesh.points, (1.0, 1.0, 1.0)))) == 6  # m = 3
        assert len(mesh.star(vertex_index(mesh.points, (1.0, 0.0, 0.0)))) == 2  # m = 1
        assert len(mesh.star(vertex_index(mesh.points, (1.0, 1.0, 0.0)))) == 2  # m = 2
        assert len(mesh.star(vertex_index(mesh.points, (0.5, 0.0, 0.0)))) == 6 + 2  # two cubes


def test_connected_components_of_two_separate_boxes():
    a = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    b = meshing.box((1.0, 1.0, 1.0), (1, 2, 1))
    points = np.vstack([a.points, b.points + [3.0, 0.0, 0.0]])
    cells = np.vstack([b.cells + a.n_points, a.cells])  # interleave the order a bit
    mesh = snede.Mesh(points, cells)
    n, label = mesh.connected_components()
    assert n == 2 and label.shape == (mesh.n_cells,)
    far = mesh.points[mesh.cells].mean(axis=1)[:, 0] > 2.0
    assert len(set(label[far])) == 1 and len(set(label[~far])) == 1 and label[far][0] != label[~far][0]
    assert far.sum() == b.n_cells


def test_vertex_star_at_a_bowtie_vertex():
    """Two triangles that share only vertex 0. Mesh does not refuse this (it checks faces, not
    vertex links), so star(0) must still find both cells."""
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    try:
        mesh = snede.Mesh(points, [[0, 1, 2], [0, 3, 4]])
    except ValueError:
        return  # refusing a non-manifold vertex is fine as well
    assert sorted(mesh.star(0)) == sorted(mesh.cell_ids)


# -- dissect --------------------------------------------------------------------------------
def check_dissected(before, mesh, pairs, expected_new):
    """Common facts after a dissection: the mesh is valid, the copies are new vertices with
    the originals' coordinates, no cell changed shape, the total volume is unchanged, and
    the boundary still encloses it (all boundary faces oriented outward)."""
    mesh.validate()
    pairs = np.asarray(pairs).reshape(-1, 2)
    assert len(pairs) == expected_new
    assert mesh.n_points == before.n_points + expected_new
    np.testing.assert_array_equal(np.sort(pairs[:, 1]), np.arange(before.n_points, mesh.n_points))
    np.testing.assert_array_equal(mesh.points[pairs[:, 1]], mesh.points[pairs[:, 0]])
    np.testing.assert_array_equal(mesh.points[: before.n_points], before.points)
    assert mesh.n_cells == before.n_cells
    volumes = signed_volumes(mesh.points, mesh.cells)
    assert np.all(volumes > 0)
    np.testing.assert_allclose(np.sort(volumes), np.sort(signed_volumes(before.points, before.cells)), rtol=1e-12)
    assert enclosed_volume(mesh) == pytest.approx(volumes.sum(), rel=1e-12)
    # Each row still spans the same original vertices (a copy stands for its original).
    original_of = np.arange(mesh.n_points)
    original_of[pairs[:, 1]] = pairs[:, 0]
    as_sets = lambda c: sorted(map(tuple, np.sort(c, axis=1)))  # noqa: E731
    assert as_sets(original_of[mesh.cells]) == as_sets(before.cells)
    return pairs


def faces_on_plane(mesh, axis, value, where=None):
    """Interior faces of `mesh` all of whose vertices have coordinate `value` along `axis`
    (and satisfy `where(points)` if given)."""
    points, cells = mesh.points, mesh.cells
    on = np.isclose(points[:, axis], value)
    if where is not None:
        on &= where(points)
    faces = set()
    for cell in cells:
        for k in range(len(cell)):
            face = np.delete(cell, k)
            if np.all(on[face]):
                faces.add(tuple(sorted(face)))
    return np.array(sorted(faces))


def test_dissect_rectangle_through_the_middle():
    mesh = meshing.rectangle((2.0, 1.0), (2, 1))
    before = meshing.rectangle((2.0, 1.0), (2, 1))
    a, b = vertex_index(mesh.points, (1.0, 0.0)), vertex_index(mesh.points, (1.0, 1.0))
    pairs = check_dissected(before, mesh, mesh.dissect([[b, a]]), 2)
    assert sorted(pairs[:, 0]) == sorted([a, b])
    n, label = mesh.connected_components()
    assert n == 2
    left = mesh.points[mesh.cells].mean(axis=1)[:, 0] < 1.0
    assert set(label[left]) & set(label[~left]) == set()
    assert set(mesh.cells[left].ravel()) & set(mesh.cells[~left].ravel()) == set()
    assert len(mesh.boundary_faces()) == 6 + 2
    assert boundary_measure(mesh) == pytest.approx(6.0 + 2.0)


def test_dissect_rectangle_along_a_diagonal_cuts_off_a_triangle():
    """Diagonal (0,0)-(1,1) of the left square: both ends on the boundary, so both split, and
    the upper-left triangle is cut off."""
    mesh = meshing.rectangle((2.0, 1.0), (2, 1))
    before = meshing.rectangle((2.0, 1.0), (2, 1))
    a, b = vertex_index(mesh.points, (0.0, 0.0)), vertex_index(mesh.points, (1.0, 1.0))
    pairs = check_dissected(before, mesh, mesh.dissect([[a, b]]), 2)
    assert sorted(pairs[:, 0]) == sorted([a, b])
    n, label = mesh.connected_components()
    assert n == 2 and sorted(np.bincount(label)) == [1, 3]


def grid_vertex(mesh, i, j, n):
    return vertex_index(mesh.points, (i / n, j / n))


def test_dissect_interior_edge_between_interior_vertices_adds_no_vertex():
    """Figure 7.7: cutting a single edge whose ends are interior vertices leaves each star
    connected around the other side, so no vertex is split. Faces are paired by their
    vertices, so without a new vertex nothing changes: the mesh stays as it was."""
    mesh, before = meshing.rectangle((1.0, 1.0), (3, 3)), meshing.rectangle((1.0, 1.0), (3, 3))
    a, b = grid_vertex(mesh, 1, 1, 3), grid_vertex(mesh, 2, 2, 3)
    check_dissected(before, mesh, mesh.dissect([[a, b]]), 0)
    assert mesh.connected_components()[0] == 1
    np.testing.assert_array_equal(mesh.cells, before.cells)
    np.testing.assert_array_equal(mesh.boundary_faces(), before.boundary_faces())


def test_dissect_path_of_interior_edges_splits_only_its_inner_vertex():
    """Figure 7.7 with two edges 1/3(1,1) - 1/3(2,2) - 1/3(2,1), all three vertices interior:
    the two cut edges at the middle vertex split its star in two (it gets one copy); the end
    vertices keep a connected star. The cut opens a slit: 4 new boundary edges, one piece."""
    mesh, before = meshing.rectangle((1.0, 1.0), (3, 3)), meshing.rectangle((1.0, 1.0), (3, 3))
    a, b, c = grid_vertex(mesh, 1, 1, 3), grid_vertex(mesh, 2, 2, 3), grid_vertex(mesh, 2, 1, 3)
    pairs = check_dissected(before, mesh, mesh.dissect([[a, b], [b, c]]), 1)
    assert pairs[0, 0] == b
    assert mesh.connected_components()[0] == 1
    assert len(mesh.boundary_faces()) == 12 + 4
    assert boundary_measure(mesh) == pytest.approx(4 + 2 * (1 / 3 + math.sqrt(2) / 3))
    # b's star falls into the cells inside the 45° wedge a-b-c (the one triangle a, b, c) and
    # the five others; one group uses b, the other the copy (which one is not specified).
    (copy,) = pairs[:, 1]
    with_b = [set(cell) - {b} for cell in mesh.cells if b in cell]
    with_copy = [set(cell) - {copy} for cell in mesh.cells if copy in cell]
    assert len(rows_containing(before.cells, b)) == 6  # valence 6 in this grid
    assert sorted([len(with_b), len(with_copy)]) == [1, 5]
    wedge = with_b if len(with_b) == 1 else with_copy
    assert wedge == [{a, c}]


def test_dissect_closed_loop_of_interior_edges_cuts_out_a_piece():
    """The triangle 1/3(1,1), 1/3(2,1), 1/3(2,2) (one cell) cut out along its three edges:
    its three interior vertices each split once, and the cell becomes its own component."""
    mesh, before = meshing.rectangle((1.0, 1.0), (3, 3)), meshing.rectangle((1.0, 1.0), (3, 3))
    a, b, c = grid_vertex(mesh, 1, 1, 3), grid_vertex(mesh, 2, 1, 3), grid_vertex(mesh, 2, 2, 3)
    check_dissected(before, mesh, mesh.dissect([[a, b], [b, c], [c, a]]), 3)
    n, label = mesh.connected_components()
    assert n == 2 and sorted(np.bincount(label)) == [1, 17]
    assert len(mesh.boundary_faces()) == 12 + 3 + 3
    assert boundary_measure(mesh) == pytest.approx(4 + 2 * (2 / 3 + math.sqrt(2) / 3))


def test_dissect_edge_ending_on_the_boundary_splits_only_the_boundary_vertex():
    mesh, before = meshing.rectangle((1.0, 1.0), (3, 3)), meshing.rectangle((1.0, 1.0), (3, 3))
    boundary, interior = grid_vertex(mesh, 0, 1, 3), grid_vertex(mesh, 1, 1, 3)
    pairs = check_dissected(before, mesh, mesh.dissect([[boundary, interior]]), 1)
    assert pairs[0, 0] == boundary
    assert mesh.connected_components()[0] == 1
    assert len(mesh.boundary_faces()) == 12 + 2


def test_dissect_rectangle_along_a_full_line():
    """Cut the whole line y = 1/3 (three edges): its four vertices split, two pieces."""
    mesh, before = meshing.rectangle((1.0, 1.0), (3, 3)), meshing.rectangle((1.0, 1.0), (3, 3))
    line = [grid_vertex(mesh, i, 1, 3) for i in range(4)]
    pairs = check_dissected(before, mesh, mesh.dissect(list(zip(line[:-1], line[1:]))), 4)
    assert sorted(pairs[:, 0]) == sorted(line)
    n, label = mesh.connected_components()
    below = mesh.points[mesh.cells].mean(axis=1)[:, 1] < 1 / 3
    assert n == 2 and len(set(label[below])) == 1 and set(label[below]) != set(label[~below])
    assert sorted(np.bincount(label)) == [6, 12]


def test_dissect_box_along_a_full_plane():
    mesh, before = meshing.box((1, 1, 1), (2, 2, 2)), meshing.box((1, 1, 1), (2, 2, 2))
    faces = faces_on_plane(mesh, 0, 0.5)
    assert len(faces) == 8  # 4 squares of the plane, 2 triangles each
    on_plane = np.flatnonzero(np.isclose(mesh.points[:, 0], 0.5))
    assert len(on_plane) == 9
    # The cut goes all the way through, so each of the 9 vertices on the plane (8 on the
    # boundary, the centre inside) gets exactly one copy.
    pairs = check_dissected(before, mesh, mesh.dissect(faces), 9)
    assert sorted(pairs[:, 0]) == sorted(on_plane)
    n, label = mesh.connected_components()
    assert n == 2
    centroids_x = mesh.points[mesh.cells].mean(axis=1)[:, 0]
    left = centroids_x < 0.5
    assert len(set(label[left])) == 1 and len(set(label[~left])) == 1 and label[left][0] != label[~left][0]
    volumes = mesh.quality().volume
    assert volumes[left].sum() == pytest.approx(0.5) and volumes[~left].sum() == pytest.approx(0.5)
    assert set(mesh.cells[left].ravel()) & set(mesh.cells[~left].ravel()) == set()
    # New boundary: the 8 faces, once for each side.
    assert len(mesh.boundary_faces()) == 2 * 6 * 4 + 2 * 8
    assert boundary_measure(mesh) == pytest.approx(6.0 + 2.0)


def test_dissect_box_along_half_a_plane():
    """Cut the part z ≤ 1/2 of the plane x = 1/2 (4 faces). Hand count of which stars split:
    the three plane vertices on the bottom face z = 0 see the cut run from boundary to
    boundary and split; (½, 0, ½), (½, 1, ½) and the centre see it end inside and do not."""
    mesh, before = meshing.box((1, 1, 1), (2, 2, 2)), meshing.box((1, 1, 1), (2, 2, 2))
    faces = faces_on_plane(mesh, 0, 0.5, where=lambda p: p[:, 2] <= 0.5 + 1e-12)
    assert len(faces) == 4
    pairs = check_dissected(before, mesh, mesh.dissect(faces), 3)
    expected = sorted(vertex_index(before.points, (0.5, y, 0.0)) for y in (0.0, 0.5, 1.0))
    assert sorted(pairs[:, 0]) == expected
    assert mesh.connected_components()[0] == 1
    assert len(mesh.boundary_faces()) == 48 + 2 * 4
    assert boundary_measure(mesh) == pytest.approx(6.0 + 2 * 0.5)


def test_dissect_single_interior_face_adds_no_vertex_3d():
    mesh, before = meshing.box((1, 1, 1), (3, 3, 3)), meshing.box((1, 1, 1), (3, 3, 3))
    face = [vertex_index(mesh.points, p) for p in ((1 / 3, 1 / 3, 1 / 3), (2 / 3, 1 / 3, 1 / 3), (2 / 3, 2 / 3, 1 / 3))]
    check_dissected(before, mesh, mesh.dissect([face]), 0)
    assert mesh.connected_components()[0] == 1
    np.testing.assert_array_equal(mesh.cells, before.cells)
    assert len(mesh.boundary_faces()) == 2 * 6 * 9


def test_dissect_accepts_either_orientation_and_repeats():
    mesh, before = meshing.rectangle((2.0, 1.0), (2, 1)), meshing.rectangle((2.0, 1.0), (2, 1))
    a, b = vertex_index(mesh.points, (1.0, 0.0)), vertex_index(mesh.points, (1.0, 1.0))
    check_dissected(before, mesh, mesh.dissect([[a, b], [b, a]]), 2)
    assert mesh.connected_components()[0] == 2


def test_star_after_dissect():
    mesh = meshing.rectangle((2.0, 1.0), (2, 1))
    a, b = vertex_index(mesh.points, (1.0, 0.0)), vertex_index(mesh.points, (1.0, 1.0))
    mesh.dissect([[a, b]])
    cells, ids = mesh.cells, mesh.cell_ids
    for v in range(mesh.n_points):
        assert sorted(mesh.star(v)) == sorted(ids[rows_containing(cells, v)]), v


@pytest.mark.parametrize("dim", [2, 3])
def test_dissect_boundary_face_raises_and_changes_nothing(dim):
    mesh = meshing.box((1, 1, 1), (2, 2, 2)) if dim == 3 else meshing.rectangle((1, 1), (2, 2))
    cells, n_points = mesh.cells, mesh.n_points
    interior = faces_on_plane(mesh, 0, 0.5)[:1]
    for boundary in mesh.boundary_faces():
        for faces in ([boundary], [boundary[::-1]], np.vstack([interior, [boundary]])):
            with pytest.raises(ValueError):
                mesh.dissect(faces)
    assert mesh.n_points == n_points
    np.testing.assert_array_equal(mesh.cells, cells)
    mesh.validate()


@pytest.mark.parametrize("dim", [2, 3])
def test_dissect_boundary_face_message_says_boundary(dim):
    mesh = meshing.box((1, 1, 1), (2, 2, 2)) if dim == 3 else meshing.rectangle((1, 1), (2, 2))
    for boundary in mesh.boundary_faces():
        with pytest.raises(ValueError, match="lies on the boundary"):
            mesh.dissect([boundary])


def test_dissect_twice_the_same_face_raises_the_second_time():
    mesh = meshing.rectangle((2.0, 1.0), (2, 1))
    a, b = vertex_index(mesh.points, (1.0, 0.0)), vertex_index(mesh.points, (1.0, 1.0))
    mesh.dissect([[a, b]])
    with pytest.raises(ValueError, match="boundary"):
        mesh.dissect([[a, b]])


@pytest.mark.parametrize(
    "face, fragment",
    [([0, 5], "no face"), ([0, 99], r"faces\[0, 1\] = 99 is not a vertex"), ([-1, 2], r"faces\[0, 0\] = -1 is not a vertex")],
)
def test_dissect_missing_face_raises(face, fragment):
    mesh = meshing.rectangle((2.0, 1.0), (2, 1))  # vertices 0 (0,0) and 5 (2,1) share no edge
    with pytest.raises(ValueError, match=fragment):
        mesh.dissect([face])
    assert mesh.n_points == 6


def test_dissect_missing_face_3d():
    mesh = meshing.box((1, 1, 1), (2, 2, 2))
    corners = [vertex_index(mesh.points, p) for p in ((0, 0, 0), (1, 0, 0), (0, 1, 0))]
    with pytest.raises(ValueError, match="no face"):
        mesh.dissect([corners])


def test_dissect_rejects_badly_shaped_faces():
    mesh = meshing.box((1, 1, 1), (2, 2, 2))
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        mesh.dissect([[0, 1]])
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        mesh.dissect(np.array([[0.0, 1.0, 2.0]]))
