"""The static solvers do not depend on the units, whatever the preconditioner (issue 48 item 8).

Every solve divides its system by the force scale E·H², and the constrained directions carry a
stiffness c of the body's own units (J = P K P + c (I − P), F = P∇Π + c (I − P)(u − ū)). With
c = 1 they were 1/(E·h) times softer than the rest of the scaled system: from E = 1e13 Pa the
Chebyshev smoothers of 'mg' estimated their interval from the constrained rows alone, the
preconditioner was indefinite and Newton stopped with DIVERGED_LINE_SEARCH (linear CG with
DIVERGED_INDEFINITE_PC); GAMG's estimate broke down from E = 1e200 (PETSc error 77, "Computed
maximum singular value as zero"); a body in millimetres reached that 1000 times sooner.

The displacements are compared with a tolerance derived from the stopping rule: a solve stops
with ‖r‖ ≤ 2·tolerance (StaticSolver's allowance for round-off), so its displacement is within
2·tolerance / λ_min of the exact one, λ_min the smallest eigenvalue of the tangent on the free
motions at the solution; loads scaled by s = E/1e5 (and by L² for lengths L times longer)
scale both the tolerance and the stiffness alike.
"""
import numpy as np
import pytest

import snede
from solve_scenes import as_dense

REFERENCE_YOUNG = 1e5
YOUNGS = [10.0 ** k for k in (5, 10, 15, 20, 50, 150)]
RTOL = 1e-8


def cantilever(young, material=snede.NeoHookean, length=1.0):
    """A 1 × 0.2 × 0.2 m beam (lengths × `length`) fixed at x = 0, sagging under gravity scaled
    by E and by 1/length: the same strains, so the displacement times `length`, at every scale."""
    mesh = snede.meshing.box((length, 0.2 * length, 0.2 * length), (10, 2, 2))
    body = snede.Body(mesh, material(young, 0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81 * young / REFERENCE_YOUNG / length))
    return body


def sliding_box(young):
    """A neo-Hookean 1 × 0.5 × 0.5 m box fixed at x = 0, each vertex at x = 1 sliding along its
    own oblique line, sagging under 10 g scaled by E (by 0.4 m); and the allowed motions' basis
    (one column per free component, one per sliding vertex along its line)."""
    mesh = snede.meshing.box((1.0, 0.5, 0.5), (8, 4, 4))
    body = snede.Body(mesh, snede.NeoHookean(young, 0.3), density=1000.0)
    x = mesh.points
    fixed, sliding = np.isclose(x[:, 0], 0.0), np.isclose(x[:, 0], 1.0)
    body.fix(fixed)
    directions = np.random.default_rng(3).normal(size=(np.count_nonzero(sliding), 3))
    for vertex, direction in zip(np.flatnonzero(sliding), directions):
        body.slide([vertex], direction)
    body.add_gravity((0.0, 0.0, -98.1 * young / REFERENCE_YOUNG))
    columns = [np.eye(3 * len(x))[:, 3 * v + k] for v in np.flatnonzero(~fixed & ~sliding) for k in range(3)]
    for vertex, direction in zip(np.flatnonzero(sliding), directions):
        column = np.zeros(3 * len(x))
        column[3 * vertex:3 * vertex + 3] = direction / np.linalg.norm(direction)
        columns.append(column)
    return body, np.array(columns).T


def cantilever_motions(body):
    free = np.flatnonzero(np.repeat(~np.isclose(body.mesh.points[:, 0], 0.0), 3))
    return np.eye(3 * body.mesh.n_points)[:, free]


def smallest_stiffness(body, motions):
    """λ_min of the tangent on the allowed motions (orthonormal columns) at the body's state."""
    J = as_dense(body.assemble_tangent(format="aij"))
    return np.linalg.eigvalsh(motions.T @ J @ motions)[0]


def reference(method, material):
    body = cantilever(REFERENCE_YOUNG, material)
    result = snede.StaticSolver(body, method, rtol=RTOL, preconditioner="none").solve()
    assert result.converged, result
    return body, result, smallest_stiffness(body, cantilever_motions(body))


@pytest.fixture(scope="module")
def sliding_reference():
    body, motions = sliding_box(REFERENCE_YOUNG)
    result = snede.StaticSolver(body, "newton", rtol=RTOL, preconditioner="none").solve()
    assert result.converged, result
    return body, result, smallest_stiffness(body, motions)


@pytest.fixture(scope="module")
def newton_reference():
    return reference("newton", snede.NeoHookean)


@pytest.fixture(scope="module")
def cg_reference():
    return reference("cg", snede.LinearElastic)


def check_same_displacement(body, result, load_scale, length, ref):
    ref_body, ref_result, lambda_min = ref
    assert result.converged, result
    bound = 2 * (result.tolerance / load_scale + ref_result.tolerance) / lambda_min
    error = np.linalg.norm(body.displacement / length - ref_body.displacement)
    assert error <= bound, (error, bound, result)
    # The bound is meaningful: far below the displacement itself.
    assert bound < 1e-3 * np.linalg.norm(ref_body.displacement)


@pytest.mark.parametrize("preconditioner", ["mg", "none", "gamg", "jacobi"])
@pytest.mark.parametrize("young", YOUNGS)
def test_newton_on_a_neo_hookean_cantilever_does_not_depend_on_the_modulus(newton_reference, young, preconditioner):
    body = cantilever(young)
    result = snede.StaticSolver(body, "newton", rtol=RTOL, preconditioner=preconditioner).solve()
    check_same_displacement(body, result, young / REFERENCE_YOUNG, 1.0, newton_reference)


@pytest.mark.parametrize("preconditioner", ["mg", "gamg"])
@pytest.mark.parametrize("young", YOUNGS + [1e200, 1e300])
def test_linear_cg_does_not_depend_on_the_modulus(cg_reference, young, preconditioner):
    body = cantilever(young, snede.LinearElastic)
    result = snede.StaticSolver(body, "cg", rtol=RTOL, preconditioner=preconditioner).solve()
    check_same_displacement(body, result, young / REFERENCE_YOUNG, 1.0, cg_reference)


# Millimetres (lengths 1000 times larger) made the constrained block 1000 times softer still:
# 'mg' failed from E = 1e10 there. Kilometres the other way (from 1e16).
@pytest.mark.parametrize("preconditioner", ["mg", "gamg"])
@pytest.mark.parametrize("length", [1e3, 1e-3])
@pytest.mark.parametrize("young", [1e5, 1e10, 1e20])
def test_newton_does_not_depend_on_the_length_unit(newton_reference, young, length, preconditioner):
    body = cantilever(young, length=length)
    result = snede.StaticSolver(body, "newton", rtol=RTOL, preconditioner=preconditioner).solve()
    check_same_displacement(body, result, young / REFERENCE_YOUNG * length ** 2, length, newton_reference)


# Vertices sliding along oblique lines couple the constrained directions' stiffness c to the
# free ones through the diagonal blocks. GAMG converged here only while c was far below K's
# diagonal (E ≳ 100 Pa with c = 1); at c ~ K its Chebyshev bounds, kept from the first Newton
# iteration's set-up, fell below the stiffened tangent's spectrum and the V-cycle turned
# indefinite (static_solver.cpp, configure_gamg).
@pytest.mark.parametrize("preconditioner", ["mg", "none", "gamg", "jacobi"])
@pytest.mark.parametrize("young", [1e-2, 1e5, 1e15, 1e150])
def test_newton_with_oblique_sliding_vertices_does_not_depend_on_the_modulus(sliding_reference, young,
                                                                             preconditioner):
    body, _ = sliding_box(young)
    result = snede.StaticSolver(body, "newton", rtol=RTOL, preconditioner=preconditioner).solve()
    check_same_displacement(body, result, young / REFERENCE_YOUNG, 1.0, sliding_reference)
