"""The other solvers of a DistributedStatic on 1, 2 and 3 ranks: nonlinear CG, GAMG, and
dynamic relaxation (DistributedRelaxation). Each is compared with the same solve on every
rank alone (COMM_SELF, the whole mesh) and with snede's serial solvers."""
import numpy as np
import pytest
from mpi4py import MPI

import snede
from cantilever_problems import cantilever, conditions, linear_cantilever_problem, serial_solution

COMM = MPI.COMM_WORLD


def relative_difference(u, v):
    return np.abs(u - v).max() / np.abs(v).max()


@pytest.mark.parametrize("dim", [3, 2])
def test_nonlinear_cg_gives_the_serial_newton_displacement(dim):
    """A neo-Hookean cantilever by nonlinear CG (secant line search, §4.4.2) on this
    communicator: converged, and the serial Newton solution to 1e-7 relative."""
    serial, thickness = cantilever(dim)
    fixed, tip, force = conditions(serial)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    material = snede.NeoHookean(1e5, 0.3)
    problem = snede.DistributedStatic(part, material, thickness=thickness, fixed=fixed,
                                      forces={int(v): force for v in tip})
    result = problem.solve("ncg", rtol=1e-11, max_iterations=20000)
    assert result.converged, result
    assert set(COMM.allgather(result.reason)) == {result.reason}
    expected = serial_solution(cantilever(dim)[0], material, thickness, "newton")
    assert relative_difference(problem.gathered_displacement(), expected) <= 1e-7


def test_nonlinear_cg_refuses_a_preconditioner():
    problem = linear_cantilever_problem(COMM)
    with pytest.raises(ValueError, match="takes no preconditioner"):
        problem.solve("ncg", preconditioner="jacobi")


def test_gamg_converges_in_fewer_iterations_than_jacobi_to_the_same_displacement():
    """CG preconditioned by GAMG on the assembled MPIAIJ tangent (its rigid-body near null
    space from the owned coordinates): fewer iterations than Jacobi, the serial solution.
    GAMG's aggregates depend on the partition, so its count may differ between rank counts."""
    gamg = linear_cantilever_problem(COMM)
    result = gamg.solve("cg", rtol=1e-10, preconditioner="gamg", options_prefix="gamg_")
    jacobi = linear_cantilever_problem(COMM).solve("cg", rtol=1e-10, preconditioner="jacobi")
    assert result.converged, result
    assert result.iterations < jacobi.iterations
    expected = serial_solution(cantilever(3)[0], snede.LinearElastic(1e5, 0.3), None, "cg")
    assert relative_difference(gamg.gathered_displacement(), expected) <= 1e-7


def test_newton_with_gamg_on_a_neo_hookean_cantilever():
    serial, _ = cantilever(3)
    fixed, tip, force = conditions(serial)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    material = snede.NeoHookean(1e5, 0.3)
    problem = snede.DistributedStatic(part, material, fixed=fixed, forces={int(v): force for v in tip})
    result = problem.solve("newton", rtol=1e-11, preconditioner="gamg", options_prefix="gamg_newton_")
    assert result.converged, result
    expected = serial_solution(cantilever(3)[0], material, None, "newton")
    assert relative_difference(problem.gathered_displacement(), expected) <= 1e-7


def test_dynamic_relaxation_takes_the_same_steps_on_every_rank_count():
    """Dynamic relaxation of the linear cantilever (η near 2ω₁, the CFL step): on this
    communicator and on each rank alone, the same time step, the same number of steps and
    the same displacement to 1e-10 relative (only the order of the ghosts' sums differs);
    (6.9) met, and the static solution to within what rtol allows."""
    together, alone = linear_cantilever_problem(COMM), linear_cantilever_problem(MPI.COMM_SELF)
    relax_together = snede.DistributedRelaxation(together, damping=1.5)
    relax_alone = snede.DistributedRelaxation(alone, damping=1.5, options_prefix="alone_")
    assert relax_together.dt == relax_alone.dt
    shared = relax_together.run(rtol=1e-6, max_steps=20000)
    single = relax_alone.run(rtol=1e-6, max_steps=20000)
    assert shared.converged and single.converged, (shared, single)
    assert shared.reason == "CONVERGED_FNORM_ABS" and shared.residual_norm <= shared.tolerance
    assert shared.iterations == single.iterations > 100
    u = together.gathered_displacement()
    assert relative_difference(u, alone.gathered_displacement()) <= 1e-10
    expected = serial_solution(cantilever(3)[0], snede.LinearElastic(1e5, 0.3), None, "cg")
    assert relative_difference(u, expected) <= 1e-3


def test_dynamic_relaxation_matches_the_serial_dynamic_relaxation():
    """The serial DynamicRelaxation on the same body, η and step: the same number of steps and
    the same displacement (the two implementations share the integrator and (6.9))."""
    problem = linear_cantilever_problem(COMM)
    relaxation = snede.DistributedRelaxation(problem, damping=1.5)
    result = relaxation.run(rtol=1e-6, max_steps=20000)
    serial, _ = cantilever(3)
    fixed, tip, force = conditions(serial)
    body = snede.Body(serial, snede.LinearElastic(1e5, 0.3), density=1000.0)
    body.fix(fixed)
    body.add_nodal_force(tip, force)
    reference = snede.DynamicRelaxation(body, damping=1.5, dt=relaxation.dt).run(rtol=1e-6, max_steps=20000)
    assert reference.converged and result.converged
    assert result.iterations == reference.iterations
    assert relative_difference(problem.gathered_displacement(), body.displacement) <= 1e-10


def test_dynamic_relaxation_reports_a_blow_up_on_every_rank():
    """Three times the CFL step is unstable: DIVERGED_BLOW_UP on every rank, not converged."""
    problem = linear_cantilever_problem(COMM)
    cfl = snede.DistributedRelaxation(problem, damping=0.0).dt
    result = snede.DistributedRelaxation(problem, damping=0.0, dt=3 * cfl, options_prefix="unstable_").run(
        rtol=1e-6, max_steps=20000)
    assert not result.converged
    assert set(COMM.allgather(result.reason)) == {"DIVERGED_BLOW_UP"}


def test_dynamic_relaxation_reads_its_own_petsc_options_on_every_rank():
    """petsc_options reach the distributed TS as the serial one's (one engine since issue 36):
    a step given as -ts_dt for this solver only, and a damping option, taken on every rank."""
    problem = linear_cantilever_problem(COMM)
    cfl = snede.DistributedRelaxation(problem, damping=1.5).dt
    halved = snede.DistributedRelaxation(problem, damping=1.5, options_prefix="halved_",
                                         petsc_options={"ts_dt": 0.5 * cfl, "ts_ss22_damping": 3.0})
    assert COMM.allgather(halved.dt) == [0.5 * cfl] * COMM.size
    assert halved._impl.damping == 3.0
    assert snede.DistributedRelaxation(problem, damping=1.5, options_prefix="halved_").dt == cfl


def test_dynamic_relaxation_refuses_bad_parameters_everywhere():
    problem = linear_cantilever_problem(COMM)
    with pytest.raises(ValueError, match="dt must be positive"):
        snede.DistributedRelaxation(problem, damping=1.0, dt=-1.0)
    with pytest.raises(ValueError, match="damping"):
        snede.DistributedRelaxation(problem, damping=-1.0)
    assert COMM.allreduce(1) == COMM.size


def test_gravity_loads_the_element_masses_as_serially():
    """A neo-Hookean cantilever sagging under its own weight (ρ = 1000, g = 9.81 down), Newton
    with GAMG: the serial Body.add_gravity solve's displacement to 1e-7 relative; a gravity of
    the wrong length is refused on every rank."""
    serial, _ = cantilever(3)
    fixed, _, _ = conditions(serial)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    material = snede.NeoHookean(1e5, 0.3)
    problem = snede.DistributedStatic(part, material, density=1000.0, fixed=fixed, gravity=(0.0, 0.0, -9.81))
    result = problem.solve("newton", rtol=1e-11, preconditioner="gamg")
    assert result.converged, result
    body = snede.Body(cantilever(3)[0], material, density=1000.0)
    body.fix(fixed)
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "newton", rtol=1e-12).solve().converged
    assert relative_difference(problem.gathered_displacement(), body.displacement) <= 1e-7
    with pytest.raises(ValueError, match="gravity needs 3 components"):
        snede.DistributedStatic(part, material, fixed=fixed, gravity=(0.0, -9.81))


@pytest.mark.parametrize("material, method", [(snede.LinearElastic(1e5, 0.3), "cg"),
                                              (snede.NeoHookean(1e5, 0.3), "newton")], ids=["linear-cg", "neohookean-newton"])
def test_the_displacement_does_not_depend_on_the_rank_count(material, method):
    """The issue's equality: this communicator against every rank alone, to 1e-10 relative
    (both solved to rtol 1e-12; only the order of the ghosts' sums differs)."""
    serial, _ = cantilever(3)
    fixed, tip, force = conditions(serial)
    solutions = []
    for comm, prefix in ((COMM, "together_"), (MPI.COMM_SELF, "alone_")):
        part = snede.distribute(serial if comm.rank == 0 else None, comm)
        problem = snede.DistributedStatic(part, material, fixed=fixed, forces={int(v): force for v in tip})
        assert problem.solve(method, rtol=1e-12, options_prefix=prefix).converged
        solutions.append(problem.gathered_displacement())
    assert relative_difference(*solutions) <= 1e-10


@pytest.mark.parametrize("method, preconditioner", [("cg", "jacobi"), ("newton", "gamg")])
def test_the_serial_criteria_apply_to_the_true_residual(method, preconditioner):
    """criterion "6.8": ‖F‖ ≤ rtol·‖f_ext‖ on the recomputed residual whatever the
    preconditioner's norm; the threshold is rtol times the tip loads' norm (200 N over the tip
    vertices)."""
    serial, _ = cantilever(3)
    _, tip, force = conditions(serial)
    external = np.sqrt(len(tip)) * np.linalg.norm(force)
    problem = linear_cantilever_problem(COMM)
    result = problem.solve(method, rtol=1e-7, preconditioner=preconditioner, criterion="6.8")
    assert result.converged, result
    assert result.tolerance == pytest.approx(1e-7 * external, rel=1e-12)
    assert result.residual_norm <= 2 * result.tolerance
    expected = serial_solution(serial, snede.LinearElastic(1e5, 0.3), None, "cg")
    assert relative_difference(problem.gathered_displacement(), expected) <= 1e-5


def test_a_solve_starts_from_a_displacement_set_on_every_rank():
    """set_displacement(u*) with the answer: the next solve stops at once; bad shapes or
    criteria raise the same ValueError on every rank."""
    problem = linear_cantilever_problem(COMM)
    assert problem.solve("cg", rtol=1e-10, criterion="6.9").converged
    answer = problem.gathered_displacement()
    fresh = linear_cantilever_problem(COMM)
    fresh.set_displacement(answer)
    result = fresh.solve("cg", rtol=1e-9, criterion="6.9")
    assert result.converged and result.iterations == 0, result
    with pytest.raises(ValueError, match=r"displacement must be \(\d+, 3\)"):
        fresh.set_displacement(answer[:-1])
    with pytest.raises(ValueError, match="criterion must be"):
        fresh.solve("cg", criterion="6.10")
    assert COMM.allreduce(1) == COMM.size


def test_a_solve_takes_a_record_whole_and_keywords_change_its_fields():
    """DistributedStatic.solve forwards (issue 51): a StaticOptions record given whole, a
    keyword changing one field, and the defaults (linear CG to ε‖r(u₀)‖) the engine's."""
    record = snede.StaticOptions(method="cg", rtol=1e-10, criterion="6.8", options_prefix="whole_dstatic_")
    whole = linear_cantilever_problem(COMM).solve(options=record)
    looser = linear_cantilever_problem(COMM).solve(options=record, rtol=1e-4)
    assert whole.converged and looser.converged, (whole, looser)
    assert looser.tolerance == pytest.approx(whole.tolerance * 1e6, rel=1e-12)  # (6.8): rtol·‖f_ext‖
    assert looser.iterations < whole.iterations
    # No record: the engine's defaults, the same solve as with its default record given whole.
    default = linear_cantilever_problem(COMM).solve()
    explicit = linear_cantilever_problem(COMM).solve(options=snede._snede.distributed_solve_options())
    assert default.converged and default.residual_norm <= default.tolerance, default
    assert (default.iterations, default.reason) == (explicit.iterations, explicit.reason)
    with pytest.raises(TypeError, match="options must be a snede.StaticOptions"):
        linear_cantilever_problem(COMM).solve(options={"rtol": 1e-3})


@pytest.mark.parametrize("preconditioner", ["bjacobi", "sor"])
def test_local_preconditioners_on_the_assembled_tangent(preconditioner):
    """Block Jacobi (ILU(0) on each rank's block) and SOR (symmetric sweeps over each rank's
    rows) of the MPIAIJ tangent: fewer CG iterations than none, the serial solution; on one
    rank they are the serial ILU(0) and SSOR."""
    problem = linear_cantilever_problem(COMM)
    result = problem.solve("cg", rtol=1e-10, preconditioner=preconditioner, criterion="6.9")
    plain = linear_cantilever_problem(COMM).solve("cg", rtol=1e-10, criterion="6.9")
    assert result.converged and plain.converged, (result, plain)
    assert result.iterations < plain.iterations
    expected = serial_solution(cantilever(3)[0], snede.LinearElastic(1e5, 0.3), None, "cg")
    assert relative_difference(problem.gathered_displacement(), expected) <= 1e-7


def test_lu_by_mumps_solves_the_linear_body_in_one_iteration():
    """LU factors of the assembled tangent (MUMPS, in parallel): CG preconditioned by the exact
    inverse converges in one iteration, to the serial solution."""
    problem = linear_cantilever_problem(COMM)
    result = problem.solve("cg", rtol=1e-10, preconditioner="lu", criterion="6.9")
    assert result.converged and result.iterations == 1, result
    expected = serial_solution(cantilever(3)[0], snede.LinearElastic(1e5, 0.3), None, "cg")
    assert relative_difference(problem.gathered_displacement(), expected) <= 1e-8
