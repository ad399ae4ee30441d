"""Benchmark (issue 18): a distributed static solve on 1 or N ranks, and the ghost exchange
it costs per tangent product. Run it under mpirun, once per rank count, and compare:

    mpirun -n 1 .venv/bin/python studies/benchmarks/distributed_scaling.py [--divisions 55] [--iterations 100]
    mpirun -n 2 .venv/bin/python studies/benchmarks/distributed_scaling.py [--divisions 55] [--iterations 100]

(as root: OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1). The body is the unit
cube as n × n × n Kuhn cubes (6 n³ tetrahedra; n = 55: 998 250), linear elastic, fixed at
x = 0 and pulled at x = 1; CG without a preconditioner runs a fixed number of iterations (its
"DIVERGED_ITS" is the point: the same work on every rank count). Printed: the distribution's
time, cells and owned/ghost vertices per rank, the bytes each rank sends and receives per
tangent product (each ghost's dim values in, its dim contributions out: 2 · ghosts · dim · 8),
and the seconds per CG iteration (the slowest rank's). Not a test; the machine has 2 cores,
so 2 ranks is the most that can show a speed-up.

With --made-on-ranks the box is made on the ranks (snede.meshing.box(..., comm=), issue 52): no
rank holds the whole mesh at any time; without it rank 0 makes the serial box and DMPlex
distributes it. With --serial the same box and CG run on the serial Body and StaticSolver (one
process; run it without mpirun). Every mode prints each rank's peak resident memory (MB, the
process's ru_maxrss: Python, PETSc and the mesh included), the figure to compare between
--serial and --made-on-ranks on 2 ranks at the same --divisions.

With --newton (and --made-on-ranks) a neo-Hookean cube (E = 10 MPa, ν = 0.3, 1000 kg/m³) held
at x = 0 sags under gravity: truncated Newton with Jacobi-preconditioned CG to rtol 1e-6 (6.9),
the issue-52 goal's solve (≥ 1.5·10⁷ tetrahedra on 2 ranks: --divisions 136).

With --to-tolerance the same body is instead solved to ‖r‖ ≤ 1e-8 ‖r₀‖ by CG with each
preconditioner (none, Jacobi, GAMG on the assembled MPIAIJ tangent, mg by aggregation of each
rank's vertices, block Jacobi, SOR, MUMPS's LU): iterations and seconds, assembly and set-up
included; with --serial too, on the serial StaticSolver (its mg: grid levels) to the same criterion,
the reference of the issue-52 goal "2 ranks ≥ 1.8× serial with mg". --preconditioners picks some. With --cantilever N the same comparison runs on the
slender `cantilever` scene (--divisions N) through StaticSolver(body, "cg", comm=...).
"""
from __future__ import annotations

import argparse
import resource
import time

import numpy as np
from mpi4py import MPI

import snede


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--divisions", type=int, default=30, help="n: 6 n³ tetrahedra (default 30: 162 000)")
    parser.add_argument("--iterations", type=int, default=100, help="CG iterations to time (default 100)")
    parser.add_argument("--to-tolerance", action="store_true", help="compare preconditioners solving to rtol 1e-8")
    parser.add_argument("--cantilever", type=int, metavar="N", help="compare them on the cantilever scene instead")
    parser.add_argument("--made-on-ranks", action="store_true", help="make the box on the ranks (no rank holds it whole)")
    parser.add_argument("--serial", action="store_true", help="the serial Body and StaticSolver instead (no mpirun)")
    parser.add_argument("--newton", action="store_true", help="a neo-Hookean cube under gravity by Newton instead")
    parser.add_argument("--preconditioners", default=",".join(PRECONDITIONERS),
                        help=f"with --to-tolerance, which to compare (default {','.join(PRECONDITIONERS)}; 'lu' "
                             "factors the whole tangent: minutes from 10⁵ tetrahedra)")
    arguments, _ = parser.parse_known_args()
    comm = MPI.COMM_WORLD
    if arguments.cantilever:
        compare_on_cantilever(arguments.cantilever, comm)
        return
    n = arguments.divisions
    if arguments.serial:
        if arguments.to_tolerance:
            compare_serially(n, arguments.preconditioners.split(","))
        else:
            solve_serially(n, arguments.iterations)
        return
    comm.Barrier()
    start = time.perf_counter()
    if arguments.made_on_ranks:
        part = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n), comm=comm, max_cells=6 * n**3)
    else:
        serial = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n), max_cells=6 * n**3) if comm.rank == 0 else None
        part = snede.distribute(serial, comm)
        del serial
    distribute_seconds = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    mesh_megabytes = resident_megabytes()
    x = part.local.points
    # Conditions by serial id, the same on every rank, picked on each rank's own points.
    fixed = part.vertices_where(lambda x: x[:, 0] == 0.0)
    pulled = part.vertices_where(lambda x: x[:, 0] == 1.0)
    def problem():
        return snede.DistributedStatic(part, snede.LinearElastic(1e5, 0.3), fixed=fixed,
                                       forces={int(v): (1.0 / len(pulled), 0.0, 0.0) for v in pulled})

    if arguments.to_tolerance:
        compare_preconditioners(problem, comm, part, arguments.preconditioners.split(","))
        return
    if arguments.newton:
        sag_under_gravity(part, fixed, distribute_seconds, comm)
        return
    problem = problem()
    problem_megabytes = resident_megabytes()
    comm.Barrier()
    result = problem.solve("cg", rtol=1e-30, round_tolerance=0.0, max_iterations=arguments.iterations)
    seconds = comm.allreduce(result.seconds, op=MPI.MAX)
    ghosts = int((~part.owned).sum())
    rows = comm.gather((comm.rank, part.local.n_cells, int(part.owned.sum()), ghosts, 2 * ghosts * 3 * 8,
                        mesh_megabytes, problem_megabytes, peak_megabytes()), root=0)
    if comm.rank == 0:
        made = "made on the ranks" if arguments.made_on_ranks else "distributed from rank 0"
        print(f"{comm.size} rank(s), {part.n_global_cells} tetrahedra, {part.n_global_vertices} vertices; "
              f"{made} in {distribute_seconds:.2f} s; CG {result.iterations} iterations ({result.reason}) in "
              f"{seconds:.3f} s: {1e3 * seconds / max(result.iterations, 1):.2f} ms per iteration")
        print(f"{'rank':>4} {'cells':>9} {'owned':>9} {'ghosts':>7} {'bytes/product':>14} {'MB with mesh':>12} "
              f"{'with problem':>12} {'peak MB':>8}")
        for rank, cells, owned, ghosts, volume, with_mesh, with_problem, peak in rows:
            print(f"{rank:>4} {cells:>9} {owned:>9} {ghosts:>7} {volume:>14} {with_mesh:>12.0f} {with_problem:>12.0f} "
                  f"{peak:>8.0f}")
        print(f"(x spans {x[:, 0].min():.2f}..{x[:, 0].max():.2f} on rank 0)")


def sag_under_gravity(part, fixed, made_seconds: float, comm) -> None:
    problem = snede.DistributedStatic(part, snede.NeoHookean(1e7, 0.3), density=1000.0, fixed=fixed,
                                      gravity=(0.0, 0.0, -9.81))
    comm.Barrier()
    result = problem.solve("newton", rtol=1e-6, criterion="6.9", preconditioner="jacobi", max_iterations=50)
    seconds = comm.allreduce(result.seconds, op=MPI.MAX)
    peaks = comm.gather(peak_megabytes(), root=0)
    if comm.rank == 0:
        print(f"{comm.size} rank(s), {part.n_global_cells} neo-Hookean tetrahedra: mesh in {made_seconds:.1f} s; Newton "
              f"{result.iterations} steps, {result.linear_iterations} CG iterations, {result.reason} "
              f"(converged {result.converged}) in {seconds:.1f} s; peak MB per rank: "
              + ", ".join(f"{peak:.0f}" for peak in peaks))


def resident_megabytes() -> float:
    """This process's resident memory now (Linux's /proc/self/statm, in pages of 4 kB)."""
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * 4096 / 2**20


def peak_megabytes() -> float:
    """This process's peak resident memory so far (Linux reports ru_maxrss in kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def serial_body(n: int):
    """The box and conditions on the serial Body."""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n), max_cells=6 * n**3)
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3))
    x = mesh.points
    body.fix(x[:, 0] == 0.0)
    pulled = np.flatnonzero(x[:, 0] == 1.0)
    body.add_nodal_force(pulled, np.tile((1.0 / len(pulled), 0.0, 0.0), (len(pulled), 1)))
    return body


def compare_serially(n: int, preconditioners) -> None:
    """--serial --to-tolerance: the distributed comparison's solves on the serial StaticSolver,
    to the same criterion (‖r‖ ≤ 1e-8 ‖r₀‖), with the preconditioners both routes have."""
    rows = []
    for preconditioner in preconditioners:
        body = serial_body(n)
        solver = snede.StaticSolver(body, "cg", rtol=1e-8, criterion="relative", max_iterations=100000,
                                    preconditioner=preconditioner)
        rows.append((preconditioner, solver.solve()))
    print_comparison(f"serial, {body.mesh.n_cells} tetrahedra: CG to rtol 1e-8", rows, MPI.COMM_SELF)
    print(f"(mg: {solver.multigrid_source} levels, unknowns {solver.multigrid_unknowns})")


def solve_serially(n: int, iterations: int) -> None:
    """The same box, conditions and CG iterations on the serial Body and StaticSolver."""
    start = time.perf_counter()
    body = serial_body(n)
    mesh, x = body.mesh, body.mesh.points
    made = time.perf_counter() - start
    with_body = resident_megabytes()
    result = snede.StaticSolver(body, "cg", rtol=1e-30, round_tolerance=0.0, max_iterations=iterations,
                                preconditioner="none").solve()
    print(f"serial, {mesh.n_cells} tetrahedra, {len(x)} vertices; made in {made:.2f} s; CG {result.iterations} "
          f"iterations ({result.reason}) in {result.seconds:.3f} s: "
          f"{1e3 * result.seconds / max(result.iterations, 1):.2f} ms per iteration; {with_body:.0f} MB with the body, "
          f"peak {peak_megabytes():.0f} MB")


PRECONDITIONERS = ("none", "jacobi", "gamg", "mg", "bjacobi", "sor", "lu")


def compare_preconditioners(problem, comm, part, preconditioners) -> None:
    rows = []
    for preconditioner in preconditioners:
        solve = problem()
        comm.Barrier()
        result = solve.solve("cg", rtol=1e-8, max_iterations=100000, preconditioner=preconditioner)
        rows.append((preconditioner, result))
    print_comparison(f"{comm.size} rank(s), {part.n_global_cells} tetrahedra: CG to rtol 1e-8", rows, comm)


def compare_on_cantilever(divisions: int, comm) -> None:
    from snede.app.scenes import Parameters, cantilever

    scene_options = Parameters(divisions=divisions)
    rows = []
    for preconditioner in PRECONDITIONERS:
        scene = cantilever.build(scene_options)
        comm.Barrier()
        rows.append((preconditioner, snede.StaticSolver(scene.body, "cg", rtol=1e-8, preconditioner=preconditioner,
                                                        comm=comm).solve()))
    print_comparison(f"{comm.size} rank(s), cantilever scene, {scene.body.mesh.n_cells} tetrahedra: CG to rtol 1e-8",
                     rows, comm)


def print_comparison(title: str, rows, comm) -> None:
    seconds = [comm.allreduce(result.seconds, op=MPI.MAX) for _, result in rows]
    if comm.rank == 0:
        print(title)
        print(f"{'preconditioner':<15} {'iterations':>10} {'reason':<20} {'s':>8}")
        for (preconditioner, result), wall in zip(rows, seconds):
            print(f"{preconditioner:<15} {result.iterations:>10} {result.reason:<20} {wall:>8.2f}")


if __name__ == "__main__":
    main()
