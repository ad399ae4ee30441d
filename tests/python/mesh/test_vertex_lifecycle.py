"""Vertex lifecycle (added with barycentric parents, moved, removed) seen from a Body: sizes
reissued, state carried over exactly, batched refinement, named load channels, constraint
switches without a solver rebuild."""
import numpy as np
import pytest

import snede

A = np.array([[0.010, -0.004], [0.003, 0.007]])
B = np.array([0.02, -0.01])


def affine(points):
    return points @ A.T + B


def sheet():
    mesh = snede.meshing.rectangle((1.0, 1.0), (6, 6))
    body = snede.Body(mesh, snede.LinearElastic(E=1e4, nu=0.3), thickness=0.01)
    body.displacement = affine(mesh.points)
    return mesh, body


def test_moving_a_vertex_by_parents_keeps_an_affine_field_affine():
    mesh, body = sheet()
    energy = body.energy(body.displacement)
    v = 3 * 7 + 3  # an interior vertex; move it a third of the way to its right neighbour
    mesh.move_vertex(v, [v, v + 7], [2 / 3, 1 / 3])
    np.testing.assert_allclose(mesh.points[v], [0.5 + 1 / 18, 0.5], rtol=1e-15)
    np.testing.assert_allclose(body.displacement, affine(mesh.points), rtol=0, atol=1e-15)
    np.testing.assert_allclose(body.energy(body.displacement), energy, rtol=1e-12)  # domain unchanged


def test_moving_a_vertex_to_coordinates_keeps_its_displacement_and_recomputes_its_cells():
    mesh, body = sheet()
    v = 2 * 7 + 4
    before = body.displacement[v].copy()
    mesh.move_vertex(v, point=mesh.points[v] + [0.05, 0.02])
    np.testing.assert_array_equal(body.displacement[v], before)
    # The reference shape changed, so the affine field's energy changes with it: recomputed
    # from the new corners, it equals a fresh body on the moved mesh.
    fresh = snede.Body(snede.Mesh(mesh.points, mesh.cells), snede.LinearElastic(E=1e4, nu=0.3), thickness=0.01)
    np.testing.assert_allclose(body.energy(body.displacement), fresh.energy(body.displacement), rtol=1e-13)


def test_a_used_vertex_cannot_be_removed_and_a_removed_id_is_reused():
    mesh, body = sheet()
    with pytest.raises(ValueError, match="still used by 6 cell"):
        mesh.remove_vertex(3 * 7 + 3)
    n = mesh.n_points
    v = mesh.add_vertex([0, 1], [0.5, 0.5])  # an unused midpoint; no cell change yet
    assert v == n and mesh.n_points == n + 1
    mesh.remove_vertex(v)
    assert mesh.n_points == n + 1 and mesh.n_live_points == n and not mesh.live_vertices[v]
    assert body.displacement.shape == (n + 1, 2)  # the model follows the row count
    np.testing.assert_array_equal(body.displacement[v], 0.0)
    assert mesh.add_vertex([1, 2], [0.25, 0.75]) == v  # the freed id comes back
    with pytest.raises(ValueError, match="sum to"):
        mesh.add_vertex([0, 1], [0.5, 0.6])
    with pytest.raises(ValueError, match="was removed|does not exist"):
        mesh.move_vertex(10_000, [0], [1.0])


def test_removed_vertices_are_out_of_the_problem_and_a_solve_still_converges():
    mesh, body = sheet()
    v = mesh.add_vertex([0, 8], [0.5, 0.5])
    mesh.remove_vertex(v)
    body.displacement = np.zeros((mesh.n_points, 2))
    body.fix(np.isclose(mesh.points[:, 0], 0.0) & mesh.live_vertices)
    body.add_nodal_force(np.flatnonzero(np.isclose(mesh.points[:, 0], 1.0)), (0.0, -1.0))
    result = snede.StaticSolver(body, "cg", rtol=1e-8).solve()
    assert result.converged, result
    np.testing.assert_array_equal(body.displacement[v], 0.0)
    np.testing.assert_array_equal(body.reaction_forces()[v], 0.0)


def test_refine_around_is_one_change_for_the_body():
    mesh = snede.meshing.box((1, 1, 1), (4, 4, 4))
    body = snede.Body(mesh, snede.LinearElastic(E=1e4, nu=0.3))
    A3 = np.array([[0.01, 0.002, 0], [0, -0.004, 0.003], [0.001, 0, 0.005]])
    body.displacement = mesh.points @ A3.T
    generation = body._model.generation
    n_cells = mesh.n_cells
    split = body.refine_around((0.3, 0.4, 0.6), 0.02)
    assert split > 100 and mesh.n_cells == n_cells + split  # each split turns one cell into two
    assert body._model.generation == generation + 1  # sizes reissued once, not once per split
    np.testing.assert_allclose(body.displacement, mesh.points @ A3.T, atol=1e-15)
    n_cells = mesh.n_cells
    assert mesh.refine_uniform(1) >= n_cells
    assert body._model.generation == generation + 2


def test_load_channels_are_changed_and_cleared_alone():
    mesh, body = sheet()
    body.add_gravity((0.0, -9.81))
    body.add_nodal_force([5, 6], (1.0, 0.0))
    body.add_nodal_force([6], (0.0, 2.0), channel="friction")
    gravity = body.gravity_forces((0.0, -9.81))
    assert sorted(body.load_channels) == ["friction", "nodal"]
    expected = gravity.copy()
    expected[[5, 6], 0] += 1.0
    expected[6, 1] += 2.0
    np.testing.assert_allclose(body.external_forces(), expected, rtol=1e-15)
    body.set_nodal_forces([7], (0.0, 3.0), channel="friction")  # replaces the channel
    np.testing.assert_array_equal(body.external_forces("friction")[[6, 7]], [[0, 0], [0, 3.0]])
    body.clear_loads("friction")
    expected[6, 1] -= 2.0
    np.testing.assert_allclose(body.external_forces(), expected, rtol=1e-15)
    body.clear_gravity()
    np.testing.assert_allclose(body.external_forces(), expected - gravity, atol=1e-15)
    body.clear_loads()
    assert body.load_channels == [] and not body.external_forces().any()


def test_gravity_is_not_a_load_channel_and_has_gravity_says_whether_it_acts():
    """load_channels names the nodal-force channels, those external_forces(channel) and
    clear_loads(channel) take; gravity is a body force of its own (issue 38, item 9)."""
    mesh, body = sheet()
    assert not body.has_gravity
    body.add_gravity((0.0, -9.81))
    assert body.has_gravity and body.load_channels == []
    body.add_nodal_force([5], (1.0, 0.0))
    body.clear_loads("nodal")
    assert body.has_gravity and body.load_channels == []
    body.clear_gravity()
    assert not body.has_gravity
    body.add_gravity((0.0, -9.81))
    body.clear_loads()  # every channel and gravity
    assert not body.has_gravity


def test_switching_constraints_between_fixed_and_sliding_does_not_rebuild_the_solver():
    mesh, body = sheet()
    body.displacement = np.zeros((mesh.n_points, 2))
    left = np.isclose(mesh.points[:, 0], 0.0)
    top = np.flatnonzero(np.isclose(mesh.points[:, 1], 1.0) & ~left)
    body.fix(left)
    body.fix(top)  # held at zero
    body.add_nodal_force(np.flatnonzero(np.isclose(mesh.points[:, 0], 1.0)), (2.0, 1.0))
    solver = snede.StaticSolver(body, "cg", rtol=1e-10)
    assert solver.solve().converged
    np.testing.assert_array_equal(body.displacement[top], 0.0)
    ksp, generation = solver.ksp.handle, body._model.generation
    body.slide(top, (1.0, 0.0))  # now free along x only, through where they are (y = 0)
    result = solver.solve()
    assert result.converged, result
    assert solver.ksp.handle == ksp and body._model.generation == generation
    np.testing.assert_array_equal(body.displacement[top][:, 1], 0.0)
    assert np.all(body.displacement[top][:, 0] > 0)
    np.testing.assert_allclose(body.reaction_forces()[top][:, 0], 0.0, atol=1e-9)  # no support along the line
    body.release(top)
    assert solver.solve().converged
    assert np.all(body.displacement[top][:, 1] > 0)  # pulled up once released
    np.testing.assert_allclose(body.reaction_forces()[top], 0.0, atol=1e-9)
    body.fix(top)  # and back: fixed at zero again
    assert solver.solve().converged and solver.ksp.handle == ksp
    np.testing.assert_array_equal(body.displacement[top], 0.0)
