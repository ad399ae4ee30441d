import numpy as np
import pytest

import snede

E, NU, GAMMA = 3.0e3, 0.3, 2.0


def all_materials(young=E, poisson=NU):
    return {
        "linear": snede.LinearElastic(young, poisson),
        "stvk": snede.StVenantKirchhoff(young, poisson),
        "neohookean": snede.NeoHookean(young, poisson),
        "veronda": snede.VerondaWestmann(young, poisson, GAMMA),
    }


def distorted(mesh: snede.Mesh, amount: float, seed: int = 0) -> snede.Mesh:
    """The same connectivity with interior points moved randomly by up to `amount`."""
    points = mesh.points.copy()
    boundary = np.unique(mesh.boundary_faces())
    interior = np.setdiff1d(np.arange(mesh.n_points), boundary)
    rng = np.random.default_rng(seed)
    points[interior] += amount * rng.uniform(-1, 1, (len(interior), mesh.dim))
    return snede.Mesh(points, mesh.cells)


def small_mesh(dim: int) -> snede.Mesh:
    if dim == 3:
        return distorted(snede.meshing.box((1.0, 1.0, 1.0), (3, 3, 3)), 0.08)
    return distorted(snede.meshing.rectangle((1.0, 1.0), (4, 4)), 0.06)


def body_of(mesh, material, density=1000.0):
    return snede.Body(mesh, material, density=density, thickness=0.01 if mesh.dim == 2 else None)


def remainder_slopes(remainder, h0=1e-3, n=4):
    """log2 of successive remainder ratios when h halves: 2 for a correct derivative."""
    values = np.array([remainder(h0 / 2**k) for k in range(n)])
    return np.log2(values[:-1] / values[1:]), values


def random_state(body, scale, seed):
    """A random displacement of relative size `scale` (no inverted element) and a direction."""
    rng = np.random.default_rng(seed)
    u = scale * rng.standard_normal((body.mesh.n_points, body.dim))
    d = 0.1 * rng.standard_normal(u.shape)
    assert len(body.inverted_elements(u)) == 0
    return u, d


def check_forces_are_minus_the_energy_gradient(body, u, d):
    """Taylor: |Π(u + h d) − Π(u) + h f·d| falls like h²."""
    energy, forces = body.energy(u), body.internal_forces(u)
    derivative = -(forces * d).sum()  # f = −∂Π/∂u
    slopes, values = remainder_slopes(lambda h: abs(body.energy(u + h * d) - energy - h * derivative))
    assert np.all(np.abs(slopes - 2) < 0.1), (slopes, values)


def check_tangent_is_the_force_derivative(body, u, d, linear: bool):
    """Taylor: |−(f(u + h d) − f(u)) − h K d| falls like h² (is round-off if linear)."""
    forces, action = body.internal_forces(u), body.tangent_apply(u, d)

    def remainder(h):
        return np.abs(-(body.internal_forces(u + h * d) - forces) - h * action).max()

    if linear:
        # forces are linear in u: the first-order expansion is exact up to round-off
        assert remainder(1e-2) <= 1e-10 * np.abs(action).max()
    else:
        slopes, values = remainder_slopes(remainder)
        assert np.all(np.abs(slopes - 2) < 0.15), (slopes, values)


@pytest.fixture(params=["linear", "stvk", "neohookean", "veronda"])
def material_name(request):
    return request.param


@pytest.fixture(params=[2, 3], ids=["2d", "3d"])
def dim(request):
    return request.param
