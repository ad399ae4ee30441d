"""The solvers on smoothed bodies (issue 35): every preconditioner through cuts and refinement,
dynamic relaxation, bisection multigrid under a large load; refused on MPI ranks."""
import numpy as np
import pytest

import snede
from smoothed_checks import check_invariants, smoothed_body, thickness, used_vertices

pytestmark = pytest.mark.filterwarnings("ignore::snede.LockingWarning")  # the P1 twins at ν ≥ 0.45


def loaded_beam(dim, formulation="smoothed", levels=None, density=10.0):
    """A cantilever 1 × 0.4 (× 0.4) m, neo-Hookean at ν = 0.49, fixed at x = 0, under gravity;
    its mesh made by bisection (``levels`` of refine_uniform) so that "mg" starts on its tree."""
    if dim == 2:
        mesh = snede.meshing.rectangle((1.0, 0.4), (5, 2))
        mesh.refine_uniform(4 if levels is None else levels)
    else:
        mesh = snede.meshing.box((1.0, 0.4, 0.4), (5, 2, 2))
        mesh.refine_uniform(2 if levels is None else levels)
    body = snede.Body(mesh, snede.NeoHookean(1e4, 0.49), density=density, thickness=thickness(mesh),
                      formulation=formulation)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity(np.r_[np.zeros(dim - 1), -9.81])
    return body


@pytest.mark.parametrize("dim", [2, 3])
def test_static_solves_agree_for_every_preconditioner_through_cuts_and_refinement(dim):
    """One solver per preconditioner, kept through the edits (it follows each change: new
    vectors, assembled tangent on the patches' two-edge sparsity, multigrid levels): fresh
    (bisection multigrid), after a cut (grid multigrid), after refine_around and after a
    uniform refinement. Each solve converges, to the answer without a preconditioner, in
    equilibrium; and in 3D the smoothed beam sags more than P1's, which locks at ν = 0.49."""
    bodies = {P: loaded_beam(dim) for P in ("none", "mg", "gamg", "jacobi")}
    solvers = {P: snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner=P) for P, body in bodies.items()}

    def solve_all(stage):
        for P, solver in solvers.items():
            result = solver.solve()
            assert result.converged, (stage, P, result)
        reference = bodies["none"].displacement
        for P, body in bodies.items():
            u = body.displacement
            assert np.abs(u - reference).max() <= 1e-6 * np.abs(reference).max(), (stage, P)
            fixed = np.zeros(body.mesh.n_points, dtype=bool)
            fixed[body._model.constraint_table()[0]] = True
            residual = (body.internal_forces(u) + body.external_forces())[~fixed & used_vertices(body.mesh)]
            assert np.linalg.norm(residual) <= 1e-6 * np.linalg.norm(body.external_forces()), (stage, P)
        return reference

    fresh = solve_all("fresh")
    assert solvers["mg"].multigrid_source == "bisection"
    p1 = loaded_beam(dim, "p1")
    assert snede.StaticSolver(p1, "newton", rtol=1e-8).solve().converged
    if dim == 3:
        assert np.abs(fresh).max() > 1.05 * np.abs(p1.displacement).max()
    for body in bodies.values():
        mesh = body.mesh
        assert len(mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.6) & (x[:, dim - 1] > 0.15)))) > 0
    solve_all("cut")
    assert solvers["mg"].multigrid_source == "grid"
    for body in bodies.values():
        body.mesh.refine_around(np.r_[0.6, np.full(dim - 1, 0.15)], 0.04)
    solve_all("refine_around")
    for body in bodies.values():
        body.mesh.refine_uniform(1)
    solve_all("refine_uniform")
    check_invariants(bodies["gamg"], 3, "after the solves")


def test_dynamic_relaxation_reaches_the_static_answer_after_a_cut():
    mesh = snede.meshing.rectangle((1.0, 0.4), (10, 4))
    body = smoothed_body(mesh, snede.LinearElastic(1e4, 0.3), density=10.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81))
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5) & (x[:, 1] > 0.15)))
    assert snede.StaticSolver(body, "cg", rtol=1e-10).solve().converged
    static = body.displacement
    body.displacement = np.zeros_like(static)
    assert snede.DynamicRelaxation(body, 20.0).run(rtol=1e-7, max_steps=100000).converged
    assert np.abs(body.displacement - static).max() <= 1e-4 * np.abs(static).max()


def test_bisection_multigrid_under_a_load_that_bends_the_beam_a_quarter_of_its_length():
    """Under this load a coarse level linearised at the injected fine state is indefinite (P1 and
    smoothed alike): the solver then linearises the coarse levels at rest and converges."""
    body = loaded_beam(3, levels=3, density=30.0)
    reference = loaded_beam(3, levels=3, density=30.0)
    assert snede.StaticSolver(reference, "newton", rtol=1e-8, preconditioner="none").solve().converged
    assert np.abs(reference.displacement).max() > 0.2  # a large, but regular, deflection
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner="mg")
    result = solver.solve()
    assert solver.multigrid_source == "bisection"
    assert result.converged, result
    assert np.abs(body.displacement - reference.displacement).max() <= 1e-6 * np.abs(reference.displacement).max()


# -- bad input ------------------------------------------------------------------------------

def test_smoothed_bodies_on_mpi_ranks_are_refused_naming_the_formulation():
    MPI = pytest.importorskip("mpi4py.MPI")
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.3), comm=MPI.COMM_WORLD)
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    message = "formulation 'smoothed' is not distributed yet"
    with pytest.raises(NotImplementedError, match=message):
        snede.StaticSolver(body, "newton").solve()
    with pytest.raises(NotImplementedError, match=message):
        snede.DynamicRelaxation(body, 10.0)
    serial = smoothed_body(mesh, snede.NeoHookean(1e4, 0.3))
    serial.fix(np.isclose(mesh.points[:, 2], 0.0))
    with pytest.raises(NotImplementedError, match=message):
        snede.StaticSolver(serial, "newton", comm=MPI.COMM_WORLD).solve()
    assert not body.displacement.any() and not serial.displacement.any()
    serial.add_gravity((0.0, 0.0, -9.81))  # without a communicator the same body solves
