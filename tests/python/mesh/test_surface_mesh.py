"""Triangulated surfaces in 3D as first-class meshes (§5.3): input checks, orientation,
boundary edges, quality, files."""
import h5py
import numpy as np
import pytest

import snede
from snede.output import SeriesWriter

OCTAHEDRON_POINTS = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
OCTAHEDRON_CELLS = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def directed_edges(cells):
    return [(c[i], c[(i + 1) % 3]) for c in cells for i in range(3)]


def test_a_closed_surface_is_oriented_consistently_whatever_the_input_order():
    cells = OCTAHEDRON_CELLS.copy()
    cells[[1, 4, 6]] = cells[[1, 4, 6]][:, ::-1]  # three triangles given the wrong way round
    mesh = snede.Mesh(OCTAHEDRON_POINTS, cells)
    assert (mesh.cell_dim, mesh.space_dim, mesh.dim, mesh.is_surface) == (2, 3, 3, True)
    assert mesh.n_reoriented == 3
    edges = directed_edges(mesh.cells)
    assert len(set(edges)) == len(edges) == 24
    assert all((b, a) in set(edges) for a, b in edges)  # every edge run both ways: consistent
    assert len(mesh.boundary_faces()) == 0
    normals = [np.cross(*(OCTAHEDRON_POINTS[c[1:]] - OCTAHEDRON_POINTS[c[0]])) for c in mesh.cells]
    outward = [np.dot(n, OCTAHEDRON_POINTS[c].mean(axis=0)) > 0 for n, c in zip(normals, mesh.cells)]
    assert all(outward)  # the first triangle's orientation (outward) is kept
    mesh.validate()


def test_an_open_surface_has_its_rim_as_boundary_edges():
    x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 4), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), 0.1 * np.sin(3 * x.ravel()) * y.ravel()])
    grid = snede.meshing.rectangle((1, 1), (4, 3))
    mesh = snede.Mesh(points, grid.cells)
    rim = mesh.boundary_faces()
    assert rim.shape == (2 * (4 + 3), 2)
    on_rim = np.isclose(points[:, 0], 0) | np.isclose(points[:, 0], 1) | np.isclose(points[:, 1], 0) | np.isclose(points[:, 1], 1)
    assert set(np.unique(rim)) == set(np.flatnonzero(on_rim))


def test_a_moebius_strip_is_refused():
    n = 8
    angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    points = []
    for t in angles:
        for s in (-0.2, 0.2):
            r = 1 + s * np.cos(t / 2)
            points.append([r * np.cos(t), r * np.sin(t), s * np.sin(t / 2)])
    cells = []
    for i in range(n):
        a, b = 2 * i, 2 * i + 1
        c, d = (2 * (i + 1), 2 * (i + 1) + 1) if i < n - 1 else (1, 0)  # the half twist
        cells += [[a, b, d], [a, d, c]]
    with pytest.raises(ValueError, match="not orientable"):
        snede.Mesh(np.array(points), np.array(cells))


def test_non_manifold_edges_duplicates_and_flat_triangles_are_refused():
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [2, 0, 0]])
    with pytest.raises(ValueError, match="shared by 3"):
        snede.Mesh(points, [[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    with pytest.raises(ValueError, match="same vertices"):
        snede.Mesh(points, [[0, 1, 2], [0, 2, 1]])
    with pytest.raises(ValueError, match="cell 1 has zero area"):
        snede.Mesh(points, [[0, 1, 2], [0, 1, 5]])


def test_quality_measures_angles_in_the_triangles_plane():
    points = np.array([[0.0, 0, 0], [1, 0, 1], [0.5, np.sqrt(3) / 2, 0.5], [0, 0, 2.0]])
    # A unit-edge triangle tilted out of the plane would not be equilateral: build one that is.
    a, b = np.array([1.0, 0, 1]) / np.sqrt(2), np.array([0.0, 1, 0])
    points[1], points[2] = a, 0.5 * a + np.sqrt(3) / 2 * b
    mesh = snede.Mesh(points[:3], [[0, 1, 2]])
    q = mesh.quality()
    np.testing.assert_allclose([q.min_dihedral[0], q.max_dihedral[0]], [np.pi / 3] * 2, rtol=1e-12)
    np.testing.assert_allclose(q.volume, np.sqrt(3) / 4, rtol=1e-12)
    np.testing.assert_allclose(q.aspect_ratio, np.sqrt(3) / 2, rtol=1e-12)


def test_boundary_surface_of_a_box_is_a_closed_surface_of_the_right_area(tmp_path):
    box = snede.meshing.box((1.0, 2.0, 3.0), (2, 3, 4))
    surface, ids = snede.meshing.boundary_surface(box)
    assert surface.is_surface and len(surface.boundary_faces()) == 0
    np.testing.assert_allclose(surface.quality().volume.sum(), 2 * (1 * 2 + 2 * 3 + 1 * 3), rtol=1e-12)
    np.testing.assert_array_equal(surface.points, box.points[ids])
    surface.validate()
    series = SeriesWriter(tmp_path / "surface")
    series.write_mesh(surface)
    with h5py.File(series.h5_path) as f:
        assert f["mesh/0/cells"].shape == (surface.n_cells, 3)
    assert 'TopologyType="Triangle"' in series.xdmf_path.read_text()
    surface.write(tmp_path / "surface.vtu")
    assert snede.Mesh.read(tmp_path / "surface.vtu").n_cells == surface.n_cells


def test_a_surface_can_be_dissected_along_interior_edges():
    x, y = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), 0.2 * x.ravel() ** 2])
    mesh = snede.Mesh(points, snede.meshing.rectangle((1, 1), (4, 4)).cells)
    cut = mesh.faces_where(lambda p: np.isclose(p[:, 0], 0.5) & (p[:, 1] > 0.2) & (p[:, 1] < 0.8))
    rim = len(mesh.boundary_faces())
    pairs = mesh.dissect(cut)
    assert len(mesh.boundary_faces()) == rim + 2 * len(cut)
    assert len(pairs) == len(cut) - 1  # the two ends of an inner slit stay joined
    mesh.validate()


def test_a_body_on_a_surface_is_a_membrane_with_a_thickness():
    surface = snede.Mesh(OCTAHEDRON_POINTS, OCTAHEDRON_CELLS)
    with pytest.raises(ValueError, match="surface mesh is an elastic membrane: give its thickness"):
        snede.Body(surface, snede.LinearElastic(E=1e3, nu=0.3))
    body = snede.Body(surface, snede.LinearElastic(E=1e3, nu=0.3), thickness=0.001)
    assert body.energy(np.zeros((surface.n_points, 3))) == 0.0
