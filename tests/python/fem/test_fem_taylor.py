"""Taylor tests: forces against the energy gradient and tangent actions against the force
derivative, for all four materials in 3D and plane stress, at random deformations."""
import numpy as np

from conftest import (all_materials, body_of, check_forces_are_minus_the_energy_gradient,
                      check_tangent_is_the_force_derivative, random_state, small_mesh)


def test_forces_are_minus_the_energy_gradient(material_name, dim):
    body = body_of(small_mesh(dim), all_materials()[material_name])
    for seed in range(3):
        check_forces_are_minus_the_energy_gradient(body, *random_state(body, 0.01, seed))


def test_tangent_is_the_force_derivative(material_name, dim):
    body = body_of(small_mesh(dim), all_materials()[material_name])
    for seed in range(3):
        check_tangent_is_the_force_derivative(body, *random_state(body, 0.01, seed), linear=material_name == "linear")


def test_tangent_is_symmetric(material_name, dim):
    body = body_of(small_mesh(dim), all_materials()[material_name])
    u, d = random_state(body, 0.01, 7)
    w = np.random.default_rng(8).standard_normal(u.shape)
    left, right = (w * body.tangent_apply(u, d)).sum(), (d * body.tangent_apply(u, w)).sum()
    assert abs(left - right) <= 1e-11 * max(abs(left), 1.0)
