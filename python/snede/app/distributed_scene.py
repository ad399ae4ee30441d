"""A static scene on several MPI ranks (issue 18): ``mpirun -n 2 python -m snede run
cantilever``. Every rank builds the scene as usual; the body's solver is given the
communicator (``StaticSolver(..., comm=)``, ``DynamicRelaxation(..., comm=)``), so rank 0's
mesh is distributed and its held vertices and external forces (nodal loads and the lumped
gravity) become a snede.DistributedStatic, solved by GAMG-preconditioned CG or Newton,
nonlinear CG or dynamic relaxation (with the scene's damping). The solution comes back into
the body on every rank; all ranks write the series together (one XDMF + HDF5, collective),
and rank 0 the picture and the summary. What does not run distributed yet is refused on every
rank with NotImplementedError naming it: scenes that change their mesh or evolve in time
(cuts, bisection, needles stay serial) and membranes.
"""
from __future__ import annotations

import time

import snede

DISTRIBUTED_METHODS = (*snede.static.METHODS, "dynamic")


def unsupported(scene, method: str) -> str | None:
    """Why the scene cannot run on several ranks, or None."""
    body = scene.body
    if scene.evolve is not None:
        return "it changes its mesh or evolves in time (cuts, bisection and needle insertion stay serial)"
    if scene.solver_options:
        return "its solver options (a scene file's [solver] preconditioner, max_iterations, petsc) are not passed " \
               "to distributed solves yet"
    if method not in DISTRIBUTED_METHODS:
        return f"method {method!r} (distributed solves are {', '.join(DISTRIBUTED_METHODS)})"
    if body.mesh.is_surface:
        return "membranes are not distributed yet"
    return None


def solve_distributed(scene, method: str, rtol: float, writer, comm) -> dict:
    """Solve on every rank of ``comm`` through the serial body's solvers with ``comm``; the body
    receives the solution on every rank, and ``writer`` (collective) the unloaded and solved
    states of the distributed mesh. The summary entries (the same on every rank)."""
    body = scene.body
    start = time.perf_counter()
    if method == "dynamic":
        solver = snede.DynamicRelaxation(body, damping=scene.damping, comm=comm)
        result = solver.run(rtol=rtol)
    else:
        solver = snede.StaticSolver(body, method, rtol=rtol, comm=comm)
        result = solver.solve()
    wall = time.perf_counter() - start
    part = solver.part
    writer.write_part(part, time=0.0)
    writer.write_part(part, time=1.0, displacement=body.displacement[part.global_vertex])
    return {"converged": result.converged, "reason": result.reason, "iterations": result.iterations,
            "linear_iterations": result.linear_iterations, "residual_norm": result.residual_norm,
            "seconds": wall, "mflop": result.flops / 1e6, "ranks": comm.size,
            "cells_per_rank": comm.allgather(part.local.n_cells)}
