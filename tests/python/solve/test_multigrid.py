"""Geometric multigrid on the bisection hierarchy (preconditioner "mg", issue 15).

Checked against independent facts: on nested conforming meshes the linear-elastic stiffness
of a coarse level is exactly the Galerkin product IᵀKI of the finer one (P1 spaces are
nested and the strains are constant per element), so the level operators and the
interpolation are tested together to round-off; the CG iteration count stays bounded over
three halvings of h while unpreconditioned CG's doubles each time; every solve reaches the
unpreconditioned answer (also for Newton on neo-Hookean, after a refinement, and on a
locally refined mesh); misuse raises ValueError naming what to do."""
import numpy as np
import pytest
from petsc4py import PETSc

import snede
from solve_scenes import as_dense, relative_difference
from solve_scenes import solve_from_rest as solve


def cantilever(dim, levels, material=None):
    """A beam fixed at x = 0 under gravity, refined `levels` times by bisection from a coarse
    grid of 4 squares (cubes)."""
    if dim == 2:
        mesh = snede.meshing.rectangle((0.4, 0.1), (4, 1))
    else:
        mesh = snede.meshing.box((0.4, 0.1, 0.1), (4, 1, 1))
    if levels:
        mesh.refine_uniform(levels)
    body = snede.Body(mesh, material or snede.LinearElastic(1e5, 0.3), density=1000.0,
                      thickness=0.01 if dim == 2 else None)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81) if dim == 2 else (0.0, 0.0, -9.81))
    return body


@pytest.mark.parametrize("dim", [2, 3])
def test_iterations_stay_bounded_over_three_refinement_levels(dim):
    # h, h/2, h/4: 2 bisections halve h in 2D, 3 in 3D.
    counts, plain_counts = [], []
    for k in range(3):
        body = cantilever(dim, dim * (k + 1))
        solver, result, u = solve(body, preconditioner="mg")
        assert result.converged, result.reason
        assert len(solver.multigrid_levels) == k + 2  # one level per halving, down to the grid
        _, plain, reference = solve(body)
        assert plain.converged
        assert relative_difference(u, reference) < 1e-6
        counts.append(result.iterations)
        plain_counts.append(plain.iterations)
    # Unpreconditioned CG needs more iterations as h shrinks (the problem gets harder) ...
    assert plain_counts[2] > 1.7 * plain_counts[0], plain_counts
    # ... multigrid's count stays within the factor 1.5 from h to h/4.
    assert max(counts) <= 1.5 * min(counts), counts
    assert max(counts) < plain_counts[0], (counts, plain_counts)


def dense(operator, n):
    """The matrix of a petsc4py operator, column by column from its products."""
    x, y = operator.createVecs()
    columns = []
    for j in range(n):
        x.set(0.0)
        x.setValue(j, 1.0)
        x.assemble()
        operator.mult(x, y)
        columns.append(y.getArray().copy())
    return np.array(columns).T


@pytest.mark.parametrize("dim", [2, 3])
def test_coarse_operators_are_galerkin_products_of_the_finer_ones(dim):
    body = cantilever(dim, 3 * dim)
    solver = snede.StaticSolver(body, "cg", preconditioner="mg")
    pc = solver.ksp.getPC()
    n_levels = pc.getMGLevels()
    assert n_levels == len(solver.multigrid_levels) == 4
    # Before any solve every level applies its unscaled tangent J = PKP + c (I − P), c the
    # level's constraint stiffness: E/(1 − ν²)·t in 2D, (λ + 2μ)(|Ω|/cells)^(1/3) in 3D (the
    # levels nest: |Ω| is the body's).
    E, nu = 1e5, 0.3
    lame_lambda, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    volume = 0.4 * 0.1 * 0.1
    c = [E / (1 - nu ** 2) * 0.01 if dim == 2 else (lame_lambda + 2 * mu) * np.cbrt(volume / cells)
         for cells in solver.multigrid_levels]
    operators = [pc.getMGSmoother(level).getOperators()[0] for level in range(1, n_levels - 1)]
    operators.insert(0, pc.getMGCoarseSolve().getOperators()[0])
    operators.append(body.tangent_operator())
    matrices = [dense(A, A.getSize()[0]) for A in operators]
    for level in range(1, n_levels):
        interpolation = as_dense(pc.getMGInterpolation(level))
        fine, coarse = matrices[level], matrices[level - 1]
        assert interpolation.shape == (fine.shape[0], coarse.shape[0])
        # A fixed coarse vertex has a zero column: a correction never moves a support.
        free = np.abs(interpolation).sum(axis=0) > 0
        assert 0 < np.count_nonzero(~free) < len(free)
        galerkin = interpolation.T @ fine @ interpolation
        scale = np.abs(coarse).max()
        assert np.abs(coarse[np.ix_(free, free)] - galerkin[np.ix_(free, free)]).max() < 1e-12 * scale
        # Fixed coarse dofs: c (I − P), decoupled from the rest.
        np.testing.assert_allclose(coarse[np.ix_(~free, ~free)], c[level - 1] * np.eye(np.count_nonzero(~free)),
                                   rtol=1e-12, atol=0)
        assert not coarse[np.ix_(~free, free)].any()


def test_newton_on_neo_hookean_reaches_the_unpreconditioned_answer_also_lagged():
    body = cantilever(3, 6, snede.NeoHookean(1e5, 0.3))
    _, reference_result, reference = solve(body, "newton", rtol=1e-9)
    assert reference_result.converged
    for options in ({}, {"snes_lag_preconditioner": 2}):
        solver, result, u = solve(body, "newton", rtol=1e-9, preconditioner="mg", petsc_options=options)
        assert result.converged, (options, result.reason)
        assert result.linear_iterations < reference_result.linear_iterations
        assert relative_difference(u, reference) < 1e-6
    # The finest level is the body's mesh; the deflection is large (the state matters).
    assert solver.multigrid_levels[-1] == body.mesh.n_cells
    assert np.abs(reference).max() > 0.05


def test_levels_follow_a_refinement_between_solves():
    body = cantilever(3, 6)
    solver, first, _ = solve(body, preconditioner="mg")
    before = solver.multigrid_levels
    body.refine_around((0.3, 0.05, 0.05), 0.004)
    result = solver.solve()
    assert result.converged, result.reason
    after = solver.multigrid_levels
    assert after[-1] == body.mesh.n_cells > before[-1]
    _, plain, reference = solve(body)
    body.displacement = np.zeros_like(body.displacement)
    assert snede.StaticSolver(body, "cg", rtol=1e-8, preconditioner="mg").solve().converged
    assert relative_difference(body.displacement, reference) < 1e-6


def test_a_locally_refined_mesh_gets_coarse_levels_and_few_iterations():
    body = cantilever(3, 3)
    body.refine_around((0.2, 0.05, 0.05), 0.004)  # deep refinement in one spot only
    solver, result, u = solve(body, preconditioner="mg")
    assert result.converged, result.reason
    levels = solver.multigrid_levels
    assert len(levels) >= 3 and levels == sorted(levels) and levels[0] == 24
    _, plain, reference = solve(body)
    assert relative_difference(u, reference) < 1e-6
    assert result.iterations < plain.iterations / 4


def test_pc_mg_levels_limits_the_levels_to_the_finest():
    body = cantilever(3, 6)
    all_levels = snede.StaticSolver(body, "cg", preconditioner="mg").multigrid_levels
    solver, result, _ = solve(body, preconditioner="mg", petsc_options={"pc_mg_levels": 2})
    assert result.converged
    assert solver.multigrid_levels == all_levels[-2:]


def test_mg_chosen_on_the_command_line():
    body = cantilever(2, 4)
    options = PETSc.Options()
    options["static_pc_type"] = "mg"
    try:
        solver, result, _ = solve(body)
    finally:
        options.delValue("static_pc_type")
    assert solver.preconditioner == "mg" and result.converged


def test_misuse_is_refused_with_a_reason():
    body = cantilever(3, 3)
    for options, message in (({"pc_mg_levels": 1}, "at least 2"), ({"pc_mg_levels": 9}, "gives [0-9]+ levels"),
                             ({"pc_mg_levels": "two"}, "integer"), ({"pc_mg_galerkin": "both"}, "chooses its coarse")):
        with pytest.raises(ValueError, match=message):
            snede.StaticSolver(body, "cg", preconditioner="mg", petsc_options=options)
    with pytest.raises(ValueError, match="ncg"):
        snede.StaticSolver(body, "ncg", preconditioner="mg")


def test_an_unrefined_mesh_is_coarsened_on_a_grid_instead():
    # Without bisection levels (tests/python/solve/test_multigrid_any_mesh.py covers them).
    unrefined = cantilever(3, 0)
    solver = snede.StaticSolver(unrefined, "cg", preconditioner="mg")
    assert solver.multigrid_source == "grid"
    assert solver.solve().converged


def test_levels_follow_constraints_changed_between_solves():
    # A needle's stick-slip fixes, releases and slides vertices between solves: stale
    # projections on the coarse levels made the cycle indefinite (DIVERGED_INDEFINITE_PC).
    body = cantilever(3, 6)
    solver, first, _ = solve(body, preconditioner="mg")
    assert first.converged
    x = body.mesh.points
    tip = np.flatnonzero(np.isclose(x[:, 0], 0.4))
    body.slide(tip[::2], (0.0, 0.0, 1.0))
    body.fix(tip[1::2])
    result = solver.solve()
    assert result.converged, result.reason
    _, plain, reference = solve(body)
    body.displacement = np.zeros_like(body.displacement)
    assert snede.StaticSolver(body, "cg", rtol=1e-8, preconditioner="mg").solve().converged
    assert relative_difference(body.displacement, reference) < 1e-6
    assert result.iterations < plain.iterations / 3


def test_newton_with_mg_continues_after_a_refinement():
    # After a mesh change the SNES gets a new shell DM; PCMG must not try to coarsen it.
    body = cantilever(3, 3, snede.NeoHookean(1e5, 0.3))
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner="mg")
    assert solver.solve().converged
    body.refine_around((0.3, 0.05, 0.05), 0.01)
    result = solver.solve()
    assert result.converged, result.reason
    _, _, reference = solve(body, "newton", rtol=1e-8)
    body.displacement = np.zeros_like(body.displacement)
    assert snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner="mg").solve().converged
    assert relative_difference(body.displacement, reference) < 1e-6


def test_chebyshev_bounds_from_the_first_solve_serve_later_ones():
    # Later set-ups reuse the first solve's eigenvalue estimates (no estimate's products):
    # the answers stay those of an unpreconditioned solve, the iteration counts comparable.
    body = cantilever(3, 6)
    solver, first, _ = solve(body, preconditioner="mg")
    levels = len(solver.multigrid_levels)
    x = body.mesh.points
    body.fix(np.isclose(x[:, 0], 0.4))  # new constraints: levels reconfigured with the same count
    result = solver.solve()
    assert result.converged, result.reason
    assert len(solver.multigrid_levels) == levels
    reused = body.displacement.copy()
    _, plain, reference = solve(body)
    assert relative_difference(reused, reference) < 1e-6
    body.displacement = np.zeros_like(body.displacement)
    fresh = snede.StaticSolver(body, "cg", rtol=1e-8, preconditioner="mg").solve()
    assert fresh.converged
    assert relative_difference(body.displacement, reference) < 1e-6
    assert result.iterations <= 1.5 * fresh.iterations


def test_bisection_levels_become_positive_definite_when_the_injected_state_makes_them_indefinite():
    """A neo-Hookean beam (ν = 0.49) sagging about a quarter of its length: a coarse level
    linearised at the injected fine state is indefinite there (CG met negative curvature in the
    preconditioner and Newton ended DIVERGED_LINE_SEARCH); the levels are then linearised at
    rest, and the solve converges to the unpreconditioned answer."""
    import warnings

    def beam():
        mesh = snede.meshing.box((1.0, 0.4, 0.4), (5, 2, 2))
        mesh.refine_uniform(3)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", snede.LockingWarning)
            body = snede.Body(mesh, snede.NeoHookean(1e4, 0.49), density=30.0)
        body.fix(np.isclose(mesh.points[:, 0], 0.0))
        body.add_gravity((0.0, 0.0, -9.81))
        return body

    reference, body = beam(), beam()
    assert snede.StaticSolver(reference, "newton", rtol=1e-8, preconditioner="none").solve().converged
    assert np.abs(reference.displacement).max() > 0.2
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner="mg")
    result = solver.solve()
    assert solver.multigrid_source == "bisection" and result.converged, result
    assert np.abs(body.displacement - reference.displacement).max() <= 1e-6 * np.abs(reference.displacement).max()
