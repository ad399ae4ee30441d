"""The tetrahedral cutter (§3.2–§3.3): validity after every sweep triangle of random paths,
snapped vertices on the sweep, pieces, the deformed configuration, solves after a cut, and
bad input. Independent references: exact geometry of the cut plane, the mesh's own volume
before the cut, analytic affine displacement fields, and the solver's PETSc reasons."""
import math

import numpy as np
import pytest

import snede


def total_volume(mesh):
    return float(np.sum(mesh.quality().volume))


def scalpel_across(normal, point, along, reach=3.0):
    """A scalpel segment through `point`, lying in the plane with `normal`, along `along`."""
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    along = np.asarray(along, float)
    along = along - along.dot(normal) * normal
    along /= np.linalg.norm(along)
    return np.array([point - reach * along, point + reach * along])


def planar_path(normal, offset, centre, sweep_from, sweep_to, steps):
    """Scalpel positions sweeping the plane normal·x = offset from sweep_from to sweep_to
    (distances from the plane point nearest `centre`, measured along the sweep direction)."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    helper = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    blade = np.cross(n, helper)
    blade /= np.linalg.norm(blade)
    travel = np.cross(n, blade)
    base = np.asarray(centre, float) - (n.dot(centre) - offset) * n
    return [scalpel_across(n, base + s * travel, blade) for s in np.linspace(sweep_from, sweep_to, steps)], n, travel


def sagging_beam(size, cells, material, method, rtol):
    """A box beam clamped at x = 0 under gravity, solved by a StaticSolver (asserted to
    converge): its mesh, body and solver."""
    mesh = snede.meshing.box(size, cells)
    body = snede.Body(mesh, material)
    body.fix(np.where(mesh.points[:, 0] < 1e-9)[0])
    body.add_gravity((0, 0, -9.81))
    solver = snede.StaticSolver(body, method, rtol=rtol)
    assert solver.solve().converged
    return mesh, body, solver


def distance_to_plane(points, normal, offset):
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    return np.abs(points @ n - offset)


def test_plane_through_the_whole_box_gives_two_pieces_with_vertices_on_the_plane():
    mesh = snede.meshing.box((1, 1, 1), (6, 6, 6))
    volume = total_volume(mesh)
    cutter = snede.TetrahedralCutter(mesh, remove_degeneracies=False)
    path, n, _ = planar_path((1, 0.4, 0.2), 0.55, (0.5, 0.5, 0.5), -2.0, 2.0, 3)
    report = cutter.cut(path)
    mesh._impl.validate()
    assert report.components == 2
    assert report.faces_dissected > 36  # at least the 6 × 6 × 2 faces of a grid plane
    faces = cutter.incision_faces()
    assert len(faces) == 2 * report.faces_dissected
    # Both lips: every incision vertex lies on the plane (§3.2.2) to round-off, except where a
    # snap was refused: a boundary vertex whose boundary faces the plane does not cross, or one
    # on an edge of the box that the plane crosses away from it (the thesis's "spikes",
    # Figure 3.14). Those are few.
    lips = mesh.points[np.unique(faces)]
    off_plane = np.unique(lips[distance_to_plane(lips, n, 0.55) > 1e-12], axis=0)
    assert len(off_plane) <= report.snaps_refused <= 0.05 * report.vertices_snapped
    # Snapping interior vertices and boundary vertices within flat boundary faces keeps the
    # box: its volume is unchanged up to round-off.
    assert total_volume(mesh) == pytest.approx(volume, rel=1e-12)


def test_cut_that_stops_inside_leaves_one_piece_and_an_incision_behind_the_scalpel():
    mesh = snede.meshing.box((1, 1, 1), (8, 8, 8))
    cutter = snede.TetrahedralCutter(mesh)
    # The scalpel enters through the face y = 0 and stops at y = 0.6, cutting the plane x = 0.43.
    path = [np.array([[0.43, y, -1.0], [0.43, y, 2.0]]) for y in (-0.5, 0.2, 0.6)]
    report = cutter.cut(path)
    mesh._impl.validate()
    assert report.components == 1
    assert report.faces_dissected > 0
    incision = mesh.points[np.unique(cutter.incision_faces())]
    h = 1 / 8
    assert incision[:, 1].max() <= 0.6 + 1e-12  # never ahead of the scalpel
    assert incision[:, 1].max() >= 0.6 - 2 * h  # lagging by at most about one element (Figure 3.4)
    assert distance_to_plane(incision, (1, 0, 0), 0.43).max() < 1e-12


@pytest.mark.parametrize("seed", range(6))
def test_random_scalpel_paths_leave_a_valid_mesh_after_every_sweep_triangle(seed):
    rng = np.random.default_rng(seed)
    mesh = snede.meshing.box((1, 1, 1), (5, 5, 5))
    threshold = 0.02
    cutter = snede.TetrahedralCutter(mesh, min_aspect_ratio=threshold)
    volume = total_volume(mesh)
    a, b = rng.uniform(-0.3, 1.3, 3), rng.uniform(-0.3, 1.3, 3)
    cut_free = 0
    for _ in range(8):
        corners = np.array([a, b, rng.uniform(-0.2, 1.2, 3)])
        try:
            report = cutter.cut_triangle(corners)
        except ValueError:
            continue
        mesh._impl.validate()
        quality = mesh.quality()
        assert quality.volume.min() > 0
        assert quality.aspect_ratio.min() >= threshold  # removed, or cut free
        cut_free += report.elements_cut_free
        a, b = corners[1], corners[2]  # a connected sweep: the next triangle shares an edge
    # Interior snaps and collapses keep the volume up to the flat elements removed and the
    # boundary vertices snapped within faces; the tolerance is generous for the removed slivers.
    assert total_volume(mesh) == pytest.approx(volume, rel=0.02)


def test_random_cuts_through_an_unstructured_cylinder_stay_valid():
    mesh = snede.meshing.cylinder(length=0.1, radius=0.03, h=0.012, seed=3)
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3))
    body.fix(np.where(mesh.points[:, 0] < 1e-9)[0])
    body.add_gravity((0, 0, -9.81))
    solver = snede.StaticSolver(body, "cg", rtol=1e-6)
    assert solver.solve().converged
    cutter = snede.TetrahedralCutter(body)
    rng = np.random.default_rng(7)
    for k in range(4):  # pie-like cuts from the axis outward (Figure 3.13), in random directions
        angle = rng.uniform(0, 2 * math.pi)
        radial = np.array([0.0, math.cos(angle), math.sin(angle)])
        x = rng.uniform(0.03, 0.08)
        cutter.move([[x - 0.01, 0, 0], [x + 0.01, 0, 0]])
        report = cutter.move([[x - 0.01, *(0.05 * radial[1:])], [x + 0.01, *(0.05 * radial[1:])]])
        mesh._impl.validate()
        assert not len(body.inverted_elements(body.displacement))
        result = solver.solve()
        assert result.converged, result
        assert report.sweeps == 2


def test_cutting_the_deformed_body_puts_deformed_vertices_on_the_deformed_plane():
    mesh = snede.meshing.box((1, 1, 1), (6, 6, 6))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.25))
    # An affine pre-deformation: shear plus stretch. The reference plane it maps to x = 0.5 is
    # not a grid plane, so the cut must be made in the deformed configuration.
    A = np.array([[0.2, 0.15, 0.0], [0.0, 0.1, 0.05], [0.05, 0.0, -0.1]])
    body.displacement = mesh.points @ A.T
    cutter = snede.TetrahedralCutter(body, remove_degeneracies=False)
    cutter.move([[0.5, -1, -1], [0.5, -1, 3]])
    report = cutter.move([[0.5, 3, -1], [0.5, 3, 3]])
    assert report.faces_dissected > 0 and report.components == 2
    deformed = mesh.points + body.displacement
    lips = np.unique(cutter.incision_faces())
    assert np.abs(deformed[lips, 0] - 0.5).max() < 1e-12
    # The displacement stays the affine field at every vertex, moved or copied (parents carry it).
    np.testing.assert_allclose(body.displacement, mesh.points @ A.T, atol=1e-14)


def test_a_piece_cut_free_of_its_supports_is_fixed_and_the_solve_converges():
    _, body, solver = sagging_beam((0.2, 0.05, 0.05), (12, 3, 3), snede.NeoHookean(1e5, 0.3), "newton", 1e-6)
    cutter = snede.TetrahedralCutter(body)
    cutter.move([[0.11, -1, 1], [0.11, 1, 1]])
    report = cutter.move([[0.11, -1, -1], [0.11, 1, -1]])
    assert report.components == 2 and report.free_pieces == 1 and report.pieces_fixed == 1
    result = solver.solve()
    assert result.converged, result
    assert not len(body.inverted_elements(body.displacement))


def test_free_pieces_are_only_reported_when_fixing_is_off():
    mesh = snede.meshing.box((1, 1, 1), (4, 4, 4))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.25))
    body.fix(np.where(mesh.points[:, 0] < 1e-9)[0])
    cutter = snede.TetrahedralCutter(body, fix_free_pieces=False)
    cutter.move([[0.6, -1, -1], [0.6, -1, 2]])
    report = cutter.move([[0.6, 2, -1], [0.6, 2, 2]])
    assert report.free_pieces == 1 and report.pieces_fixed == 0


def test_static_and_dynamic_solvers_continue_after_a_cut_from_the_carried_state():
    mesh, body, static = sagging_beam((0.1, 0.02, 0.02), (10, 2, 2), snede.LinearElastic(1e5, 0.3), "cg", 1e-8)
    tip_before = body.displacement[:, 2].min()
    cutter = snede.TetrahedralCutter(body)
    # From above the deformed beam down to the middle of its deformed section at x = 0.052.
    section = np.abs(mesh.points[:, 0] - 0.05) < 1e-9
    middle = float(np.mean(mesh.points[section, 2] + body.displacement[section, 2]))
    cutter.move([[0.052, -1, middle + 0.05], [0.052, 1, middle + 0.05]])
    report = cutter.move([[0.052, -1, middle], [0.052, 1, middle]])
    assert report.faces_dissected > 0 and report.components == 1
    result = static.solve()
    assert result.converged, result
    assert body.displacement[:, 2].min() < tip_before  # the notched beam sags more
    # Dynamic relaxation from the carried state (velocity carried too), across a further cut.
    dynamic = snede.DynamicRelaxation(body, damping=2000.0)
    dynamic.step(20)
    deeper = cutter.move([[0.052, -1, middle - 0.005], [0.052, 1, middle - 0.005]])
    assert deeper.sweeps == 2
    assert dynamic.velocity.shape == body.displacement.shape
    result = dynamic.step(20)
    assert np.all(np.isfinite(body.displacement)) and "DIVERGED" not in result.reason


def test_bad_input_is_refused_before_anything_changes():
    mesh = snede.meshing.box((1, 1, 1), (3, 3, 3))
    cutter = snede.TetrahedralCutter(mesh)
    revision = mesh._impl.revision if hasattr(mesh._impl, "revision") else None
    points = mesh.points.copy()
    with pytest.raises(ValueError, match="not finite|non-finite"):
        cutter.cut_triangle([[0, 0, 0], [1, np.nan, 0], [0, 1, 0]])
    with pytest.raises(ValueError, match="collinear"):
        cutter.cut_triangle([[0, 0, 0], [1, 1, 1], [2, 2, 2]])
    with pytest.raises(ValueError, match="shape"):
        cutter.cut_triangle([[0, 0, 0], [1, 1, 1]])
    with pytest.raises(ValueError, match="zero length"):
        cutter.move([[0.5, 0.5, 0.5], [0.5, 0.5, 0.5]])
    with pytest.raises(ValueError, match="not finite|non-finite"):
        cutter.move([[0.5, 0.5, np.inf], [0.5, 0.5, 0.5]])
    with pytest.raises(ValueError, match="min_aspect_ratio"):
        snede.TetrahedralCutter(mesh, min_aspect_ratio=0)
    with pytest.raises(ValueError, match="large_angle"):
        snede.TetrahedralCutter(mesh, large_angle=4.0)
    with pytest.raises(ValueError, match="tetrahedral"):
        snede.TetrahedralCutter(snede.meshing.rectangle((1, 1), (2, 2)))
    np.testing.assert_array_equal(mesh.points, points)
    if revision is not None:
        assert mesh._impl.revision == revision
    # A scalpel that misses the body: an empty report, the mesh untouched.
    cutter.move([[5, 5, 5], [5, 6, 5]])
    report = cutter.move([[6, 5, 5], [6, 6, 5]])
    assert report.sweeps == 2 and report.faces_selected == 0 and report.faces_dissected == 0
    np.testing.assert_array_equal(mesh.points, points)


@pytest.mark.parametrize("moves", [4, 16, 64])
def test_small_scalpel_steps_cut_as_much_as_large_ones(moves):
    """A tetrahedron crossed over many small moves still selects its face: crossings of the
    earlier sweeps count (§3.2.1, Figure 3.2). 64 moves over 0.8 m are 1/13 of an element each."""
    mesh = snede.meshing.box((1, 1, 1), (6, 6, 6))
    cutter = snede.TetrahedralCutter(mesh)
    cutter.cut([[[0.55, -0.5, z], [0.55, 1.5, z]] for z in np.linspace(1.1, 0.3, moves + 1)])
    mesh._impl.validate()
    # The plane x = 0.55 from the top down to z = 0.3: 6 columns × (rows fully passed) × 2 faces,
    # the same whatever the step.
    assert len(cutter.incision_faces()) == 96


def test_lifting_the_scalpel_starts_a_new_incision_instead_of_sweeping_between_the_two():
    mesh = snede.meshing.box((1, 1, 1), (8, 8, 8))
    cutter = snede.TetrahedralCutter(mesh)
    notch = [np.array([[0.3, -1.0, z], [0.3, 2.0, z]]) for z in (1.2, 0.6)]  # down to z = 0.6 at x = 0.3
    first = cutter.cut(notch)
    assert first.faces_dissected > 0 and cutter.placed
    cutter.lift()
    assert not cutter.placed
    placing = cutter.move(np.array([[0.7, -1.0, 1.2], [0.7, 2.0, 1.2]]))
    assert placing.sweeps == 0 and placing.faces_dissected == 0
    second = cutter.move(np.array([[0.7, -1.0, 0.6], [0.7, 2.0, 0.6]]))
    assert second.faces_dissected > 0 and second.components == 1
    mesh._impl.validate()
    # Two notches and nothing between them: every incision vertex lies on x = 0.3 or x = 0.7,
    # where a scalpel that was not lifted would have swept the plane from one to the other.
    x = mesh.points[np.unique(cutter.incision_faces()), 0]
    assert np.all(np.isclose(x, 0.3, atol=1e-12) | np.isclose(x, 0.7, atol=1e-12))
    assert np.any(np.isclose(x, 0.3, atol=1e-12)) and np.any(np.isclose(x, 0.7, atol=1e-12))


def test_pieces_are_counted_by_a_search_near_the_cut_until_one_separates():
    mesh = snede.meshing.box((1, 1, 1), (14, 14, 14))
    n = mesh.n_cells
    cutter = snede.TetrahedralCutter(mesh)
    path = [np.array([[0.47, -1.0, z], [0.47, 2.0, z]]) for z in np.linspace(1.3, -0.3, 9)]
    reports = [cutter.move(scalpel) for scalpel in path]
    notching = [r for r in reports[1:] if r.faces_dissected > 0 and r.components == 1]
    assert notching, "the path never cut without separating"
    assert max(r.piece_search for r in notching) < n / 10
    assert reports[-1].components == 2 == mesh.connected_components()[0]
