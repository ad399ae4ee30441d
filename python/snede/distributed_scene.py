"""A static scene on several MPI ranks (issue 18): ``mpirun -n 2 python -m snede run
cantilever``. Rank 0 builds the scene as usual; its mesh is distributed (snede.distribute), the
held vertices and the external forces (nodal loads and the lumped gravity, the same whatever
the state) become a snede.DistributedStatic, solved by GAMG-preconditioned CG or Newton,
nonlinear CG or dynamic relaxation (with the scene's damping), and the solution is gathered
back into rank 0's body, which writes the series, the picture and the summary as a serial run
does (the files are written by rank 0, not collectively). What does not run distributed yet
is refused on every rank with NotImplementedError naming it: scenes that change their mesh or
evolve in time (cuts, bisection, needles stay serial) and membranes.
"""
from __future__ import annotations

import time

import numpy as np

import snede

DISTRIBUTED_METHODS = ("cg", "newton", "ncg", "dynamic")


def unsupported(scene, method: str) -> str | None:
    """Why the scene cannot run on several ranks, or None."""
    body = scene.body
    if scene.evolve is not None:
        return "it changes its mesh or evolves in time (cuts, bisection and needle insertion stay serial)"
    if method not in DISTRIBUTED_METHODS:
        return f"method {method!r} (distributed solves are {', '.join(DISTRIBUTED_METHODS)})"
    if body.mesh.is_surface:
        return "membranes are not distributed yet"
    if scene.fixed is None:
        return "the scene does not say which vertices it holds"
    return None


def solve_distributed(scene, method: str, rtol: float, writer, comm) -> dict:
    """Solve on every rank of ``comm``; rank 0's body receives the solution and its writer the
    unloaded and solved states. The summary entries (the same on every rank)."""
    body = scene.body
    mesh = body.mesh
    fixed = np.flatnonzero(scene.fixed(mesh.points))
    loads = body.external_forces()
    loaded = np.flatnonzero(np.any(loads != 0, axis=1))
    if comm.rank == 0:
        writer.write(body, time=0.0)
    start = time.perf_counter()
    part = snede.distribute(mesh if comm.rank == 0 else None, comm)
    problem = snede.DistributedStatic(part, body.material, density=body.density, thickness=body.thickness,
                                      fixed=fixed, forces={int(v): loads[v] for v in loaded})
    if method == "dynamic":
        result = snede.DistributedRelaxation(problem, damping=scene.damping).run(rtol=rtol)
    else:
        result = problem.solve(method, rtol=rtol, preconditioner="none" if method == "ncg" else "gamg")
    u = problem.gathered_displacement()
    wall = time.perf_counter() - start
    if comm.rank == 0:
        body.displacement = u
        writer.write(body, time=1.0)
    return {"converged": result.converged, "reason": result.reason, "iterations": result.iterations,
            "linear_iterations": result.linear_iterations, "residual_norm": result.residual_norm,
            "seconds": wall, "mflop": result.flops / 1e6, "ranks": comm.size,
            "cells_per_rank": comm.allgather(part.local.n_cells)}
