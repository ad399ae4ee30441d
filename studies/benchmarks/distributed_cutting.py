"""Benchmark (issue 52, item 3): a scalpel on a body no rank holds whole, against the serial cut
of the same mesh, in one run.

    mpirun -n 2 .venv/bin/python studies/benchmarks/distributed_cutting.py [--divisions 10,20,30] [--moves 12]

(as root: OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1). For each box (the unit cube
as n³ Kuhn cubes, 6 n³ tetrahedra, both ends along x fixed) a blade is moved ``--moves`` times
along a plane across the middle of the box, so the incision crosses the rank boundary: the serial
``TetrahedralCutter`` on rank 0 alone (the other ranks wait) and the cutter of a ``PartBody``
(collective, the slowest rank's time). Printed per move: the mean seconds and work units (1 WU =
one product of PETSc's assembled AIJ tangent of the serial mesh, timed on rank 0 in the same
process), the ratio, and how the distributed move splits: gathering the cells near the sweep on
the cutting rank, the serial cut there, spreading the cut part over the ranks again, and the
pieces counted over every rank. The results are compared (faces dissected and cells). Not a test.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from mpi4py import MPI

import snede
from snede import part_cutting
from work_units import work_unit_seconds

COMM = MPI.COMM_WORLD
MATERIAL = snede.LinearElastic(1e4, 0.3)
STAGES = ("_gather_near", "_cut_on_cutting_rank", "_spread", "_with_pieces")


def path(moves: int) -> np.ndarray:
    """A blade in the plane x + 0.3 y + 0.2 z = 0.6, moved along it from outside the box to
    beyond its middle."""
    normal = np.array([1.0, 0.3, 0.2]) / np.linalg.norm([1.0, 0.3, 0.2])
    blade = np.cross(normal, [0.0, 0.0, 1.0])
    blade /= np.linalg.norm(blade)
    travel = np.cross(normal, blade)
    base = np.full(3, 0.5) + (0.6 - normal @ np.full(3, 0.5)) * normal
    return np.array([[base + s * travel - 3 * blade, base + s * travel + 3 * blade]
                     for s in np.linspace(-1.0, 0.3, moves)])


def held(body, x) -> None:
    body.fix(np.flatnonzero((x[:, 0] == 0.0) | (x[:, 0] == 1.0)))


def timed_stages(cutter) -> dict:
    """Wraps the PartCutter's stages to add up their seconds (the slowest rank's, per call)."""
    totals = dict.fromkeys(STAGES, 0.0)
    for name in STAGES:
        original = getattr(part_cutting.PartCutter, name)

        def wrapped(self, *arguments, original=original, name=name):
            COMM.Barrier()
            began = time.perf_counter()
            out = original(self, *arguments)
            totals[name] += COMM.allreduce(time.perf_counter() - began, op=MPI.MAX)
            return out

        setattr(cutter._impl, name, wrapped.__get__(cutter._impl))
    return totals


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--divisions", default="10,20,30", help="cubes per side, comma-separated")
    parser.add_argument("--moves", type=int, default=12)
    args = parser.parse_args()
    positions = path(args.moves)
    rows = []
    for n in (int(d) for d in args.divisions.split(",")):
        def make(n=n):
            return snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))

        serial_seconds, serial_faces, serial_cells, unit = 0.0, 0, 0, 0.0
        if COMM.rank == 0:
            body = snede.Body(make(), MATERIAL)
            unit = work_unit_seconds(body)
            held(body, body.mesh.points)
            cutter = snede.TetrahedralCutter(body)
            cutter.move(positions[0])
            began = time.perf_counter()
            for position in positions[1:]:
                serial_faces += cutter.move(position).faces_dissected
            serial_seconds = time.perf_counter() - began
            serial_cells = body.mesh.n_cells
        serial_seconds, serial_faces, serial_cells, unit = COMM.bcast(
            (serial_seconds, serial_faces, serial_cells, unit), root=0)

        body = snede.Body(snede.distribute(make() if COMM.rank == 0 else None, comm=COMM), MATERIAL)
        held(body, body.mesh.points)
        cutter = snede.TetrahedralCutter(body)
        cutter.move(positions[0])
        stages = timed_stages(cutter)
        COMM.Barrier()
        began = time.perf_counter()
        faces = 0
        for position in positions[1:]:
            faces += cutter.move(position).faces_dissected
        seconds = COMM.allreduce(time.perf_counter() - began, op=MPI.MAX)
        if (faces, body.part.n_global_cells) != (serial_faces, serial_cells):
            raise SystemExit(f"{n}: {faces} faces and {body.part.n_global_cells} cells on ranks, "
                             f"{serial_faces} and {serial_cells} serially")
        rows.append((6 * n ** 3, serial_seconds, seconds, stages, unit, faces, COMM.allgather(body.mesh.n_cells)))
    if COMM.rank == 0:
        moves = args.moves - 1
        print(f"{COMM.size} ranks, {moves} moves; seconds per move (WU per move)\n")
        print(f"{'tets':>8} {'faces':>6} {'serial':>16} {'ranks':>16} {'ratio':>6} {'gather':>7} {'cut':>7} "
              f"{'spread':>7} {'pieces':>7}  cells per rank")
        for tets, serial, seconds, stages, unit, faces, per_rank in rows:
            s, r = serial / moves, seconds / moves
            print(f"{tets:>8} {faces:>6} {s:>7.4f} ({s / unit:>6.0f}) {r:>7.4f} ({r / unit:>6.0f}) {s / r:>6.2f} "
                  + " ".join(f"{stages[name] / moves:>7.4f}" for name in STAGES) + f"  {per_rank}")


if __name__ == "__main__":
    main()
