"""Benchmark (issue 52, item 3): conforming bisection of a body no rank holds whole, against the
serial refinement of the same mesh, in one run.

    mpirun -n 2 .venv/bin/python studies/benchmarks/distributed_refinement.py [--divisions 16,24,32]

(as root: OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1). For each box (the unit cube
as n³ Kuhn cubes, 6 n³ tetrahedra) and each edit — every cell bisected once
(``refine_uniform(1)``), a needle's shaft refined to h = 1/(4n) within 1/(8n)
(``refine_near_segment``), and the shaft's next step, 5 % further in, on the body the first
shaft refined (the edit a needle loop repeats) — it times the serial edit on rank 0 alone (``Mesh``, the other ranks
wait) and the distributed edit of a ``PartBody`` (collective, the slowest rank's time), and splits
the distributed time by PETSc's event log into the local bisection (SnedeRankBisect), the
agreement on the split edges of the rank boundary (SnedeRankAgreeSplits) and the making of the
new part (SnedeRankNewPart: coordinates and state by global id, distribute_cells, which rebalances
when one rank holds more than 1.2× the mean; else the part refined in place is renumbered); the rest
is the set-up, which the first edit of a body pays (the part copied in global-id order, the shared
vertices found, the hierarchy labelled) and later edits do not. Times are also given in work units (1 WU
= one product of PETSc's assembled AIJ tangent of the serial mesh before the edit, timed on rank 0
in the same process). The refined cells are checked against the serial ones (counts). Not a test.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import snede
from work_units import work_unit_seconds

COMM = MPI.COMM_WORLD
EVENTS = ("SnedeRankBisect", "SnedeRankAgreeSplits", "SnedeRankNewPart")
MATERIAL = snede.LinearElastic(1e4, 0.3)


def event_seconds() -> dict:
    """Each event's seconds so far on this rank (its log is cumulative)."""
    return {name: PETSc.Log.Event(name).getPerfInfo()["time"] for name in EVENTS}


def slowest(seconds: float) -> float:
    return COMM.allreduce(seconds, op=MPI.MAX)


def timed_serial(edit, make, before=None):
    """Seconds of edit(mesh) on rank 0 alone (the mesh made, and before(mesh) done, before the
    clock starts), with its count."""
    seconds, count = 0.0, 0
    if COMM.rank == 0:
        mesh = make()
        if before is not None:
            before(mesh)
        began = time.perf_counter()
        count = edit(mesh)
        seconds = time.perf_counter() - began
    COMM.Barrier()
    return COMM.bcast((seconds, count), root=0)


def timed_distributed(edit, make, before=None):
    """(seconds, {event: seconds}, count, cells) of edit(body) of a PartBody on every rank
    (before(body) done first, untimed)."""
    mesh = make() if COMM.rank == 0 else None
    body = snede.Body(snede.distribute(mesh, comm=COMM), MATERIAL)
    if before is not None:
        before(body)
    COMM.Barrier()
    before = event_seconds()
    began = time.perf_counter()
    count = edit(body)
    seconds = slowest(time.perf_counter() - began)
    after = event_seconds()
    events = {name: slowest(after[name] - before[name]) for name in EVENTS}
    cells = COMM.allgather(body.mesh.n_cells)
    return seconds, events, count, cells


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--divisions", default="16,24,32", help="cubes per side, comma-separated")
    args = parser.parse_args()
    PETSc.Log.begin()
    for name in EVENTS:
        PETSc.Log.Event(name)  # registered before the first refinement, so every rank has them
    rows = []
    for n in (int(d) for d in args.divisions.split(",")):
        def make(n=n):
            return snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))

        unit = 0.0
        if COMM.rank == 0:
            unit = work_unit_seconds(snede.Body(make(), MATERIAL))
        unit = COMM.bcast(unit, root=0)
        h, radius = 1.0 / (4 * n), 1.0 / (8 * n)
        a, b = np.array([0.05, 0.43, 0.52]), np.array([0.95, 0.57, 0.48])  # across the rank boundary
        advanced = b + (b - a) * 0.05  # the shaft 5 % further in (a needle's next step)

        def shaft(target):
            return target.refine_near_segment(a, b, h, radius)

        edits = {  # label: (edit, done before it, untimed)
            "refine_uniform(1)": (lambda target: target.refine_uniform(1), None),
            "refine_near_segment": (shaft, None),
            "next shaft step": (lambda target: target.refine_near_segment(a, advanced, h, radius), shaft),
        }
        for label, (edit, before) in edits.items():
            serial_seconds, serial_count = timed_serial(edit, make, before)
            seconds, events, count, cells = timed_distributed(edit, make, before)
            if count != serial_count:
                raise SystemExit(f"{label}: {count} cells split on ranks, {serial_count} serially")
            setup = seconds - sum(events.values())
            rows.append((6 * n ** 3, label, sum(cells), serial_seconds, seconds, events, setup, unit, cells))
    if COMM.rank == 0:
        print(f"{COMM.size} ranks; times in seconds and (WU); 'set-up' = total − the three events\n")
        print(f"{'tets':>8} {'edit':>20} {'cells after':>11} {'serial':>15} {'ranks':>15} {'ratio':>6} "
              f"{'bisect':>7} {'agree':>7} {'new part':>8} {'set-up':>7}  cells per rank")
        for tets, label, cells, serial, seconds, events, setup, unit, per_rank in rows:
            print(f"{tets:>8} {label:>20} {cells:>11} {serial:>7.3f} ({serial / unit:>5.0f}) "
                  f"{seconds:>7.3f} ({seconds / unit:>5.0f}) {serial / seconds:>6.2f} "
                  f"{events['SnedeRankBisect']:>7.3f} {events['SnedeRankAgreeSplits']:>7.3f} "
                  f"{events['SnedeRankNewPart']:>8.3f} {setup:>7.3f}  {per_rank}")


if __name__ == "__main__":
    main()
