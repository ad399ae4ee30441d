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


@pytest.fixture(params=["linear", "stvk", "neohookean", "veronda"])
def material_name(request):
    return request.param


@pytest.fixture(params=[2, 3], ids=["2d", "3d"])
def dim(request):
    return request.param
