"""Honesty at the extremes: inverted elements, exponential overflow, bad parameters."""
import math

import numpy as np
import pytest

import snede
from conftest import E, NU, all_materials, body_of
from test_fem_invariants import single_element


def inverting_displacement(dim):
    u = np.zeros((dim + 1, dim))
    u[dim, dim - 1] = -2.0  # push the last vertex through the opposite face
    return u


@pytest.mark.parametrize("material_name", ["neohookean", "veronda"])
def test_inverted_element_gives_infinite_energy_and_is_reported(material_name, dim):
    body = body_of(single_element(dim), all_materials()[material_name])
    u = inverting_displacement(dim)
    assert list(body.inverted_elements(u)) == [0]
    assert body.energy(u) == math.inf
    forces, action = body.internal_forces(u), body.tangent_apply(u, np.ones_like(u))
    assert np.all(np.isfinite(forces)) and np.all(forces == 0)
    assert np.all(np.isfinite(action))


@pytest.mark.parametrize("material_name", ["linear", "stvk"])
def test_inversion_stays_finite_but_is_reported(material_name, dim):
    body = body_of(single_element(dim), all_materials()[material_name])
    u = inverting_displacement(dim)
    assert list(body.inverted_elements(u)) == [0]
    assert math.isfinite(body.energy(u)) and body.energy(u) > 0
    assert np.all(np.isfinite(body.internal_forces(u)))


def test_veronda_westmann_overflow_is_a_domain_error(dim):
    body = body_of(single_element(dim), snede.VerondaWestmann(E, NU, 50.0))
    u = 9.0 * body.mesh.points  # F = 10 I: γ (ι₁ − 3) far beyond exp's range
    with pytest.raises(snede.DomainError, match="overflow"):
        body.energy(u)
    with pytest.raises(snede.DomainError):
        body.internal_forces(u)
    with pytest.raises(snede.DomainError):
        body.tangent_apply(u, u)


@pytest.mark.parametrize("make, value", [
    (lambda: snede.LinearElastic(0.0, 0.3), "0"),
    (lambda: snede.StVenantKirchhoff(-5.0, 0.3), "-5"),
    (lambda: snede.NeoHookean(1e3, 0.5), "0.5"),
    (lambda: snede.NeoHookean(1e3, -1.0), "-1"),
    (lambda: snede.LinearElastic(float("nan"), 0.3), "nan"),
    (lambda: snede.StVenantKirchhoff(1e3, float("inf")), "inf"),
    (lambda: snede.VerondaWestmann(1e3, 0.3, 0.0), "gamma"),
    (lambda: snede.VerondaWestmann(1e3, 0.3, -2.0), "-2"),
])
def test_bad_material_parameters_are_rejected_with_the_value(make, value):
    with pytest.raises(ValueError, match=value):
        make()


def test_body_parameters_are_checked():
    tet, tri = single_element(3), single_element(2)
    material = snede.NeoHookean(E, NU)
    with pytest.raises(ValueError, match="density"):
        snede.Body(tet, material, density=0.0)
    with pytest.raises(ValueError, match="density"):
        snede.Body(tet, material, density=float("nan"))
    with pytest.raises(ValueError, match="thickness"):
        snede.Body(tri, material)
    with pytest.raises(ValueError, match="thickness"):
        snede.Body(tri, material, thickness=-1.0)
    with pytest.raises(ValueError, match="thickness"):
        snede.Body(tet, material, thickness=0.1)
    body = snede.Body(tet, material)
    with pytest.raises(ValueError, match="shape"):
        body.energy(np.zeros((3, 3)))


def test_nearly_incompressible_material_warns_about_locking():
    tet = single_element(3)
    with pytest.warns(snede.LockingWarning, match="lock"):
        snede.Body(tet, snede.NeoHookean(E, 0.49))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        snede.Body(tet, snede.NeoHookean(E, 0.3))  # no warning
