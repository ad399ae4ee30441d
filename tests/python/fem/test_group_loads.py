"""Bodies are held and loaded by named groups (issue 34), through refinement and dissection."""
import numpy as np
import pytest

import snede
from mesh_group_checks import body_held_and_loaded_by_groups, face_measure, interior_on_plane


@pytest.mark.parametrize("formulation", ["p1", "smoothed"])
def test_a_box_body_is_held_and_loaded_by_groups_after_refinement(formulation):
    mesh = snede.meshing.box((1.0, 0.25, 0.25), (4, 1, 1))
    mesh.add_boundary_group("clamped", mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.0), interior=False))
    mesh.add_boundary_group("loaded", mesh.faces_where(lambda x: np.isclose(x[:, 0], 1.0), interior=False))
    mesh.refine_around((1.0, 0.125, 0.125), 0.1)
    body = body_held_and_loaded_by_groups(mesh, 160.0, formulation=formulation)  # 160 Pa on 0.0625 m²: 10 N
    assert len(mesh.group_vertices("clamped")) >= 4
    assert body.displacement[mesh.group_vertices("loaded"), 2].max() < 0


@pytest.mark.parametrize("formulation", ["p1", "smoothed"])
def test_a_plane_stress_sheet_is_loaded_by_length_times_thickness(formulation):
    sheet = snede.meshing.rectangle((2.0, 0.5), (8, 2))
    sheet.add_boundary_group("left", sheet.faces_where(lambda x: np.isclose(x[:, 0], 0.0), interior=False))
    sheet.add_boundary_group("right", sheet.faces_where(lambda x: np.isclose(x[:, 0], 2.0), interior=False))
    sheet.refine_uniform(1)
    body = snede.Body(sheet, snede.LinearElastic(1e6, 0.3), thickness=0.01, formulation=formulation)
    body.fix("left")
    body.add_traction("right", (3000.0, -1000.0))  # on 0.5 m × 0.01 m: (15, −5) N
    np.testing.assert_allclose(body.external_forces().sum(axis=0), (15.0, -5.0), atol=1e-12)
    result = snede.StaticSolver(body, "cg", rtol=1e-8).solve()
    assert result.converged
    assert np.all(body.displacement[sheet.group_vertices("left")] == 0)
    right = sheet.group_vertices("right")
    assert np.sum(body.external_forces()[right] * body.displacement[right]) > 0  # the load does work


def test_a_body_is_loaded_by_its_group_after_a_dissection():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (4, 4, 4))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 2], 0.0), interior=False))
    body = snede.Body(mesh, snede.LinearElastic(1e6, 0.3), formulation="smoothed")
    mesh.dissect(interior_on_plane(mesh, 0, 0.5, lambda x: x[:, 2] > 0.5 - 1e-9))
    body.fix("bottom")
    body.add_traction("incision", (0.0, 0.0, -1.0))
    total = face_measure(mesh, mesh.boundary_groups["incision"])
    assert total == pytest.approx(1.0, rel=1e-12)  # both lips of the 0.5 m² cut
    np.testing.assert_allclose(body.external_forces().sum(axis=0), (0.0, 0.0, -total), atol=1e-12)
    assert snede.StaticSolver(body, "cg", rtol=1e-8).solve().converged
