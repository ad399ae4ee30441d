"""The smoothed formulation (issue 35; fem/smoothed_loops.hpp): Taylor tests of its energy,
forces and tangent for the four materials in 3D and plane stress, the assembled tangent
against the matrix-free one, patch tests (an affine displacement is reproduced exactly, also
at ν = 0.499), a cut separating the patches of its two lips, and its errors."""
import numpy as np
import pytest
from petsc4py import PETSc

import snede
from conftest import (all_materials, check_forces_are_minus_the_energy_gradient,
                      check_tangent_is_the_force_derivative, random_state, small_mesh)


def smoothed_body(mesh, material):
    return snede.Body(mesh, material, thickness=0.01 if mesh.dim == 2 else None, formulation="smoothed")


@pytest.mark.parametrize("poisson", [0.3, 0.49])
def test_forces_are_minus_the_energy_gradient(material_name, dim, poisson):
    body = smoothed_body(small_mesh(dim), all_materials(poisson=poisson)[material_name])
    for seed in range(3):
        check_forces_are_minus_the_energy_gradient(body, *random_state(body, 0.01, seed))


@pytest.mark.parametrize("poisson", [0.3, 0.49])
def test_tangent_is_the_force_derivative(material_name, dim, poisson):
    body = smoothed_body(small_mesh(dim), all_materials(poisson=poisson)[material_name])
    for seed in range(3):
        check_tangent_is_the_force_derivative(body, *random_state(body, 0.01, seed), linear=material_name == "linear")


def test_tangent_is_symmetric_and_equals_the_assembled_one(material_name, dim):
    body = smoothed_body(small_mesh(dim), all_materials(poisson=0.45)[material_name])
    u, d = random_state(body, 0.01, 7)
    w = np.random.default_rng(8).standard_normal(u.shape)
    left, right = (w * body.tangent_apply(u, d)).sum(), (d * body.tangent_apply(u, w)).sum()
    assert abs(left - right) <= 1e-11 * max(abs(left), 1.0)
    for format in ("aij", "baij"):
        J = body.assemble_tangent(u, format=format)
        x = PETSc.Vec().createWithArray(d.ravel().copy())
        y = x.duplicate()
        J.mult(x, y)
        expected = body.tangent_apply(u, d).ravel()
        assert np.abs(y.getArray() - expected).max() <= 1e-10 * np.abs(expected).max(), format


@pytest.mark.filterwarnings("ignore::snede.LockingWarning")  # the P1 body compared with
@pytest.mark.parametrize("poisson", [0.3, 0.499])
def test_affine_displacement_is_reproduced_exactly(material_name, dim, poisson):
    """Patch test: under u = A x every patch has F = I + A, so the energy is the volume times
    W(I + A) as for P1, the interior vertices carry no force, and the stress is W's."""
    material = all_materials(poisson=poisson)[material_name]
    mesh = small_mesh(dim)
    A = 0.01 * np.random.default_rng(3).standard_normal((dim, dim))
    u = mesh.points @ A.T
    smoothed = smoothed_body(mesh, material)
    p1 = snede.Body(mesh, material, thickness=0.01 if dim == 2 else None)
    assert smoothed.energy(u) == pytest.approx(p1.energy(u), rel=1e-12)
    boundary = np.unique(mesh.boundary_faces())
    interior = np.setdiff1d(np.arange(mesh.n_points), boundary)
    forces = smoothed.internal_forces(u)
    scale = np.abs(forces[boundary]).max()
    assert np.abs(forces[interior]).max() <= 1e-11 * scale
    np.testing.assert_allclose(forces, p1.internal_forces(u), rtol=0, atol=1e-11 * scale)
    np.testing.assert_allclose(smoothed.element_stress(u), p1.element_stress(u), rtol=1e-10,
                               atol=1e-12 * np.abs(p1.element_stress(u)).max())


def test_a_cut_separates_the_patches_of_its_lips():
    """Dissect a box across its middle: a displacement of one half must leave the other half's
    vertices without force once cut (their edge and vertex patches no longer reach across),
    where before the cut it pulled on them."""
    mesh = snede.meshing.box((2.0, 1.0, 1.0), (4, 2, 2))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.49))
    rng = np.random.default_rng(0)

    def left_moved():
        """A random displacement of the vertices of the cells left of x = 1 (the cut's
        vertices too, before the cut; their left copies after it), and the others' mask."""
        left = np.unique(mesh.cells[mesh.points[mesh.cells].mean(axis=1)[:, 0] < 1.0])
        u = np.zeros((mesh.n_points, 3))
        u[left] = 0.01 * rng.standard_normal((len(left), 3))
        others = np.ones(mesh.n_points, dtype=bool)
        others[left] = False
        return u, others

    u, others = left_moved()
    assert np.abs(body.internal_forces(u)[others]).max() > 0  # joined: the left half pulls on the right
    pairs = mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 1.0)))
    assert len(pairs) == 9  # the 3 × 3 vertices of the plane x = 1
    u, others = left_moved()
    assert others.sum() == 2 * 9 + 9  # right of the cut: the 2 planes beyond it, and the cut's copies
    assert np.abs(body.internal_forces(u)[others]).max() == 0.0


def test_errors_name_the_formulation():
    tet = small_mesh(3)
    with pytest.raises(ValueError, match="unknown formulation 'q2'"):
        snede.Body(tet, snede.LinearElastic(1e3, 0.3), formulation="q2")
    surface, _ = snede.meshing.boundary_surface(snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)))
    with pytest.raises(ValueError, match="membrane"):
        snede.Body(surface, snede.NeoHookean(1e3, 0.3), thickness=0.001, formulation="smoothed")
    body = smoothed_body(tet, snede.LinearElastic(1e3, 0.3))
    with pytest.raises(ValueError, match="strain patches"):
        body.element_stiffness(0, np.zeros((tet.n_points, 3)))
    assert body.formulation == "smoothed"
    assert set(snede.formulations()) == {"p1", "smoothed"}


def test_no_locking_warning_for_the_smoothed_formulation():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        smoothed_body(small_mesh(3), snede.NeoHookean(1e3, 0.499))
