"""Elastic membranes: a Body on a surface mesh (triangles in 3D) under plane stress, for all
four materials. Forces and tangent actions against the energy (Taylor), rigid motions,
a flat membrane against the 2D plane-stress Body on the same triangles (also tilted out of
the xy plane), element stiffnesses against tangent actions, masses against areas, mesh edits
against a fresh body, and bad input."""
import numpy as np
import pytest

import snede
from conftest import (E, NU, all_materials, check_forces_are_minus_the_energy_gradient,
                      check_tangent_is_the_force_derivative, distorted, random_state)
from membrane_sheets import pretensioned_sheet

THICKNESS = 0.01


def flat_mesh() -> snede.Mesh:
    """A distorted unit square of 32 triangles in the xy plane (a 2D mesh)."""
    return distorted(snede.meshing.rectangle((1.0, 1.0), (4, 4)), 0.06)


def lifted(mesh: snede.Mesh, height) -> snede.Mesh:
    """The triangles of a 2D mesh as a surface in 3D, at z = height(x, y)."""
    x, y = mesh.points.T
    return snede.Mesh(np.c_[x, y, height(x, y)], mesh.cells)


def curved_patch(seed: int = 0) -> snede.Mesh:
    """A surface over the unit square with random Gaussian bumps (curved in both directions)."""
    rng = np.random.default_rng(seed)
    centres, heights = rng.uniform(0, 1, (3, 2)), rng.uniform(-0.3, 0.3, 3)

    def height(x, y):
        return sum(h * np.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2) / 0.15) for c, h in zip(centres, heights))

    return lifted(flat_mesh(), height)


def rotation_matrix(rotation_vector) -> np.ndarray:
    """Rodrigues' formula: the rotation by |r| about r."""
    r = np.asarray(rotation_vector, dtype=float)
    angle = np.linalg.norm(r)
    k = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]]) / angle
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def membrane(mesh, material) -> snede.Body:
    return snede.Body(mesh, material, density=1000.0, thickness=THICKNESS)


@pytest.mark.parametrize("scale", [0.01, 0.1])
def test_forces_are_minus_the_energy_gradient(material_name, scale):
    body = membrane(curved_patch(), all_materials()[material_name])
    for seed in range(3):
        check_forces_are_minus_the_energy_gradient(body, *random_state(body, scale, seed))


@pytest.mark.parametrize("scale", [0.01, 0.1])
def test_tangent_is_the_force_derivative(material_name, scale):
    body = membrane(curved_patch(1), all_materials()[material_name])
    for seed in range(3):
        check_tangent_is_the_force_derivative(body, *random_state(body, scale, seed), linear=material_name == "linear")


def test_tangent_is_symmetric(material_name):
    body = membrane(curved_patch(2), all_materials()[material_name])
    u, d = random_state(body, 0.05, 7)
    w = np.random.default_rng(8).standard_normal(u.shape)
    left, right = (w * body.tangent_apply(u, d)).sum(), (d * body.tangent_apply(u, w)).sum()
    assert abs(left - right) <= 1e-11 * max(abs(left), 1.0)


def rigid_motion(points, rotation, translation):
    return points @ rotation.T + translation - points


def test_finite_rigid_motions_cost_nothing(material_name):
    """Rotations by up to π about random axes (a half-turn flips every normal) plus a
    translation: no energy, no force, nothing reported inverted. The linear membrane, whose
    strain is linearised, is invariant under translations and infinitesimal rotations
    u = ω × X only; the hyperelastic ones under finite rotations."""
    body = membrane(curved_patch(3), all_materials()[material_name])
    X = body.mesh.points
    rng = np.random.default_rng(4)
    # the stress scale of a unit strain, on one element: energies and forces are round-off
    # against it
    energy_scale = all_materials()[material_name].lame[1] * THICKNESS
    force_scale = energy_scale / 0.25
    for angle in [0.7, 2.0, np.pi]:
        axis = rng.standard_normal(3)
        axis /= np.linalg.norm(axis)
        translation = rng.standard_normal(3)
        if material_name == "linear":
            u = np.cross(angle * axis, X) + translation
        else:
            u = rigid_motion(X, rotation_matrix(angle * axis), translation)
        assert len(body.inverted_elements(u)) == 0
        assert abs(body.energy(u)) <= 1e-13 * energy_scale
        assert np.abs(body.internal_forces(u)).max() <= 1e-12 * force_scale
        assert np.all(np.isfinite(body.tangent_apply(u, rng.standard_normal(u.shape))))


@pytest.mark.parametrize("material_name", ["stvk", "neohookean", "veronda"])
def test_nonlinear_membrane_is_frame_indifferent(material_name):
    """A finite rotation of a deformed membrane keeps its energy and rotates its forces and
    tangent actions (the hyperelastic energy depends on FᵀF only; the small-strain linear
    membrane is not invariant under finite rotations)."""
    body = membrane(curved_patch(5), all_materials()[material_name])
    X = body.mesh.points
    u, d = random_state(body, 0.05, 11)
    Q = rotation_matrix([0.4, -2.1, 1.3])
    rotated = (X + u) @ Q.T - X  # the deformed membrane, rotated as a whole
    assert body.energy(rotated) == pytest.approx(body.energy(u), rel=1e-12)
    scale = np.abs(body.internal_forces(u)).max()
    assert np.abs(body.internal_forces(rotated) - body.internal_forces(u) @ Q.T).max() <= 1e-12 * scale
    action = body.tangent_apply(u, d)
    rotated_action = body.tangent_apply(rotated, d @ Q.T)
    assert np.abs(rotated_action - action @ Q.T).max() <= 1e-11 * np.abs(action).max()


def tilt():
    return rotation_matrix([0.9, -0.4, 0.3])


@pytest.mark.parametrize("rotation", [np.eye(3), tilt()], ids=["flat", "tilted"])
def test_flat_membrane_equals_plane_stress_body(material_name, rotation):
    """The same triangles as a 2D plane-stress body and as a membrane in the plane z = 0,
    optionally rotated into a tilted plane as a whole: the same energy, the in-plane forces
    and tangent actions (rotated), nothing out of the plane."""
    material = all_materials()[material_name]
    sheet = flat_mesh()
    body_2d = snede.Body(sheet, material, thickness=THICKNESS)
    plane = snede.Mesh(np.c_[sheet.points, np.zeros(sheet.n_points)] @ rotation.T, sheet.cells)
    body = membrane(plane, material)
    rng = np.random.default_rng(12)
    for scale in [0.01, 0.03]:
        u_2d, d_2d = scale * rng.standard_normal((sheet.n_points, 2)), rng.standard_normal((sheet.n_points, 2))
        assert len(body_2d.inverted_elements(u_2d)) == 0

        def in_space(field):
            return np.c_[field, np.zeros(len(field))] @ rotation.T

        u, d = in_space(u_2d), in_space(d_2d)
        assert body.energy(u) == pytest.approx(body_2d.energy(u_2d), rel=1e-12)
        forces_2d = body_2d.internal_forces(u_2d)
        assert np.abs(body.internal_forces(u) - in_space(forces_2d)).max() <= 1e-12 * np.abs(forces_2d).max()
        action_2d = body_2d.tangent_apply(u_2d, d_2d)
        assert np.abs(body.tangent_apply(u, d) - in_space(action_2d)).max() <= 1e-12 * np.abs(action_2d).max()


def test_membrane_stress_is_the_plane_stress_in_the_element_frame(material_name):
    """element_stress gives each cell's 2×2 stress in its frame t₁ = first edge direction,
    t₂ = n × t₁: rotated into x, y it is the 2D body's stress."""
    material = all_materials()[material_name]
    sheet = flat_mesh()
    body_2d = snede.Body(sheet, material, thickness=THICKNESS)
    body = membrane(lifted(sheet, lambda x, y: 0 * x), material)
    u_2d = 0.05 * np.random.default_rng(13).standard_normal((sheet.n_points, 2))
    stress = body.element_stress(np.c_[u_2d, np.zeros(sheet.n_points)])
    stress_2d = body_2d.element_stress(u_2d)
    assert stress.shape == (sheet.n_cells, 2, 2)
    points = body.mesh.points
    for row, cell in enumerate(body.mesh.cells):
        t1 = points[cell[1]] - points[cell[0]]
        t1 /= np.linalg.norm(t1)
        normal = np.cross(points[cell[1]] - points[cell[0]], points[cell[2]] - points[cell[0]])
        t2 = np.cross(normal / np.linalg.norm(normal), t1)
        frame = np.c_[t1, t2][:2]  # columns t₁, t₂ in x, y
        expected = frame.T @ stress_2d[body_2d.mesh.cells.tolist().index(cell.tolist())] @ frame
        assert np.abs(stress[row] - expected).max() <= 1e-12 * np.abs(stress_2d).max()


def test_element_stiffness_sums_to_the_tangent(material_name):
    body = membrane(curved_patch(6), all_materials()[material_name])
    u, d = random_state(body, 0.05, 14)
    action = np.zeros_like(u)
    for row, cell in enumerate(body.mesh.cells):
        K = body.element_stiffness(row, u)
        assert K.shape == (9, 9)
        assert np.abs(K - K.T).max() <= 1e-10 * np.abs(K).max()
        action[cell] += (K @ d[cell].ravel()).reshape(3, 3)
    expected = body.tangent_apply(u, d)
    assert np.abs(action - expected).max() <= 1e-12 * np.abs(expected).max()


def test_linear_membrane_has_no_stiffness_out_of_its_plane():
    """Documented limit: normal displacements of a flat linear membrane cost nothing."""
    body = membrane(lifted(flat_mesh(), lambda x, y: 0 * x), all_materials()["linear"])
    normal = np.zeros((body.mesh.n_points, 3))
    normal[:, 2] = np.random.default_rng(15).standard_normal(body.mesh.n_points)
    assert body.energy(normal) == 0.0
    assert np.abs(body.tangent_apply(np.zeros_like(normal), normal)).max() == 0.0


def triangle_areas(mesh):
    p = mesh.points[mesh.cells]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def test_mass_and_gravity_follow_the_areas():
    mesh = curved_patch(7)
    body = snede.Body(mesh, all_materials()["stvk"], density=1200.0, thickness=THICKNESS)
    areas = triangle_areas(mesh)
    expected = np.zeros(mesh.n_points)
    for cell, area in zip(mesh.cells, areas):
        expected[cell] += 1200.0 * THICKNESS * area / 3
    assert np.abs(body.lumped_mass() - expected).max() <= 1e-14 * expected.max()
    g = np.array([0.3, -1.0, -9.81])
    assert np.abs(body.gravity_forces(g) - np.outer(expected, g)).max() <= 1e-13 * expected.max() * 9.81


@pytest.mark.parametrize("collapse", ["onto an edge", "to a point"])
def test_collapsed_triangles_are_reported_inverted(material_name, collapse):
    """A triangle squashed onto a line or a point is the membrane's inversion (up to the
    round-off of its reference area): reported, and the materials that forbid inversion give
    +inf and leave it out. A triangle squashed to ~1e-6 of its area is not."""
    body = membrane(curved_patch(8), all_materials()[material_name])
    points = body.mesh.points
    row = 5
    a, b, c = body.mesh.cells[row]
    u = np.zeros_like(points)
    target = 0.5 * (points[a] + points[b]) if collapse == "onto an edge" else points[a]
    u[c] = target - points[c]
    expected = [row]
    if collapse == "to a point":
        u[b] = target - points[b]
        # every cell with two of a, b, c (its neighbours across ab, bc, ca) collapses too
        expected = [r for r, cell in enumerate(body.mesh.cells) if len({a, b, c} & set(cell)) >= 2]
    assert list(body.inverted_elements(u)) == expected
    energy, forces = body.energy(u), body.internal_forces(u)
    if material_name in ("neohookean", "veronda"):
        assert energy == np.inf
    else:
        assert np.isfinite(energy)
    assert np.all(np.isfinite(forces))
    if collapse == "onto an edge":
        u[c] += 1e-6 * np.cross(points[b] - points[a], points[c] - points[a])
        assert len(body.inverted_elements(u)) == 0


def test_membrane_follows_mesh_edits(material_name):
    """After an edge split and an edge flip on the surface, the body equals a new body on
    the edited mesh, with the displacement the edits carried over."""
    material = all_materials()[material_name]
    mesh = curved_patch(9)
    body = membrane(mesh, material)
    u, d = random_state(body, 0.03, 16)
    body.displacement = u
    a, b = mesh.cells[10][:2]
    assert mesh.split_edge(a, b)
    flipped = False
    for cell in mesh.cells:
        for i in range(3):
            if mesh.flip_edge(cell[i], cell[(i + 1) % 3]):
                flipped = True
                break
        if flipped:
            break
    assert flipped
    mesh.validate()
    u = body.displacement
    d = np.random.default_rng(17).standard_normal(u.shape)
    fresh = membrane(snede.Mesh(mesh.points, mesh.cells), material)
    assert body.energy(u) == pytest.approx(fresh.energy(u), rel=1e-13)
    forces = fresh.internal_forces(u)
    assert np.abs(body.internal_forces(u) - forces).max() <= 1e-12 * np.abs(forces).max()
    action = fresh.tangent_apply(u, d)
    assert np.abs(body.tangent_apply(u, d) - action).max() <= 1e-12 * np.abs(action).max()
    assert body.lumped_mass() == pytest.approx(fresh.lumped_mass(), rel=1e-13)


def test_surface_of_a_volume_mesh_is_a_membrane():
    surface, _ = snede.meshing.boundary_surface(snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)))
    body = snede.Body(surface, snede.NeoHookean(1e4, 0.3), thickness=0.002)
    assert body.dim == 3 and body.thickness == 0.002
    # inflating the closed box by 10 % stretches every triangle equally
    u = 0.1 * (surface.points - 0.5)
    assert body.energy(u) > 0
    forces = body.internal_forces(u)
    centre_pull = (forces * (surface.points - 0.5)).sum()
    assert centre_pull < 0  # the stretched membrane pulls its points back in


def test_bad_input_is_refused():
    surface = curved_patch()
    material = all_materials()["stvk"]
    with pytest.raises(ValueError, match="surface mesh is an elastic membrane"):
        snede.Body(surface, material)
    for thickness in [0.0, -1.0, np.nan]:
        with pytest.raises(ValueError, match="membrane"):
            snede.Body(surface, material, thickness=thickness)
    body = membrane(surface, material)
    with pytest.raises(ValueError, match="shape"):
        body.energy(np.zeros((surface.n_points, 2)))
    with pytest.raises(ValueError, match="3 components"):
        body.gravity_forces((0.0, -9.81))
    with pytest.raises(ValueError):
        body.element_stiffness(surface.n_cells, np.zeros((surface.n_points, 3)))
    with pytest.raises(ValueError, match="tetrahedral"):
        snede.Body(snede.meshing.box((1.0, 1.0, 1.0), (1, 1, 1)), material, thickness=0.01)


def test_overflow_is_a_domain_error():
    body = membrane(curved_patch(), snede.VerondaWestmann(3e3, 0.3, 50.0))
    with pytest.raises(snede.DomainError):
        body.internal_forces(30.0 * body.mesh.points)


def test_newton_solves_a_pretensioned_membrane_under_a_transverse_load():
    """A flat neo-Hookean square, its rim pulled out by 10 %: Newton finds the homogeneous
    stretch (exact on any mesh), then under a small load across its plane the deflection w
    of the membrane equation t·s·Δw = −p (s the pre-stress S₁₁; P1 Laplacian on the reference
    triangles, assembled here independently)."""
    sheet = snede.meshing.rectangle((1.0, 1.0), (8, 8))
    mesh = lifted(sheet, lambda x, y: 0 * x)
    thickness, load = 0.001, 1e-3
    body = snede.Body(mesh, snede.NeoHookean(1e5, 0.3), thickness=thickness)
    X = mesh.points
    rim = np.unique(mesh.boundary_faces())
    inside = np.setdiff1d(np.arange(mesh.n_points), rim)
    stretch = 0.1 * (X - [0.5, 0.5, 0.0])
    stretch[:, 2] = 0
    body.fix(rim, stretch[rim])
    solver = snede.StaticSolver(body, "newton", rtol=1e-10)
    assert solver.solve().converged
    assert np.abs(body.displacement - stretch).max() <= 1e-10

    body.add_nodal_force(inside, (0.0, 0.0, -load))
    assert solver.solve().converged
    pre_stress = body.element_stress(stretch)[:, 0, 0]
    assert np.ptp(pre_stress) <= 1e-10 * pre_stress[0]
    laplacian = np.zeros((mesh.n_points, mesh.n_points))
    for cell in mesh.cells:
        corners = np.c_[np.ones(3), X[cell][:, :2]]
        gradients = np.linalg.inv(corners)[1:]
        laplacian[np.ix_(cell, cell)] += 0.5 * abs(np.linalg.det(corners)) * gradients.T @ gradients
    stiffness = thickness * pre_stress[0] * laplacian[np.ix_(inside, inside)]
    expected = np.linalg.solve(stiffness, np.full(len(inside), -load))
    deflection = body.displacement[inside, 2]
    # the load stretches the membrane further by (∇w)²/2 ~ 1e-6, against a pre-strain of 0.1
    assert np.abs(deflection - expected).max() <= 1e-4 * np.abs(expected).max()


def matrix_product(A, d):
    x, y = A.createVecs()
    x.setArray(d.ravel())
    A.mult(x, y)
    return y.getArray().copy()


def test_the_assembled_tangent_and_its_diagonal_equal_the_shell(material_name):
    """Assembled from the membrane elements' stiffness matrices: the same sums as the shell's
    product, in another order (round-off only), also where compressed elements make it
    indefinite (the solvers' preconditioners take positive parts there, not this matrix)."""
    rng = np.random.default_rng(len(material_name))
    body = membrane(curved_patch(), all_materials()[material_name])
    body.fix(np.isclose(body.mesh.points[:, 0], 0.0))
    u = 0.02 * rng.normal(size=(body.mesh.n_points, 3))
    shell = body.tangent_operator(u)
    for _ in range(3):
        d = rng.normal(size=u.shape)
        expected = matrix_product(shell, d)
        for fmt in ("aij", "baij"):
            np.testing.assert_allclose(matrix_product(body.assemble_tangent(u, fmt), d), expected, rtol=0,
                                       atol=1e-12 * np.abs(expected).max())
    diagonal = shell.getDiagonal().getArray()
    np.testing.assert_allclose(diagonal, body.assemble_tangent(u, "aij").getDiagonal().getArray(), rtol=1e-12)
    # A fixed vertex's rows: c times the identity's, c = E/(1 − ν²)·t (issue 48 item 8).
    fixed = np.isclose(body.mesh.points[:, 0], 0.0)
    np.testing.assert_allclose(diagonal.reshape(-1, 3)[fixed], E / (1 - NU ** 2) * THICKNESS, rtol=1e-12)


# GAMG is left out: on this sheet its Newton stops with DIVERGED_LINE_SEARCH (reported, not
# hidden; studies/benchmarks/membrane_preconditioners.py).
@pytest.mark.parametrize("preconditioner", ["jacobi", "mg"])
def test_jacobi_and_multigrid_solve_a_membrane_to_the_unpreconditioned_answer(preconditioner):
    reference = pretensioned_sheet(12)
    assert snede.StaticSolver(reference, "newton", rtol=1e-10, preconditioner="none").solve().converged
    body = pretensioned_sheet(12)
    solver = snede.StaticSolver(body, "newton", rtol=1e-10, preconditioner=preconditioner)
    assert solver.preconditioner == preconditioner
    assert solver.solve().converged
    deflection = np.abs(reference.displacement[:, 2]).max()
    assert np.abs(body.displacement - reference.displacement).max() <= 1e-6 * deflection


def test_multigrid_takes_a_wrinkling_membrane():
    """A hollow box's skin held at one end sags under its weight into folds, where compressed
    elements make the tangent indefinite: multigrid over the elements' positive parts converges
    (over the exact element matrices it stopped at once with DIVERGED_LINE_SEARCH), and in
    fewer Newton iterations than no preconditioner."""
    def hanging_skin():
        surface, _ = snede.meshing.boundary_surface(snede.meshing.box((0.4, 0.1, 0.1), (8, 2, 2)))
        body = snede.Body(surface, snede.NeoHookean(1e5, 0.3), thickness=0.001, density=1000.0)
        body.fix(np.isclose(surface.points[:, 0], 0.0))
        body.add_gravity((0.0, 0.0, -9.81))
        return body

    plain = snede.StaticSolver(hanging_skin(), "newton", rtol=1e-6, preconditioner="none").solve()
    body = hanging_skin()
    result = snede.StaticSolver(body, "newton", rtol=1e-6, preconditioner="mg").solve()
    assert plain.converged and result.converged, (plain, result)
    assert result.iterations < plain.iterations
    assert body.displacement[:, 2].min() < -0.1  # it sagged: the folds are there
