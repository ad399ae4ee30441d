"""Patch test, objectivity, small-strain limit and rigid modes of the element kernels."""
import numpy as np
import pytest

import snede
from conftest import E, NU, all_materials, body_of, small_mesh


def lame(young, poisson):
    return young * poisson / ((1 + poisson) * (1 - 2 * poisson)), young / (2 * (1 + poisson))


def young_poisson(lam, mu):
    return mu * (3 * lam + 2 * mu) / (lam + mu), lam / (2 * (lam + mu))


def linear_field(mesh, gradient):
    return mesh.points @ np.asarray(gradient).T


GRADIENT = {2: [[0.02, 0.01], [-0.015, 0.03]], 3: [[0.02, 0.01, -0.005], [-0.015, 0.03, 0.01], [0.004, -0.01, 0.025]]}


def test_patch_test_linear_field_gives_equilibrium_and_constant_stress(material_name, dim):
    mesh = small_mesh(dim)
    body = body_of(mesh, all_materials()[material_name])
    u = linear_field(mesh, GRADIENT[dim])
    forces = body.internal_forces(u)
    boundary = np.unique(mesh.boundary_faces())
    interior = np.setdiff1d(np.arange(mesh.n_points), boundary)
    assert len(interior) > 0
    scale = np.abs(forces[boundary]).max()
    assert np.abs(forces[interior]).max() <= 1e-11 * scale
    assert np.abs(forces.sum(axis=0)).max() <= 1e-11 * scale  # no net force
    stress = body.element_stress(u)
    assert np.abs(stress - stress.mean(axis=0)).max() <= 1e-11 * np.abs(stress).max()


def test_linear_elastic_stress_is_exact(dim):
    mesh = small_mesh(dim)
    body = body_of(mesh, snede.LinearElastic(E, NU))
    grad = np.asarray(GRADIENT[dim])
    eps = 0.5 * (grad + grad.T)
    lam, mu = lame(E, NU)
    if dim == 2:  # plane stress
        lam = 2 * lam * mu / (lam + 2 * mu)
    expected = 2 * mu * eps + lam * np.trace(eps) * np.eye(dim)
    stress = body.element_stress(linear_field(mesh, grad))
    assert np.allclose(stress, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def random_rotation(dim, seed):
    rng = np.random.default_rng(seed)
    if dim == 2:
        angle = rng.uniform(0, 2 * np.pi)
        return np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q *= np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


@pytest.mark.parametrize("material_name", ["stvk", "neohookean", "veronda"])
def test_objectivity_rotation_rotates_forces_keeps_energy(material_name, dim):
    mesh = small_mesh(dim)
    body = body_of(mesh, all_materials()[material_name])
    u = 0.05 * np.random.default_rng(3).standard_normal((mesh.n_points, dim))
    for seed in range(3):
        R = random_rotation(dim, seed)
        x = mesh.points + u
        u_rotated = x @ R.T - mesh.points
        assert body.energy(u_rotated) == pytest.approx(body.energy(u), rel=1e-11)
        f, f_rotated = body.internal_forces(u), body.internal_forces(u_rotated)
        assert np.abs(f_rotated - f @ R.T).max() <= 1e-10 * np.abs(f).max()


@pytest.mark.parametrize("material_name", ["stvk", "neohookean"])
def test_small_strain_approaches_linear(material_name, dim):
    mesh = small_mesh(dim)
    body = body_of(mesh, all_materials()[material_name])
    linear = body_of(mesh, snede.LinearElastic(E, NU))
    u0 = np.random.default_rng(4).standard_normal((mesh.n_points, dim))
    errors = []
    for s in (1e-3, 1e-4, 1e-5):
        f_lin = linear.internal_forces(s * u0)
        errors.append(np.abs(body.internal_forces(s * u0) - f_lin).max() / np.abs(f_lin).max())
    # the difference is O(strain): ten times smaller strain, ten times smaller relative error
    assert errors[-1] < 1e-3
    assert errors[0] / errors[1] == pytest.approx(10, rel=0.2)
    assert errors[1] / errors[2] == pytest.approx(10, rel=0.2)


@pytest.mark.parametrize("gamma", [0.5, 2.0, 5.0])
def test_veronda_westmann_small_strain_trace_term(gamma, dim):
    """§4.3.4 states that Veronda-Westmann's small-strain limit is not the linear model: the
    trace term differs. Linearising (4.7) with C = I + 2ε gives
    S ≈ 2μ ε + (λ + 2μ(2γ − 1)) tr(ε) I, the linear model with λ' = λ + 2μ(2γ − 1), which
    is the linear model itself only for γ = ½. (The thesis writes the γ → 0 limit as
    (μ + λ/2) tr(C − I); the derivation gives (λ/2 − μ) tr(C − I) there.)"""
    mesh = small_mesh(dim)
    body = body_of(mesh, snede.VerondaWestmann(E, NU, gamma))
    lam, mu = lame(E, NU)
    shifted = body_of(mesh, snede.LinearElastic(*young_poisson(lam + 2 * mu * (2 * gamma - 1), mu)))
    plain = body_of(mesh, snede.LinearElastic(E, NU))
    u = 1e-7 * np.random.default_rng(5).standard_normal((mesh.n_points, dim))
    f = body.internal_forces(u)
    f_shifted, f_plain = shifted.internal_forces(u), plain.internal_forces(u)
    assert np.abs(f - f_shifted).max() <= 1e-4 * np.abs(f_shifted).max()
    if gamma != 0.5:
        assert np.abs(f - f_plain).max() >= 0.05 * np.abs(f_plain).max()


def single_element(dim):
    if dim == 3:
        return snede.Mesh([[0, 0, 0], [1, 0.1, 0], [0.2, 1.1, 0], [0.1, 0.3, 0.9]], [[0, 1, 2, 3]])
    return snede.Mesh([[0, 0], [1, 0.1], [0.3, 0.9]], [[0, 1, 2]])


def test_reference_tangent_has_exactly_the_rigid_modes_as_kernel(material_name, dim):
    mesh = single_element(dim)
    body = body_of(mesh, all_materials()[material_name])
    K = body.element_stiffness(0, np.zeros((mesh.n_points, dim)))
    assert np.allclose(K, K.T, atol=1e-10 * np.abs(K).max())
    eigenvalues = np.sort(np.abs(np.linalg.eigvalsh(0.5 * (K + K.T))))
    n_rigid = 6 if dim == 3 else 3
    assert np.all(eigenvalues[:n_rigid] < 1e-10 * eigenvalues[-1])
    assert np.all(eigenvalues[n_rigid:] > 1e-3 * eigenvalues[-1])
