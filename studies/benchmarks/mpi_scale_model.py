"""Benchmark (issue 52, item 5): a scale model of the distributed CG iteration, measured on 1
and 2 ranks of this machine and extrapolated to 10⁸–10⁹ tetrahedra on 64–1024 ranks.

    mpirun -n 2 .venv/bin/python studies/benchmarks/mpi_scale_model.py [--divisions 30,40,55] [--iterations 60]

(as root: OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1). One run measures both rank
counts, so the ratios come from one process pair on a quiet machine: for each box (the unit
cube as n³ Kuhn cubes, 6 n³ tetrahedra, linear elastic, fixed at x = 0 and pulled at x = 1,
made on the ranks by `snede.meshing.box(..., comm=)`) CG runs a fixed number of iterations
(its DIVERGED_ITS is the point: the same work on both counts), first on rank 0 alone (rank 1
waits), then on both ranks. From PETSc's event log (KSPSolve and what it contains) it prints,
per CG iteration: seconds, messages, bytes and global reductions per rank, and the seconds the
ranks spend in the ghost exchange (VecScatterBegin/End). A ping-pong and an Allreduce between
the two ranks give this machine's latency and bandwidth.

The model of one CG iteration on P ranks of N tetrahedra, cubic parts of m³ Kuhn cubes
(6 m³ = N / P):

    t(N, P) = w · N / P                                  element work and vector updates
            + 26 α + 2 · 6 (m + 1)² · 3 · 8 B / β         ghost exchange, there and back
            + R · 2 ⌈log₂ P⌉ α                            R reductions, a tree each

w (seconds per tetrahedron per iteration) and R are measured here on one rank; the ghost term
counts each face's (m + 1)² vertices once each way (a part owns about half of its faces'
vertices and ghosts the other half: the scatter sends its owned face values forward and the
ghosts' contributions back) and 26 neighbours (faces, edges, corners). The check against this
machine replaces the cube by the measured slab (the 2-rank box is cut across x) and α, β by the
ping-pong's; the extrapolation uses a cluster's α = 1.5 µs, β = 12 GB/s (an InfiniBand HDR
link, stated, not measured). Not a test; the machine has 2 cores.
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import snede

CLUSTER_LATENCY = 1.5e-6        # α, s: one message between nodes (InfiniBand HDR class)
CLUSTER_BANDWIDTH = 12e9        # β, B/s: one node's link
NEIGHBOURS = 26                 # a cubic part's face, edge and corner neighbours
EVENTS = ("KSPSolve", "MatMult", "VecScatterBegin", "VecScatterEnd", "PCApply")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--divisions", default="30,40,55", help="n of the boxes, comma-separated (6 n³ tetrahedra)")
    parser.add_argument("--iterations", type=int, default=60, help="CG iterations per solve (default 60)")
    arguments, _ = parser.parse_known_args()
    world = MPI.COMM_WORLD
    if world.size != 2:
        raise SystemExit("run it on 2 ranks: mpirun -n 2 ... (it measures 1 and 2 ranks in one run)")
    PETSc.Log.begin()
    latency, bandwidth, allreduce = measure_links(world)
    rows = []
    for n in (int(text) for text in arguments.divisions.split(",")):
        alone = None
        if world.rank == 0:
            alone = measure_cg(MPI.COMM_SELF, n, arguments.iterations)
        world.Barrier()
        both = measure_cg(world, n, arguments.iterations)
        if world.rank == 0:
            rows.append((n, alone, both))
    if world.rank == 0:
        report(rows, latency, bandwidth, allreduce)


def measure_links(comm):
    """Half a ping-pong's round trip for 8 bytes (α) and for 4 MB (β from the difference), and
    one Allreduce of a double, between the two ranks of this machine."""
    def half_round_trip(size: int, repeats: int) -> float:
        buffer = np.zeros(size // 8)
        comm.Barrier()
        start = time.perf_counter()
        for _ in range(repeats):
            if comm.rank == 0:
                comm.Send(buffer, dest=1)
                comm.Recv(buffer, source=1)
            else:
                comm.Recv(buffer, source=0)
                comm.Send(buffer, dest=0)
        return (time.perf_counter() - start) / (2 * repeats)

    half_round_trip(8, 100)  # the connection's set-up out of the timing
    latency = half_round_trip(8, 20000)
    large = 4 * 2**20
    bandwidth = large / (half_round_trip(large, 50) - latency)
    value = np.ones(1)
    comm.Barrier()
    start = time.perf_counter()
    repeats = 20000
    for _ in range(repeats):
        comm.Allreduce(MPI.IN_PLACE, value)
    allreduce = (time.perf_counter() - start) / repeats
    return latency, bandwidth, allreduce


def log_snapshot():
    return {name: PETSc.Log.Event(name).getPerfInfo() for name in EVENTS}


def measure_cg(comm, n: int, iterations: int) -> dict:
    """CG without a preconditioner, `iterations` of them, on the box made on `comm`'s ranks;
    per iteration, this rank's figures (times the slowest rank's)."""
    part = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n), comm=comm, max_cells=6 * n**3)
    fixed = part.vertices_where(lambda x: x[:, 0] == 0.0)
    pulled = part.vertices_where(lambda x: x[:, 0] == 1.0)
    problem = snede.DistributedStatic(part, snede.LinearElastic(1e5, 0.3), fixed=fixed,
                                      forces={int(v): (1.0 / len(pulled), 0.0, 0.0) for v in pulled})
    before = log_snapshot()
    comm.Barrier()
    result = problem.solve("cg", rtol=1e-30, round_tolerance=0.0, max_iterations=iterations, preconditioner="none")
    after = log_snapshot()
    delta = {name: {key: after[name][key] - before[name][key] for key in after[name]} for name in EVENTS}
    count = max(result.iterations, 1)
    solve = delta["KSPSolve"]
    scatter_seconds = delta["VecScatterBegin"]["time"] + delta["VecScatterEnd"]["time"]
    return {
        "ranks": comm.size,
        "cells": part.n_global_cells,
        "cells_here": comm.allreduce(part.local.n_cells, op=MPI.MAX),
        "ghosts": comm.allreduce(int((~part.owned).sum()), op=MPI.MAX),
        "reason": result.reason,
        "iterations": result.iterations,
        "products_per_iteration": delta["MatMult"]["count"] / count,
        "seconds": comm.allreduce(solve["time"], op=MPI.MAX) / count,
        "scatter_seconds": comm.allreduce(scatter_seconds, op=MPI.MAX) / count,
        "messages": solve["numMessages"] / count,
        "bytes": solve["messageLength"] / count,
        "reductions": solve["numReductions"] / count,
    }


def modelled_seconds(work: float, reductions: float, cells_per_rank: float, ranks: int, latency: float,
                     bandwidth: float, neighbours: int, face_vertices: float, faces: int) -> float:
    """The model's seconds per CG iteration (module docstring)."""
    if ranks == 1:
        return work * cells_per_rank
    exchange = neighbours * latency + 2 * faces * face_vertices * 3 * 8 / bandwidth
    return work * cells_per_rank + exchange + reductions * 2 * math.ceil(math.log2(ranks)) * latency


def busy_work(both: dict, allreduce: float) -> float:
    """Seconds per tetrahedron of a CG iteration with both cores working: the 2-rank iteration
    less its ghost exchange and reductions, over the larger part's cells."""
    return (both["seconds"] - both["scatter_seconds"] - both["reductions"] * allreduce) / both["cells_here"]


def report(rows, latency: float, bandwidth: float, allreduce: float) -> None:
    print(f"this machine, 2 ranks: latency α = {1e6 * latency:.2f} µs, bandwidth β = {bandwidth / 1e9:.2f} GB/s, "
          f"Allreduce of a double {1e6 * allreduce:.2f} µs")
    print()
    print("measured, per CG iteration (no preconditioner; rank 0's counts, the slowest rank's seconds)")
    print(f"{'tetrahedra':>10} {'ranks':>5} {'ms':>8} {'scatter ms':>10} {'products':>8} {'messages':>8} "
          f"{'kB sent+recv':>12} {'reductions':>10} {'ghosts':>7} {'speed-up':>8}")
    for n, alone, both in rows:
        for measured in (alone, both):
            speed_up = alone["seconds"] / measured["seconds"]
            print(f"{measured['cells']:>10} {measured['ranks']:>5} {1e3 * measured['seconds']:>8.3f} "
                  f"{1e3 * measured['scatter_seconds']:>10.3f} {measured['products_per_iteration']:>8.2f} "
                  f"{measured['messages']:>8.2f} {measured['bytes'] / 1e3:>12.1f} {measured['reductions']:>10.2f} "
                  f"{measured['ghosts']:>7} {speed_up:>8.2f}")
    print()
    print("the model on this machine (slab cut across x: one face of (n+1)² vertices, one neighbour; w from one rank "
          "alone; w busy: the 2-rank iteration less its measured exchange and reductions, per tetrahedron of the "
          "larger part)")
    print(f"{'tetrahedra':>10} {'w ns/tet':>9} {'w busy':>7} {'R':>5} {'model ms':>9} {'comm µs':>8} "
          f"{'measured ms':>11} {'scatter µs':>10} {'measured/model':>14}")
    for n, alone, both in rows:
        w = alone["seconds"] / alone["cells"]
        reductions = both["reductions"]
        model = modelled_seconds(w, reductions, both["cells_here"], 2, latency, bandwidth, 1, (n + 1) ** 2, 1)
        communication = model - w * both["cells_here"]
        print(f"{both['cells']:>10} {1e9 * w:>9.2f} {1e9 * busy_work(both, allreduce):>7.2f} {reductions:>5.1f} "
              f"{1e3 * model:>9.3f} {1e6 * communication:>8.1f} {1e3 * both['seconds']:>11.3f} "
              f"{1e6 * both['scatter_seconds']:>10.1f} {both['seconds'] / model:>14.2f}")
    print()
    largest = rows[-1][2]
    work = busy_work(largest, allreduce)
    reductions = largest["reductions"]
    print(f"extrapolated (w = {1e9 * work:.2f} ns per tetrahedron: 'w busy' of the {largest['cells']}-tetrahedron box, "
          f"every core of a node working; R = {reductions:.1f}; cluster α = {1e6 * CLUSTER_LATENCY} µs, "
          f"β = {CLUSTER_BANDWIDTH / 1e9:.0f} GB/s; cubic parts, {NEIGHBOURS} neighbours)")
    print(f"{'tetrahedra':>10} {'ranks':>5} {'tets/rank':>10} {'m':>5} {'kB/product':>10} {'compute ms':>10} "
          f"{'exchange µs':>11} {'reductions µs':>13} {'ms/iteration':>12} {'efficiency':>10}")
    for cells in (1e8, 1e9):
        for ranks in (64, 256, 1024):
            per_rank = cells / ranks
            m = (per_rank / 6) ** (1 / 3)
            face = (m + 1) ** 2
            compute = work * per_rank
            total = modelled_seconds(work, reductions, per_rank, ranks, CLUSTER_LATENCY, CLUSTER_BANDWIDTH,
                                     NEIGHBOURS, face, 6)
            exchange = NEIGHBOURS * CLUSTER_LATENCY + 2 * 6 * face * 24 / CLUSTER_BANDWIDTH
            tree = total - compute - exchange
            print(f"{cells:>10.0e} {ranks:>5} {per_rank:>10.3g} {m:>5.1f} {2 * 6 * face * 24 / 1e3:>10.1f} "
                  f"{1e3 * compute:>10.2f} {1e6 * exchange:>11.1f} {1e6 * tree:>13.1f} {1e3 * total:>12.3f} "
                  f"{compute / total:>10.3f}")


if __name__ == "__main__":
    main()
