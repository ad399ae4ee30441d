"""The cutters open an "incision" group and keep the user's named groups (issue 34)."""
import numpy as np
import pytest

import snede
from mesh_group_checks import cell_measure, check, face_measure, label_partition


def test_tetrahedral_cutter_opens_an_incision_and_keeps_the_user_groups():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (6, 6, 6))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 2], 0.0), interior=False))
    mesh.add_boundary_group("back", mesh.faces_where(lambda x: np.isclose(x[:, 1], 1.0), interior=False))
    partition = label_partition(mesh, np.random.default_rng(11), 2)
    volumes = {name: cell_measure(mesh, mesh.cell_groups[name]) for name in partition}
    cutter = snede.TetrahedralCutter(mesh)
    # The scalpel enters through y = 0 and stops at y = 0.6, cutting the plane x = 0.43.
    report = cutter.cut([np.array([[0.43, y, -1.0], [0.43, y, 2.0]]) for y in (-0.5, 0.2, 0.6)])
    assert report.faces_dissected > 0
    incision = mesh.boundary_groups["incision"]
    assert len(incision) > 0
    # The cutter's own incision faces and the group are the same faces.
    assert {tuple(f) for f in np.sort(incision, axis=1).tolist()} == \
        {tuple(f) for f in np.sort(cutter.incision_faces(), axis=1).tolist()}
    check(mesh, partition, {"bottom": 1.0, "back": 1.0}, {})
    # Snapping moves vertices onto the plane: the total volume stays, each group's up to the
    # slabs the snaps moved (a cell keeps its group by its centroid's old place).
    assert cell_measure(mesh, np.arange(mesh.n_cells)) == pytest.approx(1.0, rel=1e-12)
    for name in partition:
        assert cell_measure(mesh, mesh.cell_groups[name]) == pytest.approx(volumes[name], abs=2.0 / 6)
    assert np.all(np.abs(mesh.points[np.unique(incision), 0] - 0.43) < 1e-12)


def test_delaunay_cutter_opens_an_incision_and_keeps_the_user_groups():
    mesh = snede.meshing.rectangle((1.0, 1.0), (8, 8))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 1], 0.0), interior=False))
    mesh.add_boundary_group("left", mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.0), interior=False))
    partition = label_partition(mesh, np.random.default_rng(12), 2)
    cutter = snede.DelaunayCutter(mesh)
    for y in np.linspace(1.2, 0.45, 40):  # enters through y = 1 and stops inside
        cutter.move([0.43, y])
    incision = mesh.boundary_groups["incision"]
    assert len(incision) > 0
    length = face_measure(mesh, incision)
    assert length > 2 * 0.4  # both lips, about 0.55 long each
    check(mesh, partition, {"bottom": 1.0, "left": 1.0}, {})
    assert cell_measure(mesh, np.arange(mesh.n_cells)) == pytest.approx(1.0, rel=1e-12)


def test_tetrahedral_cutter_on_a_curved_body_puts_only_the_lips_in_incision():
    mesh = snede.meshing.ellipsoid(h=0.012, seed=1)
    mesh.add_boundary_group("skin", mesh.boundary_faces())
    cutter = snede.TetrahedralCutter(mesh)
    report = cutter.cut([np.array([[0.005, y, -0.1], [0.005, y, 0.1]]) for y in (-0.06, 0.0, 0.01)])
    assert report.faces_dissected > 0
    keys = lambda faces: {tuple(f) for f in np.sort(faces, axis=1).tolist()}  # noqa: E731
    assert keys(mesh.boundary_groups["incision"]) == keys(cutter.incision_faces())
    assert keys(mesh.boundary_groups["skin"]) == keys(mesh.boundary_faces()) - keys(cutter.incision_faces())
