"""Checks of a smoothed body's operators (issue 35) at the mesh as it is now, against
references independent of the formulation (a fresh P1 body on the same mesh, finite
differences): for the tests of the formulation, the cutters, the needle and the solvers."""
import numpy as np
import pytest
from petsc4py import PETSc

import snede

THICKNESS = 0.01


def thickness(mesh):
    return THICKNESS if mesh.dim == 2 else None


def smoothed_body(mesh, material, **options):
    return snede.Body(mesh, material, thickness=thickness(mesh), formulation="smoothed", **options)


def p1_twin(body):
    """A P1 body on the same mesh (a second Body watching it)."""
    return snede.Body(body.mesh, body.material, density=body.density, thickness=thickness(body.mesh))


def cell_altitudes(mesh) -> np.ndarray:
    """The smallest height of each cell (row of ``mesh.cells``)."""
    x = mesh.points[mesh.cells]
    if mesh.dim == 2:
        e1, e2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
        area = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / 2
        return np.min([2 * area / np.linalg.norm(x[:, (k + 1) % 3] - x[:, (k + 2) % 3], axis=1) for k in range(3)],
                      axis=0)
    volume = np.abs(np.einsum("ij,ij->i", x[:, 1] - x[:, 0], np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]))) / 6
    heights = []
    for k in range(4):
        a, b, c = (x[:, j] for j in range(4) if j != k)
        heights.append(3 * volume / (np.linalg.norm(np.cross(b - a, c - a), axis=1) / 2))
    return np.min(heights, axis=0)


def min_altitude(mesh) -> float:
    return float(cell_altitudes(mesh).min())


def vertex_scales(mesh) -> np.ndarray:
    """Per vertex, the smallest height of the cells around it (1 for a vertex of no cell):
    moving each vertex by a small fraction of its own scale inverts no cell, and keeps the
    strains, energies and round-off of large and small cells alike."""
    scale = np.full(mesh.n_points, np.inf)
    heights = cell_altitudes(mesh)
    for k in range(mesh.cells.shape[1]):
        np.minimum.at(scale, mesh.cells[:, k], heights)
    scale[~np.isfinite(scale)] = 1.0
    return scale[:, None]


def mult(matrix, v):
    x = PETSc.Vec().createWithArray(np.ascontiguousarray(v, dtype=np.float64).ravel().copy())
    y = x.duplicate()
    matrix.mult(x, y)
    out = y.getArray().copy().reshape(v.shape)
    x.destroy()
    y.destroy()
    return out


def used_vertices(mesh):
    used = np.zeros(mesh.n_points, dtype=bool)
    used[mesh.cells.ravel()] = True
    return used


def interior_vertices(mesh):
    """Vertices of some cell and on no boundary face (the lips of a cut are boundary)."""
    interior = used_vertices(mesh)
    interior[np.unique(mesh.boundary_faces())] = False
    return interior


def taylor_slopes(remainder, h0=1e-4, n=4):
    values = np.array([remainder(h0 / 2**k) for k in range(n)])
    return np.log2(values[:-1] / values[1:]), values


def check_invariants(body, seed, what=""):
    """Everything the smoothed operators promise at the mesh as it is now (see the module doc).
    ``what`` names the edit that came before, for the failure message."""
    mesh, dim = body.mesh, body.dim
    n = mesh.n_points
    zero = np.zeros((n, dim))
    assert body.energy(zero) == 0.0, what
    assert not body.internal_forces(zero).any(), what

    rng = np.random.default_rng(seed)
    h = vertex_scales(mesh)
    u = 0.02 * h * rng.standard_normal((n, dim))
    d = h * rng.standard_normal((n, dim))
    assert len(body.inverted_elements(u)) == 0, what
    energy, forces = body.energy(u), body.internal_forces(u)
    assert np.isfinite(energy) and np.isfinite(forces).all(), what
    # f = −∂Π/∂u: |Π(u + t d) − Π(u) + t f·d| falls like t² (like t where f is wrong, which
    # dominates at these t even for an error at a few vertices; the remainder is far above
    # round-off); and component by component, by central differences at 24 random unknowns.
    slope = -(forces * d).sum()
    slopes, values = taylor_slopes(lambda t: abs(body.energy(u + t * d) - energy - t * slope))
    assert np.all(np.abs(slopes - 2) < 0.05), (what, slopes, values)
    for k in rng.choice(n * dim, size=min(24, n * dim), replace=False):
        step = 1e-3 * h.flat[k // dim]
        e = np.zeros(n * dim)
        e[k] = step
        e = e.reshape(n, dim)
        derivative = (body.energy(u + e) - body.energy(u - e)) / (2 * step)
        assert abs(derivative + forces.flat[k]) <= 1e-5 * np.abs(forces).max(), (what, k, derivative, forces.flat[k])
    # K = −∂f/∂u: |−(f(u + t d) − f(u)) − t K d| falls like t².
    Kd = body.tangent_apply(u, d)

    def force_remainder(t):
        return np.abs(-(body.internal_forces(u + t * d) - forces) - t * Kd).max()

    if isinstance(body.material, snede.LinearElastic):  # linear forces: exact up to round-off
        assert force_remainder(1e-2) <= 1e-10 * np.abs(Kd).max(), what
    else:
        slopes, values = taylor_slopes(force_remainder)
        assert np.all(np.abs(slopes - 2) < 0.1), (what, slopes, values)
    # Symmetric.
    w = rng.standard_normal((n, dim))
    left, right = (w * Kd).sum(), (d * body.tangent_apply(u, w)).sum()
    assert abs(left - right) <= 1e-11 * np.linalg.norm(w) * np.linalg.norm(Kd), (what, left, right)

    # The shell J = P K P + (I − P) is tangent_apply on the free vertices; the assembled J and
    # its diagonal are the shell's, on every row (removed and constrained vertices included).
    fixed, _, sliding = body._model.constraint_table()
    held = ~mesh.live_vertices
    held[fixed] = True
    held[sliding] = True
    projected = np.where(held[:, None], 0.0, d)
    shell = body.tangent_operator(u)
    expected = body.tangent_apply(u, projected)
    np.testing.assert_allclose(mult(shell, projected)[~held], expected[~held], rtol=0,
                               atol=1e-11 * np.abs(expected).max(), err_msg=what)
    Jd, diagonal = mult(shell, d), shell.getDiagonal().getArray().copy()
    for format in ("aij", "baij"):
        J = body.assemble_tangent(u, format=format)
        np.testing.assert_allclose(mult(J, d), Jd, rtol=0, atol=1e-11 * np.abs(Jd).max(), err_msg=f"{what} {format}")
        np.testing.assert_allclose(J.getDiagonal().getArray(), diagonal, rtol=1e-12, atol=0, err_msg=f"{what} {format}")
        J.destroy()

    # Patch test against a fresh P1 body on the same mesh.
    A = 0.01 * rng.standard_normal((dim, dim))
    affine = mesh.points @ A.T
    twin = p1_twin(body)
    assert body.energy(affine) == pytest.approx(twin.energy(affine), rel=1e-10), what
    forces = body.internal_forces(affine)
    scale = np.abs(forces).max()
    np.testing.assert_allclose(forces, twin.internal_forces(affine), rtol=0, atol=1e-9 * scale, err_msg=what)
    stress = twin.element_stress(affine)  # row by row of mesh.cells, whatever ids edits left
    np.testing.assert_allclose(body.element_stress(affine), stress, rtol=0, atol=1e-9 * np.abs(stress).max(),
                               err_msg=what)
    inner = interior_vertices(mesh)
    if inner.any():
        assert np.abs(forces[inner]).max() <= 1e-9 * scale, what


def check_affine_state_carried(body, A, what=""):
    """The body's displacement, set to A·x before the edits, is still A·x at every live vertex:
    every edit interpolates it linearly to new and moved vertices."""
    live = body.mesh.live_vertices
    expected = body.mesh.points @ A.T
    error = np.abs(body.displacement - expected)[live].max()
    assert error <= 1e-12 * np.abs(expected).max(), (what, error)


def distorted_grid(dim):
    mesh = snede.meshing.rectangle((1.0, 1.0), (6, 6)) if dim == 2 else snede.meshing.box((1.0, 1.0, 1.0), (3, 3, 3))
    points = mesh.points.copy()
    inner = interior_vertices(mesh)
    points[inner] += 0.05 * np.random.default_rng(dim).uniform(-1, 1, (inner.sum(), dim))
    return snede.Mesh(points, mesh.cells)
