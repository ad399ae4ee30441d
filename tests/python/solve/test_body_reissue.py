"""A Body's vectors after many edits that add vertices: the model reissues them over storage with
spare room (engine/core/growable_vec), so the state, the carried fields and the constraints must
come through every append and removal exactly, the storage must move only when it is full (a
logarithmic number of times over many edits), and the body must equal one built from scratch on
the edited mesh."""
import numpy as np

import snede

A = np.array([[0.010, 0.002, -0.001], [0.000, -0.004, 0.003], [0.001, 0.000, 0.005]])
B = np.array([0.002, -0.001, 0.0005])
MATERIAL = snede.NeoHookean(E=3e4, nu=0.3)


def affine(points, scale=1.0):
    return scale * (points @ A.T + B)


def storage_address(body) -> int:
    """Where the PETSc vector of the body's displacement keeps its entries."""
    return body._model.displacement_vec.array.__array_interface__["data"][0]


def clamped_box(divisions=4):
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (divisions,) * 3)
    body = snede.Body(mesh, MATERIAL)
    body.displacement = affine(mesh.points)
    fixed = np.flatnonzero(mesh.points[:, 0] == 0.0)
    body.fix(fixed, affine(mesh.points[fixed]))
    return mesh, body


def expected_moves(n_first: int, n_last: int) -> int:
    """How often storage that grows by half when full moves from n_first to n_last entries."""
    moves, capacity = 0, n_first
    while capacity < n_last:
        capacity += capacity // 2
        moves += 1
    return moves


def test_many_small_refinements_carry_the_state_the_velocity_and_the_constraints():
    mesh, body = clamped_box()
    relaxation = snede.DynamicRelaxation(body, damping=10.0, dt=1e-4)
    relaxation.velocity = affine(mesh.points, scale=-3.0)  # a carried field besides the state
    n_first, addresses = 3 * mesh.n_points, {storage_address(body)}
    points = np.random.default_rng(3).uniform(0.02, 0.98, (60, 3))
    points[::4, 0] = 0.0  # some on the clamped face: new vertices there inherit the constraint
    for point in points:
        generation, n_points = body._model.generation, mesh.n_points
        body.refine_around(point, 0.1)
        assert body._model.generation == generation + (mesh.n_points > n_points)
        assert body._model.displacement_vec.getSize() == 3 * mesh.n_points
        assert body._model.tangent_mat.getSize() == (3 * mesh.n_points,) * 2
        np.testing.assert_allclose(body.displacement, affine(mesh.points), rtol=0, atol=1e-15)
        np.testing.assert_allclose(relaxation.velocity, affine(mesh.points, scale=-3.0), rtol=0, atol=1e-14)
        addresses.add(storage_address(body))
    on_face = mesh.points[:, 0] == 0.0
    assert body._model.n_constrained == np.count_nonzero(on_face) > 25
    fixed, anchors, _ = body._model.constraint_table()
    np.testing.assert_array_equal(fixed.ravel(), np.flatnonzero(on_face))  # fixed exactly there, where
    np.testing.assert_allclose(anchors, affine(mesh.points[on_face]), rtol=0, atol=1e-15)  # they were held
    assert mesh.n_points > 3 * 125
    # The storage moved only when full: as often as growth by half needs, not once per edit.
    assert len(addresses) - 1 == expected_moves(n_first, 3 * mesh.n_points)


def test_vertices_added_and_removed_one_by_one_keep_their_rows():
    mesh, body = clamped_box(3)
    rng = np.random.default_rng(4)
    added = []
    for _ in range(200):  # each addition, with the move that announces it, grows the vectors by a row
        a, b = rng.choice(mesh.n_live_points, 2, replace=False)
        added.append(mesh.add_vertex([a, b], [0.25, 0.75]))
        mesh.move_vertex(added[-1], [a, b], [0.5, 0.5])
        assert body.displacement.shape == (mesh.n_points, 3)
    removed = added[::3]
    for v in removed:
        mesh.remove_vertex(v)
    live = mesh.live_vertices
    np.testing.assert_array_equal(body.displacement[~live], 0.0)
    np.testing.assert_allclose(body.displacement[live], affine(mesh.points[live]), rtol=0, atol=1e-15)
    n_points = mesh.n_points
    for _ in removed:  # the freed ids come back, with their new parents' values
        mesh.move_vertex(mesh.add_vertex([0, 1], [0.5, 0.5]), [0, 1], [0.25, 0.75])
    assert mesh.n_points == n_points and mesh.live_vertices.all()
    np.testing.assert_allclose(body.displacement, affine(mesh.points), rtol=0, atol=1e-15)
    assert body._model.displacement_vec.getSize() == 3 * n_points


def test_after_refinements_and_a_cut_the_body_equals_one_built_from_scratch():
    mesh, body = clamped_box(6)
    body.add_gravity()
    for point in np.random.default_rng(5).uniform(0.1, 0.9, (10, 3)):
        body.refine_around(point, 0.05)
    cutter, n_points = snede.TetrahedralCutter(body), mesh.n_points
    report = cutter.cut([[[0.4, 0.3, z], [0.6, 0.7, z]] for z in (1.05, 0.9, 0.75, 0.6)])
    assert report.faces_dissected >= 5 and mesh.n_points > n_points
    assert mesh.n_points == mesh.n_live_points  # no removals here: every row is a vertex of the fresh mesh

    fresh = snede.Body(snede.Mesh(mesh.points, mesh.cells), MATERIAL)
    fresh.add_gravity()
    fresh.fix(np.flatnonzero(mesh.points[:, 0] == 0.0), affine(mesh.points[mesh.points[:, 0] == 0.0]))
    u = fresh.displacement = body.displacement
    d = np.random.default_rng(6).normal(size=u.shape)
    assert body._model.displacement_vec.getSize() == fresh._model.displacement_vec.getSize() == u.size
    np.testing.assert_allclose(body.energy(u), fresh.energy(u), rtol=1e-12)
    np.testing.assert_allclose(body.internal_forces(u), fresh.internal_forces(u), rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(body.tangent_apply(u, d), fresh.tangent_apply(u, d), rtol=1e-11, atol=1e-9)
    np.testing.assert_allclose(body.lumped_mass(), fresh.lumped_mass(), rtol=1e-13)
    np.testing.assert_allclose(body.external_forces(), fresh.external_forces(), rtol=1e-13)
    for edited, built in zip(body._model.constraint_table(), fresh._model.constraint_table()):
        np.testing.assert_allclose(edited, built, rtol=0, atol=1e-15)
    np.testing.assert_allclose(body.reaction_forces(), fresh.reaction_forces(), rtol=1e-10, atol=1e-9)
