"""Manufactured-solution convergence of the linear elastic P1 solution (as scikit-fem's
tests/test_convergence.py does): a smooth displacement u*, the body force f = −div σ(u*)
that makes it an equilibrium, f applied as consistent nodal loads, the boundary fixed at u*;
the fitted log-log slopes of the L2 and H1-seminorm errors must be those of P1 elements,
2 and 1. A wrong plane-stress λ*, thickness, sign or load assembly leaves an error that does
not go to zero with h, and the fitted rates collapse.

Everything on the test side is numpy from mesh.points and mesh.cells: collapsed (Duffy)
Gauss-Legendre rules on the reference simplex, P1 hat functions, analytic f and ∇u*.
"""
import time

import numpy as np
import pytest

import snede

E, NU = 1.0e4, 0.3
AMPLITUDE = 1e-3  # metres, on a unit square / cube: small strain, and the theory is linear anyway
THICKNESS = 0.01

# u*(x) = AMPLITUDE Σ a sin(k·x + c): plane waves, one mostly longitudinal (a ∥ k) and the
# others mostly transverse, so both μ and λ enter f. For one wave
# ∇u = a ⊗ k cos(k·x + c), Δu = −|k|² u, ∇(div u) = −(a·k) k sin(k·x + c), and
# f = −div σ = −[μ Δu + (λ + μ) ∇(div u)] = [μ |k|² a + (λ + μ)(a·k) k] sin(k·x + c).
WAVES = {
    2: [((1.0, 0.5), np.pi * np.array([1.0, 0.5]), 0.3),
        ((-0.4, 1.0), np.pi * np.array([-0.7, 1.2]), 1.1)],
    3: [((1.0, 0.4, -0.3), np.pi * np.array([1.0, 0.5, 0.3]), 0.3),
        ((-0.5, 1.0, 0.2), np.pi * np.array([-0.6, 0.9, 0.4]), 1.1),
        ((0.3, -0.2, 1.0), np.pi * np.array([0.4, -0.3, 1.1]), -0.7)],
}
# Transverse waves only (a ⊥ k): div u* = 0, so f = μ |k|² a sin(k·x + c) does not grow with λ
# and a formulation free of volumetric locking converges at the same rates as ν → ½ (the
# classic locking test), where P1 locks.
SOLENOIDAL_WAVES = [((0.5, -1.0, 0.0), np.pi * np.array([1.0, 0.5, 0.3]), 0.3),
                    ((1.0, 0.0, 1.5), np.pi * np.array([-0.6, 0.9, 0.4]), 1.1),
                    ((0.3, 0.4, 0.0), np.pi * np.array([0.4, -0.3, 1.1]), -0.7)]
# Divisions per side: 2D rectangles of 2n² triangles, 3D boxes of 6n³ tetrahedra.
DIVISIONS = {2: [8, 16, 32, 64], 3: [4, 8, 12, 16]}


def exact(x, dim, waves=None):
    """u*, ∇u* (∂u_i/∂x_j) at points x (..., dim)."""
    u = np.zeros(x.shape)
    grad = np.zeros(x.shape + (dim,))
    for a, k, c in waves or WAVES[dim]:
        a = AMPLITUDE * np.asarray(a)
        phase = x @ k + c
        u += np.sin(phase)[..., None] * a
        grad += np.cos(phase)[..., None, None] * np.outer(a, k)
    return u, grad


def body_force(x, dim, lam, mu, waves=None):
    f = np.zeros(x.shape)
    for a, k, c in waves or WAVES[dim]:
        a = AMPLITUDE * np.asarray(a)
        f += np.sin(x @ k + c)[..., None] * (mu * (k @ k) * a + (lam + mu) * (a @ k) * k)
    return f


def simplex_rule(dim, n):
    """Collapsed Gauss-Legendre rule with n points per direction on the reference simplex
    {ξ ≥ 0, Σξ ≤ 1}: points (q, dim) and weights (q,) summing to 1/dim!. Exact for
    polynomials of degree 2n − dim."""
    g, w = np.polynomial.legendre.leggauss(n)
    g, w = (g + 1) / 2, w / 2
    if dim == 2:
        s, t = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
        ws, wt = (a.ravel() for a in np.meshgrid(w, w, indexing="ij"))
        return np.column_stack([s, t * (1 - s)]), ws * wt * (1 - s)
    s, t, r = (a.ravel() for a in np.meshgrid(g, g, g, indexing="ij"))
    ws, wt, wr = (a.ravel() for a in np.meshgrid(w, w, w, indexing="ij"))
    return np.column_stack([s, t * (1 - s), r * (1 - s) * (1 - t)]), ws * wt * wr * (1 - s) ** 2 * (1 - t)


def test_simplex_rule_is_exact_for_monomials():
    for dim, factorial in ((2, 2), (3, 6)):
        xi, w = simplex_rule(dim, 4)
        assert w.sum() == pytest.approx(1 / factorial, rel=1e-14)
        # ∫ ξ1^a ξ2^b (ξ3^c) over the reference simplex = a! b! c! / (a + b + c + dim)!
        assert np.sum(w * xi[:, 0] ** 2 * xi[:, 1] ** 3) == pytest.approx(
            2 * 6 / np.prod(np.arange(1, 5 + dim + 1)), rel=1e-12)


def solve_and_measure(dim, n, lam_star, mu, formulation="p1", poisson=NU, waves=None):
    """The solution on an n-per-side mesh of the unit square/cube: h, its L2 and H1-seminorm
    errors against u* (both from the P1 interpolant of the vertex values, the unknowns of
    every formulation), and the H1 seminorm of u* (for scale)."""
    if dim == 2:
        mesh = snede.meshing.rectangle((1.0, 1.0), (n, n))
        body = snede.Body(mesh, snede.LinearElastic(E, poisson), thickness=THICKNESS, formulation=formulation)
        measure = THICKNESS  # the sheet's element measures are area × thickness
    else:
        mesh = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))
        body = snede.Body(mesh, snede.LinearElastic(E, poisson), formulation=formulation)
        measure = 1.0
    points, cells = mesh.points, mesh.cells
    corners = points[cells]  # (cells, dim+1, dim)
    jac = np.transpose(corners[:, 1:] - corners[:, :1], (0, 2, 1))  # x = x0 + J ξ
    det = np.linalg.det(jac)
    assert np.all(det > 0)
    # Gradients of the hat functions (constant per cell): ∇φ_i = J^-T ∇_ξ φ_i.
    ref_grad = np.vstack([-np.ones(dim), np.eye(dim)])  # (dim+1, dim)
    hat_grad = ref_grad @ np.linalg.inv(jac)  # (cells, dim+1, dim)

    xi, w = simplex_rule(dim, 4)
    hats = np.column_stack([1 - xi.sum(axis=1), xi])  # (q, dim+1)
    x = np.einsum("qa,cad->cqd", hats, corners)  # quadrature points (cells, q, dim)
    dx = det[:, None] * w[None, :]  # (cells, q)

    # Consistent nodal loads F_a = ∫ f φ_a (× thickness in plane stress): Π = Π_int − F·u.
    f = body_force(x, dim, lam_star, mu, waves)
    loads = np.zeros((mesh.n_points, dim))
    np.add.at(loads, cells, measure * np.einsum("cq,qa,cqd->cad", dx, hats, f))
    body.add_nodal_force(np.arange(mesh.n_points), loads)
    boundary = np.unique(mesh.boundary_faces())
    body.fix(boundary, exact(points[boundary], dim, waves)[0])

    result = snede.StaticSolver(body, "cg", rtol=1e-10, preconditioner="mg" if formulation != "p1" else None).solve()
    assert result.converged, result
    uh = body.displacement
    u_star, grad_star = exact(x, dim, waves)
    uh_at_q = np.einsum("qa,cad->cqd", hats, uh[cells])
    grad_h = np.einsum("cai,caj->cij", uh[cells], hat_grad)  # (cells, dim, dim), ∂u_i/∂x_j
    l2 = np.sqrt(np.sum(dx * np.sum((uh_at_q - u_star) ** 2, axis=-1)))
    h1 = np.sqrt(np.sum(dx * np.sum((grad_h[:, None] - grad_star) ** 2, axis=(-2, -1))))
    h1_exact = np.sqrt(np.sum(dx * np.sum(grad_star**2, axis=(-2, -1))))
    # The nodal values of u* are on the boundary exactly; inside they are only approximated.
    np.testing.assert_array_equal(uh[boundary], exact(points[boundary], dim, waves)[0])
    return 1.0 / n, l2, h1, h1_exact


def fitted_rate(h, error):
    return np.polyfit(np.log(h), np.log(error), 1)[0]


# (dim, formulation, ν): P1 at a compressible ν; the smoothed formulation there and, in 3D, at
# ν = 0.499 on the solenoidal waves, where P1 locks and a locking-free formulation keeps its
# rates (issue 35).
CASES = [(2, "p1", NU), (3, "p1", NU), (2, "smoothed", NU), (3, "smoothed", NU), (3, "smoothed", 0.499)]


@pytest.mark.filterwarnings("ignore::snede.LockingWarning")
@pytest.mark.parametrize("dim,formulation,poisson", CASES,
                         ids=[f"{'2d-plane-stress' if d == 2 else '3d'}-{f}-nu{nu}" for d, f, nu in CASES])
def test_manufactured_solution_converges_at_p1_rates(dim, formulation, poisson):
    lam, mu = snede.LinearElastic(E, poisson).lame
    lam_star = lam if dim == 3 else 2 * lam * mu / (lam + 2 * mu)  # plane stress (§6.3.1)
    start = time.perf_counter()
    waves = SOLENOIDAL_WAVES if poisson > 0.45 else None
    h, l2, h1, h1_exact = np.array([solve_and_measure(dim, n, lam_star, mu, formulation, poisson, waves)
                                    for n in DIVISIONS[dim]]).T
    l2_rate, h1_rate = fitted_rate(h, l2), fitted_rate(h, h1)
    report = (f"{dim}D {formulation} ν = {poisson}: h = {np.round(h, 4).tolist()}, L2 = {l2.tolist()}, H1 = {h1.tolist()}, "
              f"relative H1 error {h1[-1] / h1_exact[-1]:.3g} on the finest mesh, "
              f"rates L2 {l2_rate:.3f}, H1 {h1_rate:.3f}, {time.perf_counter() - start:.1f} s")
    print(report)
    assert np.all(np.diff(l2) < 0) and np.all(np.diff(h1) < 0), report
    assert 1.8 < l2_rate < 2.3, report
    assert 0.9 < h1_rate < 1.2, report
    # Small against the field itself on the finest mesh, not only decreasing.
    assert h1[-1] < 0.15 * h1_exact[-1], report


@pytest.mark.filterwarnings("ignore::snede.LockingWarning")
def test_p1_locks_on_the_solenoidal_waves():
    """The other side of the locking case above: P1 at ν = 0.499 loses its rates on the same
    meshes (measured L2 0.83, H1 0.82), so the smoothed formulation's rates there are its own."""
    lam, mu = snede.LinearElastic(E, 0.499).lame
    h, l2, h1, _ = np.array([solve_and_measure(3, n, lam, mu, "p1", 0.499, SOLENOIDAL_WAVES) for n in DIVISIONS[3]]).T
    assert fitted_rate(h, l2) < 1.2 and fitted_rate(h, h1) < 0.9, (l2, h1)
