"""Taylor tests: forces against the energy gradient and tangent actions against the force
derivative, for all four materials in 3D and plane stress, at random deformations."""
import numpy as np

from conftest import all_materials, body_of, remainder_slopes, small_mesh


def random_state(body, scale, seed):
    """A random displacement of relative size `scale` (no inverted element) and a direction."""
    rng = np.random.default_rng(seed)
    u = scale * rng.standard_normal((body.mesh.n_points, body.dim))
    d = 0.1 * rng.standard_normal(u.shape)
    assert len(body.inverted_elements(u)) == 0
    return u, d


def test_forces_are_minus_the_energy_gradient(material_name, dim):
    body = body_of(small_mesh(dim), all_materials()[material_name])
    for seed in range(3):
        u, d = random_state(body, 0.01, seed)
        energy, forces = body.energy(u), body.internal_forces(u)
        derivative = -(forces * d).sum()  # f = −∂Π/∂u
        slopes, values = remainder_slopes(lambda h: abs(body.energy(u + h * d) - energy - h * derivative))
        assert np.all(np.abs(slopes - 2) < 0.1), (slopes, values)


def test_tangent_is_the_force_derivative(material_name, dim):
    body = body_of(small_mesh(dim), all_materials()[material_name])
    for seed in range(3):
        u, d = random_state(body, 0.01, seed)
        forces, action = body.internal_forces(u), body.tangent_apply(u, d)

        def remainder(h):
            return np.abs(-(body.internal_forces(u + h * d) - forces) - h * action).max()

        if material_name == "linear":
            # forces are linear in u: the first-order expansion is exact up to round-off
            assert remainder(1e-2) <= 1e-10 * np.abs(action).max()
        else:
            slopes, values = remainder_slopes(remainder)
            assert np.all(np.abs(slopes - 2) < 0.15), (slopes, values)


def test_tangent_is_symmetric(material_name, dim):
    body = body_of(small_mesh(dim), all_materials()[material_name])
    u, d = random_state(body, 0.01, 7)
    w = np.random.default_rng(8).standard_normal(u.shape)
    left, right = (w * body.tangent_apply(u, d)).sum(), (d * body.tangent_apply(u, w)).sum()
    assert abs(left - right) <= 1e-11 * max(abs(left), 1.0)
