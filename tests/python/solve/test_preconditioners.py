"""Preconditioners of the CG (issue 15): the assembled tangent equals the shell's products (the
same element kernels, projected by the constraints) for every material in 2D and 3D, with
fixed and sliding vertices, and after a cut and a refinement; the diagonal the shell gives
Jacobi equals the assembled one; every preconditioner converges to the unpreconditioned
answer on a cantilever, also after a topology change, with GAMG's iteration count nearly
independent of the mesh size (against unpreconditioned CG's, which doubles with each halving)."""
import numpy as np
import pytest
from petsc4py import PETSc

import snede

MATERIALS = {
    "linear": lambda: snede.LinearElastic(1e4, 0.3),
    "stvk": lambda: snede.StVenantKirchhoff(1e4, 0.3),
    "neohookean": lambda: snede.NeoHookean(1e4, 0.3),
    "veronda": lambda: snede.VerondaWestmann(1e4, 0.3, 4.0),
}


def constrained_body(dim, material, rng):
    mesh = snede.meshing.rectangle((1.0, 0.5), (6, 3)) if dim == 2 else snede.meshing.box((1.0, 0.5, 0.5), (4, 2, 2))
    body = snede.Body(mesh, material, thickness=0.01 if dim == 2 else None)
    x = mesh.points
    body.fix(np.isclose(x[:, 0], 0.0))
    body.slide(np.flatnonzero(np.isclose(x[:, 0], 1.0)), rng.normal(size=dim))
    return body


def as_array(vec):
    return vec.getArray().copy()


def shell_product(body, u, d):
    J = body.tangent_operator(u)
    x, y = J.createVecs()
    x.setArray(d.ravel())
    J.mult(x, y)
    return as_array(y)


def assembled_product(body, u, d, fmt):
    A = body.assemble_tangent(u, format=fmt)
    x, y = A.createVecs()
    x.setArray(d.ravel())
    A.mult(x, y)
    return as_array(y)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("name", MATERIALS)
def test_the_assembled_tangent_and_its_diagonal_equal_the_shell(dim, name):
    rng = np.random.default_rng(dim * 10 + len(name))
    body = constrained_body(dim, MATERIALS[name](), rng)
    u = 0.02 * rng.normal(size=(body.mesh.n_points, dim))
    for _ in range(3):
        d = rng.normal(size=u.shape)
        shell = shell_product(body, u, d)
        for fmt in ("aij", "baij"):
            # Sums of the same element contributions in another order: round-off only.
            np.testing.assert_allclose(assembled_product(body, u, d, fmt), shell, rtol=0,
                                       atol=1e-12 * np.abs(shell).max())
    diagonal = as_array(body.tangent_operator(u).getDiagonal())
    np.testing.assert_allclose(diagonal, as_array(body.assemble_tangent(u, "aij").getDiagonal()), rtol=1e-12)
    # A fixed vertex's rows are c times the identity's, c the constraint stiffness (issue 48
    # item 8): E/(1 − ν²)·t in 2D, (λ + 2μ)(|Ω|/cells)^(1/3) in 3D.
    E, nu = 1e4, 0.3
    c = (E / (1 - nu ** 2) * 0.01 if dim == 2 else
         E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) * np.cbrt(0.25 / body.mesh.n_cells))
    fixed = np.isclose(body.mesh.points[:, 0], 0.0)
    np.testing.assert_allclose(diagonal.reshape(-1, dim)[fixed], c, rtol=1e-12)


def test_the_assembled_tangent_follows_a_cut_and_a_refinement():
    rng = np.random.default_rng(4)
    body = constrained_body(3, snede.NeoHookean(1e4, 0.3), rng)
    mesh = body.mesh
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5) & (x[:, 2] < 0.3)))
    body.refine_around((0.75, 0.25, 0.25), 0.1)
    # The larger state inverts some of the small refined elements: both leave them out.
    for size, inverts in ((0.001, False), (0.03, True)):
        u = size * rng.normal(size=(mesh.n_points, 3))
        assert (len(body.inverted_elements(u)) > 0) == inverts
        d = rng.normal(size=u.shape)
        shell = shell_product(body, u, d)
        assert shell.size == 3 * mesh.n_points
        np.testing.assert_allclose(assembled_product(body, u, d, "baij"), shell, rtol=0,
                                   atol=1e-12 * np.abs(shell).max())


def cantilever(n, material=None):
    mesh = snede.meshing.box((1.0, 0.2, 0.2), (5 * n, n, n))
    body = snede.Body(mesh, material or snede.LinearElastic(1e5, 0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


@pytest.mark.parametrize("preconditioner", ["jacobi", "gamg", "icc", "sor"])
def test_each_preconditioner_converges_to_the_unpreconditioned_answer_also_after_a_cut(preconditioner):
    plain, body = cantilever(3), cantilever(3)
    assert snede.StaticSolver(plain, "cg", rtol=1e-10).solve().converged
    solver = snede.StaticSolver(body, "cg", rtol=1e-10, preconditioner=preconditioner)
    assert solver.preconditioner == preconditioner
    result = solver.solve()
    assert result.converged, result
    scale = np.abs(plain.displacement).max()
    np.testing.assert_allclose(body.displacement, plain.displacement, atol=1e-7 * scale)
    # A cut through the lower half near the support: a new mesh size, a new assembled matrix.
    for b in (plain, body):
        b.mesh.dissect(b.mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.2) & (x[:, 2] <= 0.1 + 1e-12)))
    assert snede.StaticSolver(plain, "cg", rtol=1e-10).solve().converged
    after = solver.solve()
    assert after.converged, after
    np.testing.assert_allclose(body.displacement, plain.displacement, atol=1e-7 * np.abs(plain.displacement).max())


def test_gamg_iterations_stay_nearly_flat_while_plain_cg_doubles_with_each_halving():
    counts = {}
    for preconditioner in ("none", "gamg"):
        counts[preconditioner] = []
        for n in (2, 4, 8):  # h, h/2, h/4: 240 to 15 360 tetrahedra
            result = snede.StaticSolver(cantilever(n), "cg", rtol=1e-8, preconditioner=preconditioner).solve()
            assert result.converged, (preconditioner, n, result)
            counts[preconditioner].append(result.iterations)
    none, gamg = counts["none"], counts["gamg"]
    assert none[2] > 3 * none[0], counts  # CG's count grows like 1/h
    assert gamg[2] <= 2 * gamg[0] and gamg[2] < none[2] / 10, counts


def test_the_preconditioner_comes_from_the_options_and_the_command_line_wins():
    body = cantilever(2)
    assert snede.StaticSolver(body, "cg").preconditioner == "none"
    assert snede.StaticSolver(body, "cg", petsc_options={"pc_type": "gamg"}).preconditioner == "gamg"
    PETSc.Options().setValue("-pcwins_pc_type", "jacobi")
    try:
        solver = snede.StaticSolver(body, "cg", preconditioner="gamg", options_prefix="pcwins_")
        assert solver.preconditioner == "jacobi"
        assert solver.solve().converged
    finally:
        PETSc.Options().delValue("-pcwins_pc_type")


@pytest.mark.parametrize("cells_per_side, chosen", [(2, "none"), (6, "mg")])
def test_pc_type_auto_on_the_command_line_is_resolved_as_the_argument_is(cells_per_side, chosen):
    """-static_pc_type auto reached PETSc, which knows no such PC: 'Unable to find requested PC
    type auto' (issue 38 item 5)."""
    body = snede.Body(snede.meshing.box((1.0, 1.0, 1.0), (cells_per_side,) * 3), snede.NeoHookean(1e6, 0.3), density=1000.0)
    body.fix(np.isclose(body.mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    PETSc.Options().setValue("-autowins_pc_type", "auto")
    try:
        solver = snede.StaticSolver(body, "newton", preconditioner="jacobi", options_prefix="autowins_")
        assert solver.preconditioner == chosen and solver.ksp.getPC().getType() == chosen
        assert solver.solve().converged
    finally:
        PETSc.Options().delValue("-autowins_pc_type")


@pytest.mark.parametrize("damping", ["nan", "inf", "0", "-1"])
def test_a_line_search_damping_that_is_not_positive_and_finite_is_refused(damping):
    """A NaN damping made PETSc's backtracking line search loop for ever (issue 38 item 5)."""
    with pytest.raises(ValueError, match="snes_linesearch_damping must be positive and finite"):
        snede.StaticSolver(cantilever(2), "newton", petsc_options={"snes_linesearch_damping": damping})


def test_bad_preconditioners_are_refused():
    body = cantilever(2)
    with pytest.raises(ValueError, match="nonlinear CG"):
        snede.StaticSolver(body, "ncg", preconditioner="gamg")
    with pytest.raises(ValueError, match="PC type name"):
        snede.StaticSolver(body, "cg", preconditioner="")
    with pytest.raises(snede.PetscError, match="nosuchpc"):
        snede.StaticSolver(body, "cg", preconditioner="nosuchpc")
    with pytest.raises(ValueError, match="format must be"):
        body.assemble_tangent(format="dense")


def test_an_edit_that_keeps_the_vertex_count_still_rebuilds_the_assembled_tangent():
    # A flip changes the sparsity without changing the sizes: the solver must notice it.
    mesh = snede.meshing.rectangle((1.0, 0.2), (10, 2))
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3), thickness=0.01)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81))
    solver = snede.StaticSolver(body, "cg", rtol=1e-10, preconditioner="gamg")
    assert solver.solve().converged
    cells = mesh.cells.copy()
    assert mesh.flip_edge(*interior_edge(mesh))
    assert not np.array_equal(np.sort(mesh.cells, axis=1), np.sort(cells, axis=1))
    after = solver.solve()
    assert after.converged, after
    carried = body.displacement.copy()
    body.displacement = np.zeros_like(carried)
    assert snede.StaticSolver(body, "cg", rtol=1e-10, options_prefix="plain_").solve().converged
    np.testing.assert_allclose(carried, body.displacement, atol=1e-7 * np.abs(carried).max())


def interior_edge(mesh):
    """An edge shared by two triangles whose flip is allowed (a convex quadrilateral)."""
    count = {}
    for t in mesh.cells:
        for k in range(3):
            edge = tuple(sorted((int(t[k]), int(t[(k + 1) % 3]))))
            count[edge] = count.get(edge, 0) + 1
    x = mesh.points
    for (a, b), n in count.items():
        if n == 2 and 0.3 < x[a, 0] < 0.7 and x[a, 0] != x[b, 0] and x[a, 1] != x[b, 1]:
            return a, b  # a diagonal of a grid square
    raise AssertionError("no interior diagonal")


@pytest.mark.parametrize("preconditioner", ["jacobi", "gamg", "icc"])
def test_the_stopping_test_sees_the_true_residual_not_the_preconditioned_one(preconditioner):
    # CG hands its convergence test the preconditioned norm by default; snede's criterion is on
    # the equilibrium residual. Before, a 2D needle solve with GAMG stopped on ‖B r‖ and was
    # then reported NOT converged (residual above tolerance at the final state).
    mesh = snede.meshing.rectangle((1.0, 0.2), (20, 4))
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3), thickness=0.01)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81))
    result = snede.StaticSolver(body, "cg", rtol=1e-6, preconditioner=preconditioner).solve()
    assert result.converged, result
    # The last norm CG reported is the residual recomputed at the final state, up to the drift
    # of CG's recursive residual (measured here: under 1% with jacobi and icc, 14% with GAMG's
    # large corrections); the preconditioned norms it reported before were 0.46× and 2.2× the
    # true residual for two of the three on this sheet.
    assert result.residual_history[-1] == pytest.approx(result.residual_norm, rel=0.25)


@pytest.mark.parametrize("options", [{}, {"snes_lag_preconditioner": 2}], ids=["refilled", "lagged"])
def test_newton_with_gamg_converges_before_and_after_a_refinement(options):
    body = cantilever(2, snede.NeoHookean(1e5, 0.3))
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner="gamg", petsc_options=options)
    first = solver.solve()
    assert first.converged, first
    body.refine_around((0.5, 0.1, 0.1), 0.05)
    after = solver.solve()
    assert after.converged, after
    carried = body.displacement.copy()
    body.displacement = np.zeros_like(carried)
    plain = snede.StaticSolver(body, "newton", rtol=1e-8, options_prefix="plain_newton_").solve()
    assert plain.converged, plain
    np.testing.assert_allclose(carried, body.displacement, atol=1e-6 * np.abs(carried).max())


@pytest.mark.parametrize("method", ["newton", "cg"])
@pytest.mark.parametrize("preconditioner", ["none", "jacobi", "mg", "gamg"])
def test_sliding_vertices_stay_on_their_lines_with_every_preconditioner(preconditioner, method):
    """A linear box held at x = 0 whose 49 vertices at x = 1 slide along random directions:
    a preconditioner that is not projected gave CG iterates off the lines (Jacobi: Newton
    stopped with DIVERGED_LINE_SEARCH; mg took 39 iterations of this linear problem; linear CG
    ended DIVERGED_RESIDUAL_ABOVE_TOLERANCE). The step is projected: every preconditioner
    converges (Newton in a few iterations) to the same answer."""
    rng = np.random.default_rng(0)
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (6, 6, 6))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3))
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    sliding = np.flatnonzero(np.isclose(mesh.points[:, 0], 1.0))
    directions = rng.standard_normal((len(sliding), 3))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    for vertex, direction in zip(sliding, directions):
        body.slide([vertex], direction)
    body.add_gravity((0.0, 0.0, -9.81))
    result = snede.StaticSolver(body, method, rtol=1e-8, preconditioner=preconditioner).solve()
    assert result.converged and (method == "cg" or result.iterations <= 6), result
    u = body.displacement[sliding]
    along = np.einsum("ij,ij->i", u, directions)
    assert np.abs(u - along[:, None] * directions).max() <= 1e-12 * np.abs(u).max()
    residual = body.external_forces() + body.internal_forces(body.displacement)
    assert np.abs(np.einsum("ij,ij->i", residual[sliding], directions)).max() <= 1e-6 * np.abs(body.external_forces()).max()
