"""A solver keeps solving after a cut changes the mesh under it, from the carried-over state."""
import numpy as np
import pytest

import snede


@pytest.mark.parametrize("method", ["cg", "ncg", "newton"])
def test_every_method_continues_after_a_dissection_and_agrees_with_a_new_solver(method):
    # Item 3 (ncg raised "Incompatible vector local lengths" after a mesh change): a cut that
    # adds vertices, then the same solver object solves again, from the carried-over state.
    mesh = snede.meshing.rectangle((1.0, 0.2), (10, 2))
    material = snede.LinearElastic(1e5, 0.3) if method == "cg" else snede.NeoHookean(1e5, 0.3)
    body = snede.Body(mesh, material, thickness=0.01, density=1.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81))
    solver = snede.StaticSolver(body, method, rtol=1e-9)
    assert solver.solve().converged
    n_before = mesh.n_points
    faces = mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5) & (x[:, 1] < 0.15))
    assert len(mesh.dissect(faces)) > 0 and mesh.n_points > n_before
    after = solver.solve()
    assert after.converged, after
    carried = body.displacement.copy()
    body.displacement = np.zeros_like(carried)
    fresh = snede.StaticSolver(body, method, rtol=1e-9, options_prefix="fresh_").solve()
    assert fresh.converged, fresh
    np.testing.assert_allclose(carried, body.displacement, atol=1e-6 * np.abs(carried).max())
