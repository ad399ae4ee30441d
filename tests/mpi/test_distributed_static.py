"""snede.DistributedStatic on 1, 2 and 3 ranks (see test_distribute.py for how they run): a
cantilever loaded at its tip, linear (cg, no preconditioner) and neo-Hookean (Newton). Every
rank count gives the displacement snede's serial StaticSolver gives on the whole mesh (to
1e-8 relative: both stop at their own rtol 1e-12), the same CG iteration count, and the same
energy; a bar in 2D (plane stress) too. Collective calls are made on every rank."""
import numpy as np
import pytest
from mpi4py import MPI

import snede
from cantilever_problems import cantilever, conditions, linear_cantilever_problem, serial_solution

COMM = MPI.COMM_WORLD


@pytest.mark.parametrize("dim", [3, 2])
@pytest.mark.parametrize("material, method", [(snede.LinearElastic(1e5, 0.3), "cg"),
                                              (snede.NeoHookean(1e5, 0.3), "newton")], ids=["linear-cg", "neohookean-newton"])
def test_every_rank_count_gives_the_serial_displacement(dim, material, method):
    serial, thickness = cantilever(dim)
    fixed, tip, force = conditions(serial)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    problem = snede.DistributedStatic(part, material, thickness=thickness, fixed=fixed,
                                      forces={int(v): force for v in tip})
    result = problem.solve(method, rtol=1e-12)
    assert result.converged, result
    u = problem.gathered_displacement()
    expected = serial_solution(cantilever(dim)[0], material, thickness, method)
    assert np.abs(u - expected).max() <= 1e-8 * np.abs(expected).max()
    # What every rank holds agrees with the gathered field, ghosts included.
    np.testing.assert_array_equal(problem.local_displacement(), u[part.global_vertex])
    # The same numbers on every rank count: iterations (CG) and energy.
    energy = problem.energy()
    assert len(set(COMM.allgather(round(energy, 9)))) == 1
    if method == "cg":
        assert len(set(COMM.allgather(result.iterations))) == 1


@pytest.mark.parametrize("preconditioner", ["none", "jacobi"])
def test_iteration_count_and_energy_do_not_depend_on_the_rank_count(preconditioner):
    """The linear cantilever's CG iteration count and energy, solved on this communicator and
    on every rank alone: equal (energy to 1e-12 relative); Jacobi, its diagonal summed across
    the ranks, takes fewer iterations than none and gives the serial StaticSolver's answer."""
    together, alone = linear_cantilever_problem(COMM), linear_cantilever_problem(MPI.COMM_SELF)
    shared = together.solve("cg", rtol=1e-10, preconditioner=preconditioner)
    single = alone.solve("cg", rtol=1e-10, preconditioner=preconditioner, options_prefix="alone_")
    # CG's iterates on N ranks and on one differ by the order of the dot products' sums; after
    # it loses orthogonality (163 iterations unpreconditioned) that moves the step where ‖r‖
    # crosses rtol: 164 against 163 in the portable build. Equal to 2 %.
    assert shared.converged and abs(shared.iterations - single.iterations) <= max(1, 0.02 * single.iterations)
    assert together.energy() == pytest.approx(alone.energy(), rel=1e-12)
    if preconditioner == "jacobi":
        plain = linear_cantilever_problem(MPI.COMM_SELF).solve("cg", rtol=1e-10, options_prefix="plain_")
        assert shared.iterations < plain.iterations
        expected = serial_solution(cantilever(3)[0], snede.LinearElastic(1e5, 0.3), None, "cg")
        u = together.gathered_displacement()
        assert np.abs(u - expected).max() <= 1e-7 * np.abs(expected).max()


def test_an_inverted_element_is_never_converged():
    """A neo-Hookean bar whose end is held 1.5 lengths back, through the bar: the elements next
    to it are inverted (on whichever rank holds them), every rank flags the residual as outside
    its domain (and NaN), and every rank reports the final state's verdict, as the serial solver
    does: DIVERGED_INVERTED_ELEMENTS."""
    serial, _ = cantilever(3)
    x = serial.points
    fixed = np.flatnonzero(np.isclose(x[:, 0], 0.0) | np.isclose(x[:, 0], 4.0))
    values = np.zeros((len(fixed), 3))
    values[np.isclose(x[fixed, 0], 4.0), 0] = -6.0
    part = snede.distribute(serial if COMM.rank == 0 else None)
    problem = snede.DistributedStatic(part, snede.NeoHookean(1e5, 0.3), fixed=fixed, fixed_values=values)
    result = problem.solve("newton", rtol=1e-10, max_iterations=20)
    assert not result.converged
    assert set(COMM.allgather(result.reason)) == {"DIVERGED_INVERTED_ELEMENTS"}


@pytest.mark.parametrize("method", ["cg", "newton", "ncg"])
def test_a_solve_from_the_converged_state_stops_at_once_as_serially(method):
    """Solved once (PETSc's relative test, the default), the cantilever is in equilibrium:
    solved again it stops at once, converged and unmoved, as the serial StaticSolver does
    (Newton and nonlinear CG ended DIVERGED_LINE_SEARCH: ‖F‖ ≤ rtol·‖F(u₀)‖ asked a residual
    already at round-off for rtol of itself)."""
    serial, _ = cantilever(3)
    fixed, tip, force = conditions(serial)
    material = snede.LinearElastic(1e5, 0.3) if method == "cg" else snede.NeoHookean(1e5, 0.3)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    problem = snede.DistributedStatic(part, material, fixed=fixed, forces={int(v): force for v in tip})
    assert problem.solve(method, rtol=1e-8, max_iterations=20000).converged
    answer = problem.gathered_displacement()
    again = problem.solve(method, rtol=1e-8, max_iterations=20000)
    assert again.converged and again.iterations == 0, again
    np.testing.assert_array_equal(problem.gathered_displacement(), answer)
    body = snede.Body(cantilever(3)[0], material)
    body.fix(fixed)
    body.add_nodal_force(tip, force)
    solver = snede.StaticSolver(body, method, preconditioner="none", rtol=1e-8, max_iterations=20000)
    assert solver.solve().converged
    serial_again = solver.solve()
    assert serial_again.converged and serial_again.iterations == 0, serial_again


def test_bad_conditions_raise_the_same_error_everywhere():
    serial, _ = cantilever(3)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    with pytest.raises(ValueError, match="is not a vertex of the serial mesh"):
        snede.DistributedStatic(part, snede.LinearElastic(1e5, 0.3), fixed=[len(serial.points)])
    with pytest.raises(ValueError, match="fixed_values must be"):
        snede.DistributedStatic(part, snede.LinearElastic(1e5, 0.3), fixed=[0, 1], fixed_values=np.zeros((3, 3)))
    assert COMM.allreduce(1) == COMM.size


@pytest.mark.skipif(COMM.size == 1, reason="needs ranks that disagree")
@pytest.mark.parametrize("disagreement", ["fixed", "forces", "material", "gravity", "thickness"])
def test_ranks_given_different_inputs_raise_the_same_error(disagreement):
    """Each rank passes its own fixed vertex, force, stiffness or gravity: the same ValueError
    everywhere, naming the argument and the first rank that differs from rank 0 (a rank left
    out would otherwise solve another problem, or wait)."""
    serial, _ = cantilever(3)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    own = 1.0 + COMM.rank  # differs between ranks
    inputs = {"material": snede.LinearElastic(1e5, 0.3), "fixed": [0], "forces": {5: (0.0, 0.0, -1.0)}, "gravity": None,
              "thickness": None}
    inputs[disagreement] = {"fixed": [0, COMM.rank + 1], "forces": {5: (0.0, 0.0, -own)},
                            "material": snede.LinearElastic(1e5 * own, 0.3), "gravity": (0.0, 0.0, -9.81 * own),
                            "thickness": None if COMM.rank == 0 else 0.1}[disagreement]
    differs = rf"the ranks were given different inputs \({disagreement}: rank 1 differs from rank 0\)"
    with pytest.raises(ValueError, match=differs):
        snede.DistributedStatic(part, **inputs)
    assert COMM.allreduce(1) == COMM.size


@pytest.mark.skipif(COMM.size == 1, reason="needs a rank that differs")
def test_a_python_argument_error_on_one_rank_reaches_every_rank():
    """fixed_values of the wrong shape on the last rank only: every rank raises its ValueError,
    naming that rank, instead of the others waiting for it in the engine."""
    serial, _ = cantilever(3)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    rows = 3 if COMM.rank == COMM.size - 1 else 2
    with pytest.raises(ValueError, match=rf"rank {COMM.size - 1}: fixed_values must be \(2, 3\)"):
        snede.DistributedStatic(part, snede.LinearElastic(1e5, 0.3), fixed=[0, 1], fixed_values=np.zeros((rows, 3)))
    assert COMM.allreduce(1) == COMM.size


@pytest.mark.skipif(COMM.size == 1, reason="needs a rank that differs")
def test_a_rank_given_no_part_raises_on_every_rank():
    """The last rank passes None for its part (it has no communicator to report on): it
    reports on the world's, which is the part's, and every rank raises its TypeError."""
    serial, _ = cantilever(3)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    mine = None if COMM.rank == COMM.size - 1 else part
    with pytest.raises(TypeError, match=rf"rank {COMM.size - 1}: part must be a DistributedMesh"):
        snede.DistributedStatic(mine, snede.LinearElastic(1e5, 0.3), fixed=[0, 1, 2])
    assert COMM.allreduce(1) == COMM.size


@pytest.mark.skipif(COMM.size == 1, reason="needs ranks that disagree")
def test_solver_arguments_that_differ_between_ranks_raise_everywhere():
    """A tolerance, a method or a damping that differs between ranks would make the ranks leave
    CG at different iterations and wait for each other: the same ValueError instead."""
    problem = linear_cantilever_problem(COMM)
    with pytest.raises(ValueError, match=r"StaticSolver: the ranks were given different inputs \(rtol:"):
        problem.solve("cg", rtol=1e-8 * (1 + COMM.rank))
    with pytest.raises(ValueError, match=r"rank 1: method must be 'cg', 'ncg' or 'newton', got 'bicg'"):
        problem.solve("cg" if COMM.rank == 0 else "bicg")  # rank 1's is checked (and refused) on every rank
    with pytest.raises(ValueError, match=r"the ranks were given different inputs \(method: rank 1"):
        problem.solve("cg" if COMM.rank == 0 else "newton")
    with pytest.raises(ValueError, match=r"DynamicRelaxation: the ranks were given different inputs \(damping:"):
        snede.DistributedRelaxation(problem, damping=1.0 + COMM.rank)
    with pytest.raises(ValueError, match=f"rank {COMM.size - 1}: dt must be positive"):
        snede.DistributedRelaxation(problem, damping=1.0, dt=-1.0 if COMM.rank == COMM.size - 1 else None)
    with pytest.raises(TypeError, match="rank 0: material must be"):
        snede.DistributedStatic(problem.part, "rubber" if COMM.rank == 0 else snede.LinearElastic(1e5, 0.3))
    assert problem.solve("cg", rtol=1e-8).converged  # and the problem still solves
    assert COMM.allreduce(1) == COMM.size


def test_parts_touching_at_a_single_vertex():
    """Two tetrahedra sharing only a vertex (one per rank on 2 ranks): the shared vertex is
    owned once, and a solve with each held on two fixed corners and a third sliding along z
    (two fixed corners alone leave each free to turn about the line through them, both turning
    together about the shared vertex: issue 48 item 1), the sliding corners and the shared one
    pulled, gives the serial displacement."""
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1.0]])
    serial = snede.Mesh(points, [[0, 1, 2, 3], [0, 4, 6, 5]])
    part = snede.distribute(serial if COMM.rank == 0 else None)
    owners = np.concatenate(COMM.allgather(part.global_vertex[part.owned]))
    np.testing.assert_array_equal(np.sort(owners), np.arange(7))
    if COMM.size == 2:
        assert COMM.allgather(part.local.n_cells) == [1, 1]  # PETSc's partitioner splits them
    material = snede.LinearElastic(1e5, 0.3)
    fixed, forces = [1, 2, 4, 5], {3: (0.0, 0.0, 10.0), 6: (0.0, 0.0, -10.0), 0: (5.0, 0.0, 0.0)}
    sliding, along_z = [3, 6], [(0.0, 0.0, 1.0)] * 2
    problem = snede.DistributedStatic(part, material, fixed=fixed, sliding=sliding, sliding_directions=along_z,
                                      forces=forces)
    result = problem.solve("cg", rtol=1e-12)
    assert result.converged, result
    body = snede.Body(snede.Mesh(points, [[0, 1, 2, 3], [0, 4, 6, 5]]), material)
    body.fix(fixed)
    body.slide(sliding, along_z[0])
    for vertex, force in forces.items():
        body.add_nodal_force([vertex], force)
    assert snede.StaticSolver(body, "cg", preconditioner="none", rtol=1e-12).solve().converged
    np.testing.assert_allclose(problem.gathered_displacement(), body.displacement, rtol=0,
                               atol=1e-9 * np.abs(body.displacement).max())
