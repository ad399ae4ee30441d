"""A serial script's solvers given a communicator (StaticSolver(..., comm=),
DynamicRelaxation(..., comm=)): on several ranks they distribute rank 0's body and gather the
answer back into it on every rank, so the script is the same on 1 or N ranks (on one rank
the distributed path runs too). Compared with the serial solvers on the same body."""
import numpy as np
import pytest
from mpi4py import MPI

import snede
from snede.output import SeriesWriter, read_series
from cantilever_problems import cantilever, conditions

COMM = MPI.COMM_WORLD


def loaded_body(material, refine=False):
    mesh, _ = cantilever(3)
    if refine:
        mesh.refine_uniform()
    fixed, tip, force = conditions(mesh)
    body = snede.Body(mesh, material)
    body.fix(fixed)
    body.add_nodal_force(tip, force)
    body.add_gravity((0.0, 0.0, -1.0))
    return body


def relative_difference(u, v):
    return np.abs(u - v).max() / np.abs(v).max()


def test_static_solver_with_comm_gives_the_serial_displacement_on_every_rank():
    material = snede.NeoHookean(1e5, 0.3)
    body = loaded_body(material)
    result = snede.StaticSolver(body, "newton", rtol=1e-11, comm=COMM).solve()
    assert result.converged, result
    reference = loaded_body(material)
    assert snede.StaticSolver(reference, "newton", rtol=1e-12).solve().converged
    assert relative_difference(body.displacement, reference.displacement) <= 1e-7
    # Every rank holds the same answer.
    assert len({arr.tobytes() for arr in COMM.allgather(body.displacement)}) == 1


def test_static_solver_with_comm_stops_at_the_serial_criterion():
    """Unpreconditioned CG to criterion (6.9) with rtol 1e-6: the same threshold and, in exact
    arithmetic, the same iterates as the serial CG (which scales the system by E·H², a
    round-off difference only). After ~150 iterations the round-off of another summation order
    moves CG's residual history enough that the threshold may be crossed one iteration apart."""
    material = snede.LinearElastic(1e5, 0.3)
    body, reference = loaded_body(material), loaded_body(material)
    result = snede.StaticSolver(body, "cg", rtol=1e-6, preconditioner="none", comm=COMM).solve()
    expected = snede.StaticSolver(reference, "cg", rtol=1e-6, preconditioner="none").solve()
    assert result.converged and expected.converged, (result, expected)
    assert result.tolerance == pytest.approx(expected.tolerance, rel=1e-12)
    assert abs(result.iterations - expected.iterations) <= 1
    assert result.residual_norm <= 2 * result.tolerance  # the recomputed residual, as serially
    assert relative_difference(body.displacement, reference.displacement) <= 1e-8  # 1-2e-10 measured, 1-4 ranks


@pytest.mark.parametrize("method", ["cg", "newton"])
def test_a_solve_starts_from_the_body_as_the_serial_one_does(method):
    """Solved once, the body is in equilibrium: the next solve starts there and stops at once.
    Set half way (u*/2) instead, the linear body's residual is F(u*/2) = F(0)/2 (K u* = f on
    the free dofs): the solve starts from there, not from zero, and ends at u* again."""
    body = loaded_body(snede.LinearElastic(1e5, 0.3))
    solver = snede.StaticSolver(body, method, rtol=1e-10, comm=COMM)
    first = solver.solve()
    assert first.converged, first
    again = solver.solve()
    assert again.converged and again.iterations == 0, again
    answer = body.displacement.copy()
    body.displacement = 0.5 * answer
    restarted = solver.solve()
    assert restarted.converged, restarted
    assert restarted.initial_residual_norm == pytest.approx(0.5 * first.initial_residual_norm, rel=1e-6)
    assert relative_difference(body.displacement, answer) <= 1e-8


def test_dynamic_relaxation_with_comm_takes_the_serial_steps():
    material = snede.LinearElastic(1e5, 0.3)
    body = loaded_body(material)
    relaxation = snede.DynamicRelaxation(body, damping=1.5, comm=COMM)
    result = relaxation.run(rtol=1e-6, max_steps=20000)
    reference = loaded_body(material)
    expected = snede.DynamicRelaxation(reference, damping=1.5, dt=relaxation.dt).run(rtol=1e-6, max_steps=20000)
    assert result.converged and expected.converged
    assert result.iterations == expected.iterations
    assert relative_difference(body.displacement, reference.displacement) <= 1e-10


def test_a_refined_body_is_distributed_anew():
    """The serial body refined on every rank between two solves: the second solve distributes
    the refined mesh and matches the serial solve of the refined body."""
    material = snede.LinearElastic(1e5, 0.3)
    body = loaded_body(material)
    solver = snede.StaticSolver(body, "cg", rtol=1e-12, comm=COMM)
    assert solver.solve().converged
    cells_before = solver.part.n_global_cells
    body.mesh.refine_uniform()
    assert solver.solve().converged
    assert solver.part.n_global_cells == 2 * cells_before == body.mesh.n_cells  # one bisection each
    reference = loaded_body(material, refine=True)
    assert snede.StaticSolver(reference, "cg", rtol=1e-12).solve().converged
    assert relative_difference(body.displacement, reference.displacement) <= 1e-7


def test_what_is_not_distributed_is_refused_on_every_rank():
    mesh, _ = cantilever(3)
    fixed, _, _ = conditions(mesh)
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3), formulation="smoothed")
    body.fix(fixed)
    with pytest.raises(NotImplementedError, match=r"on \d MPI ranks: formulation 'smoothed' is not distributed"):
        snede.StaticSolver(body, "cg", comm=COMM).solve()
    solver = snede.StaticSolver(loaded_body(snede.LinearElastic(1e5, 0.3)), "cg", comm=COMM)
    with pytest.raises(NotImplementedError, match="only solve"):
        solver.ksp  # there is no engine solver before the first solve
    assert solver.solve().converged
    assert solver.ksp.getComm().getSize() == COMM.size
    assert COMM.allreduce(1) == COMM.size


@pytest.mark.parametrize("method", ["cg", "newton"])
def test_multigrid_on_ranks_gives_the_serial_displacement(method):
    """Issue 36: preconditioner "mg" with comm= (PCMG over aggregates of each rank's vertices,
    Galerkin levels of the MPIAIJ tangent) solves to the serial answer (grid levels) within
    1e-8, with far fewer CG iterations than no preconditioner on the same ranks."""
    material = snede.LinearElastic(1e5, 0.3) if method == "cg" else snede.NeoHookean(1e5, 0.3)
    body, reference, plain = (loaded_body(material, refine=True) for _ in range(3))
    solver = snede.StaticSolver(body, method, rtol=1e-12, preconditioner="mg", comm=COMM)
    result = solver.solve()
    expected = snede.StaticSolver(reference, method, rtol=1e-12, preconditioner="mg").solve()
    unpreconditioned = snede.StaticSolver(plain, method, rtol=1e-12, preconditioner="none", comm=COMM).solve()
    assert result.converged and expected.converged and unpreconditioned.converged, (result, expected)
    assert solver.multigrid_source == "aggregation" and len(solver.multigrid_unknowns) >= 2
    assert solver.multigrid_unknowns[-1] == body.mesh.n_points * 3
    linear = (lambda r: r.iterations) if method == "cg" else (lambda r: r.linear_iterations)
    assert linear(result) < linear(unpreconditioned) / 2, (result, unpreconditioned)
    assert relative_difference(body.displacement, reference.displacement) <= 1e-8


def test_multigrid_on_ranks_smooths_its_first_level_unless_told_not_to():
    """On ranks "mg" smooths the first level by default (one Jacobi step of the whole mesh's
    graph Laplacian): fewer CG iterations than plain aggregates, the same answer; the option
    that turns it off is read on ranks as serially."""
    material = snede.LinearElastic(1e5, 0.3)
    smoothed, plain = (loaded_body(material, refine=True) for _ in range(2))
    by_default = snede.StaticSolver(smoothed, "cg", rtol=1e-12, preconditioner="mg", comm=COMM).solve()
    unsmoothed = snede.StaticSolver(plain, "cg", rtol=1e-12, preconditioner="mg", comm=COMM,
                                    petsc_options={"mg_aggregation_smoothing": "false"}).solve()
    assert by_default.converged and unsmoothed.converged, (by_default, unsmoothed)
    assert by_default.iterations < unsmoothed.iterations, (by_default, unsmoothed)
    assert relative_difference(smoothed.displacement, plain.displacement) <= 1e-8


@pytest.mark.skipif(COMM.size == 1, reason="one rank factors the whole matrix")
def test_a_sequential_factorisation_on_ranks_names_the_block_version():
    with pytest.raises(ValueError, match=r"on \d MPI ranks use 'bjacobi'"):
        snede.StaticSolver(loaded_body(snede.LinearElastic(1e5, 0.3)), "cg", preconditioner="ilu", comm=COMM).solve()
    assert COMM.allreduce(1) == COMM.size


def test_solver_options_reach_every_rank_and_must_agree():
    """petsc_options, line_search and ncg_type apply on ranks as serially (one Newton iteration
    allowed: DIVERGED_MAX_IT on every rank); options that differ between the ranks raise the
    same ValueError on every rank, naming them."""
    body = loaded_body(snede.NeoHookean(1e5, 0.3))
    result = snede.StaticSolver(body, "newton", petsc_options={"snes_max_it": 1}, comm=COMM).solve()
    assert not result.converged and result.reason == "DIVERGED_MAX_IT" and result.iterations == 1, result
    assert snede.StaticSolver(loaded_body(snede.NeoHookean(1e5, 0.3)), "ncg", rtol=1e-6, ncg_type="fr",
                              line_search="snede_secant", comm=COMM).solve().converged
    if COMM.size > 1:
        mine = {"snes_max_it": 5 + COMM.rank}
        with pytest.raises(ValueError, match="petsc_options: rank 1 differs from rank 0"):
            snede.StaticSolver(loaded_body(snede.NeoHookean(1e5, 0.3)), "newton", petsc_options=mine,
                               comm=COMM).solve()
    assert COMM.allreduce(1) == COMM.size


def test_a_collective_series_reads_back_as_the_serial_mesh(tmp_path_factory):
    """SeriesWriter(comm=) and write_part after a distributed solve: rank 0 reads one series
    whose points, mapped by serial_vertex, carry the solved displacement."""
    folder = COMM.bcast(str(tmp_path_factory.mktemp("series")) if COMM.rank == 0 else None)
    body = loaded_body(snede.LinearElastic(1e5, 0.3))
    part = snede.distribute(body.mesh if COMM.rank == 0 else None, COMM)
    assert snede.StaticSolver(body, "cg", rtol=1e-10, comm=COMM).solve().converged
    writer = SeriesWriter(f"{folder}/cantilever", comm=COMM)
    writer.write_part(part, time=1.0, displacement=body.displacement[part.global_vertex])
    COMM.Barrier()
    if COMM.rank == 0:
        (step,) = read_series(writer.xdmf_path)
        serial = step.point_fields["serial_vertex"].astype(np.int64)
        np.testing.assert_array_equal(np.sort(serial), np.arange(body.mesh.n_points))
        np.testing.assert_allclose(step.mesh.points, body.mesh.points[serial])
        np.testing.assert_allclose(step.point_fields["displacement"], body.displacement[serial])
    COMM.Barrier()


def test_a_body_given_a_communicator_hands_it_to_its_solvers():
    """Body(..., comm=) makes StaticSolver(body) distributed (part set, the serial answer);
    a communicator that is not one is refused."""
    material = snede.LinearElastic(1e5, 0.3)
    mesh, _ = cantilever(3)
    fixed, tip, force = conditions(mesh)
    body = snede.Body(mesh, material, comm=COMM)
    body.fix(fixed)
    body.add_nodal_force(tip, force)
    body.add_gravity((0.0, 0.0, -1.0))
    solver = snede.StaticSolver(body, "cg", rtol=1e-12)
    assert solver.solve().converged
    assert solver.part is not None and solver.part.comm is COMM
    reference = loaded_body(material)
    assert snede.StaticSolver(reference, "cg", rtol=1e-12).solve().converged
    assert relative_difference(body.displacement, reference.displacement) <= 1e-7
    with pytest.raises(TypeError, match="mpi4py communicator"):
        snede.Body(cantilever(3)[0], material, comm=0)


def test_dynamic_relaxation_takes_up_a_body_changed_between_runs():
    """Relaxed, then moved back to rest (u = 0) or refined, the body is taken up anew by the
    next run (it used to relax the old state again): the run takes steps and ends at the
    static answer of the body as it is now."""
    material = snede.LinearElastic(1e5, 0.3)
    body = loaded_body(material)
    relaxation = snede.DynamicRelaxation(body, damping=1.5, comm=COMM)
    assert relaxation.run(rtol=1e-6, max_steps=20000).converged
    answer = body.displacement.copy()
    body.displacement = np.zeros_like(answer)
    again = relaxation.run(rtol=1e-6, max_steps=20000)
    assert again.converged and again.iterations > 0, again
    assert relative_difference(body.displacement, answer) <= 1e-4  # both within (6.9) at 1e-6
    body.mesh.refine_uniform()
    refined = relaxation.run(rtol=1e-6, max_steps=40000)
    assert refined.converged and refined.iterations > 0, refined
    reference = loaded_body(material, refine=True)
    assert snede.StaticSolver(reference, "cg", rtol=1e-10).solve().converged
    assert body.displacement.shape == reference.displacement.shape
    assert relative_difference(body.displacement, reference.displacement) <= 1e-4


ONE_RANK_EDITS = {
    "mesh": lambda body: body.mesh.refine_uniform(),
    "fixed vertices": lambda body: body.fix([int(np.argmax(body.mesh.points[:, 0]))]),
    "prescribed displacements": lambda body: body.fix(np.flatnonzero(body.mesh.points[:, 0] == 0.0), (0.0, 0.0, 1e-3)),
    "sliding vertices": lambda body: body.slide([int(np.argmax(body.mesh.points[:, 0]))], (1.0, 0.0, 0.0)),
    "nodal forces": lambda body: body.add_nodal_force([int(np.argmax(body.mesh.points[:, 0]))], (0.0, 1.0, 0.0)),
    "gravity": lambda body: body.add_gravity((0.0, 0.0, -2.0)),
    "displacement": lambda body: setattr(body, "displacement", np.full_like(body.displacement, 1e-4)),
}


@pytest.mark.skipif(COMM.size == 1, reason="needs a rank whose body differs")
@pytest.mark.parametrize("edited", ONE_RANK_EDITS)
def test_a_body_edited_on_one_rank_only_raises_on_every_rank(edited):
    """The last rank alone refines its body, loads it, holds or moves it otherwise: every rank
    raises the same ValueError naming what differs, before solving (rank 0's body was solved
    and the other ranks' conditions silently ignored)."""
    body = loaded_body(snede.LinearElastic(1e5, 0.3))
    if COMM.rank == COMM.size - 1:
        ONE_RANK_EDITS[edited](body)
    differs = rf"the ranks were given different inputs \({edited}[^)]*: rank {COMM.size - 1} differs from rank 0\)"
    with pytest.raises(ValueError, match=differs):
        snede.StaticSolver(body, "cg", rtol=1e-8, comm=COMM).solve()
    with pytest.raises(ValueError, match=differs):
        snede.DynamicRelaxation(body, damping=1.5, comm=COMM)
    assert COMM.allreduce(1) == COMM.size


@pytest.mark.skipif(COMM.size == 1, reason="needs a rank whose body differs")
def test_a_body_loaded_on_one_rank_between_relaxations_raises_on_every_rank():
    """A load added on the last rank alone after a relaxation: the next run raises on every
    rank, naming the nodal forces (rank 0 alone decided whether the body had changed, and the
    load was dropped)."""
    body = loaded_body(snede.LinearElastic(1e5, 0.3))
    relaxation = snede.DynamicRelaxation(body, damping=1.5, comm=COMM)
    assert relaxation.run(rtol=1e-3, max_steps=20000).converged
    if COMM.rank == COMM.size - 1:
        ONE_RANK_EDITS["nodal forces"](body)
    with pytest.raises(ValueError, match=rf"\(nodal forces: rank {COMM.size - 1} differs from rank 0\)"):
        relaxation.run(rtol=1e-3, max_steps=20000)
    assert COMM.allreduce(1) == COMM.size
