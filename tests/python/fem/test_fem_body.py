"""Mass, gravity and per-element data across a topology change."""
import numpy as np
import pytest

import snede
from conftest import all_materials, body_of, small_mesh


def test_lumped_mass_and_gravity_add_up(dim):
    mesh = small_mesh(dim)
    body = body_of(mesh, snede.NeoHookean(1e3, 0.3), density=1100.0)
    measure = mesh.quality().volume.sum() * (0.01 if dim == 2 else 1.0)
    mass = body.lumped_mass()
    assert mass.shape == (mesh.n_points,)
    assert mass.sum() == pytest.approx(1100.0 * measure, rel=1e-12)
    g = np.array([0.0, -9.81] if dim == 2 else [0.0, 0.0, -9.81])
    f = body.gravity_forces(g)
    assert np.allclose(f.sum(axis=0), mass.sum() * g, rtol=1e-12)
    assert np.allclose(f, mass[:, None] * g)


def test_flops_are_counted_per_kernel(material_name):
    flops = body_of(small_mesh(3), all_materials()[material_name]).flops_per_element()
    # ≤: the linear force −K u and tangent K d are one kernel (§3.1), equal in cost.
    assert 50 < flops["energy"] < flops["force"] <= flops["tangent"] < 2000


def test_reference_data_follow_a_dissection(material_name):
    """After a cut (change_elements) the body's per-element data is recomputed for the
    changed elements: a linear field on the cut mesh has the energy it had before."""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = body_of(mesh, all_materials()[material_name])
    gradient = np.array([[0.02, 0.01, 0.0], [0.0, -0.01, 0.01], [0.005, 0.0, 0.03]])
    before = body.energy(mesh.points @ gradient.T)
    split = mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5)))
    assert len(split) == 9 and mesh.connected_components()[0] == 2
    after = body.energy(mesh.points @ gradient.T)
    assert after == pytest.approx(before, rel=1e-13)
    assert body.lumped_mass().shape == (mesh.n_points,)
