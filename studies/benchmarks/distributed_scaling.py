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

With --to-tolerance the same body is instead solved to ‖r‖ ≤ 1e-8 ‖r₀‖ by CG with each
preconditioner (none, Jacobi, GAMG on the assembled MPIAIJ tangent, mg by aggregation of each
rank's vertices, block Jacobi, SOR, MUMPS's LU): iterations and seconds, assembly and set-up
included. With --cantilever N the same comparison runs on the
slender `cantilever` scene (--divisions N) through StaticSolver(body, "cg", comm=...).
"""
from __future__ import annotations

import argparse
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
    arguments, _ = parser.parse_known_args()
    comm = MPI.COMM_WORLD
    if arguments.cantilever:
        compare_on_cantilever(arguments.cantilever, comm)
        return
    n = arguments.divisions
    serial = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n)) if comm.rank == 0 else None
    comm.Barrier()
    start = time.perf_counter()
    part = snede.distribute(serial, comm)
    distribute_seconds = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    x = part.local.points
    # Conditions by serial id, the same on every rank: rebuilt from the grid's numbering.
    grid = np.stack(np.meshgrid(*[np.arange(n + 1)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    fixed = np.flatnonzero(grid[:, 0] == 0)
    pulled = np.flatnonzero(grid[:, 0] == n)
    def problem():
        return snede.DistributedStatic(part, snede.LinearElastic(1e5, 0.3), fixed=fixed,
                                       forces={int(v): (1.0 / len(pulled), 0.0, 0.0) for v in pulled})

    if arguments.to_tolerance:
        compare_preconditioners(problem, comm, part)
        return
    problem = problem()
    comm.Barrier()
    result = problem.solve("cg", rtol=1e-30, round_tolerance=0.0, max_iterations=arguments.iterations)
    seconds = comm.allreduce(result.seconds, op=MPI.MAX)
    ghosts = int((~part.owned).sum())
    rows = comm.gather((comm.rank, part.local.n_cells, int(part.owned.sum()), ghosts, 2 * ghosts * 3 * 8), root=0)
    if comm.rank == 0:
        print(f"{comm.size} rank(s), {part.n_global_cells} tetrahedra, {part.n_global_vertices} vertices; "
              f"distribute {distribute_seconds:.2f} s; CG {result.iterations} iterations ({result.reason}) in "
              f"{seconds:.3f} s: {1e3 * seconds / max(result.iterations, 1):.2f} ms per iteration")
        print(f"{'rank':>4} {'cells':>9} {'owned':>9} {'ghosts':>7} {'bytes/product':>14}")
        for rank, cells, owned, ghosts, volume in rows:
            print(f"{rank:>4} {cells:>9} {owned:>9} {ghosts:>7} {volume:>14}")
        print(f"(x spans {x[:, 0].min():.2f}..{x[:, 0].max():.2f} on rank 0)")


PRECONDITIONERS = ("none", "jacobi", "gamg", "mg", "bjacobi", "sor", "lu")


def compare_preconditioners(problem, comm, part) -> None:
    rows = []
    for preconditioner in PRECONDITIONERS:
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
