"""Running a scene: solve with progress, write the XDMF series, the picture and a summary."""
from __future__ import annotations

import json
import logging
import resource
import time
from functools import partial
from pathlib import Path

import numpy as np

import snede
from snede.output import SeriesWriter
from snede.app.plotting import plot_body

log = logging.getLogger("snede")


class Progress:
    """A tqdm bar: fed by a PETSc monitor (iterations, residual norm) or by a loop (``total``)."""

    def __init__(self, label: str, enabled: bool, total: int | None = None, unit: str = " it"):
        self.bar = None
        if enabled:
            from tqdm import tqdm

            # disable=None: no bar when the output is not a terminal (logs, CI)
            self.bar = tqdm(desc=label, total=total, unit=unit, leave=False, dynamic_ncols=True, disable=None)

    def __call__(self, count: int, status: str = "") -> None:
        if self.bar is not None:
            self.bar.update(max(0, count - self.bar.n))
            if status:
                self.bar.set_postfix_str(status, refresh=False)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def static_solver(scene, method: str, rtol: float, max_iterations: int = 100000):
    """The scene's static solver: ``method``, ``rtol`` and the scene's ``solver_options``."""
    return snede.StaticSolver(scene.body, method, rtol=rtol, **{"max_iterations": max_iterations,
                                                                 **scene.solver_options})


def solve_scene(scene, method: str, rtol: float, progress: bool, max_iterations: int = 100000):
    body = scene.body
    bar = Progress(f"{scene.name} ({method})", progress)
    try:
        if method == "dynamic":
            if not hasattr(snede, "DynamicRelaxation"):
                raise ValueError("dynamic relaxation is not available in this build")
            options = scene.solver_options
            solver = snede.DynamicRelaxation(body, damping=scene.damping, petsc_options=options.get("petsc_options"))
            solver.ts.setMonitor(lambda ts, step, t, u: bar(step))
            result = solver.run(rtol=rtol, max_steps=options.get("max_iterations", max_iterations))
        else:
            solver = static_solver(scene, method, rtol, max_iterations)
            if method == "cg":
                solver.ksp.setMonitor(lambda ksp, it, norm: bar(it, f"|r| = {norm:.2e}"))
            else:
                solver.snes.setMonitor(lambda snes, it, norm: bar(it, f"|r| = {norm:.2e}"))
            result = solver.solve()
    finally:
        bar.close()
    return result


def solve_once(scene, method: str, rtol: float, writer, folder: Path, progress: bool) -> dict:
    """A static scene: the unloaded state, one solve, the solution; its summary entries."""
    writer.write(scene.body, time=0.0)
    start = time.perf_counter()
    result = solve_scene(scene, method, rtol, progress)
    wall = time.perf_counter() - start
    writer.write(scene.body, time=1.0)
    return {"converged": result.converged, "reason": result.reason, "iterations": result.iterations,
            "linear_iterations": result.linear_iterations, "residual_norm": result.residual_norm,
            "seconds": wall, "mflop": result.flops / 1e6}


def fitting_method(scene) -> str:
    """The scene's default method, unless that is linear CG and the body's material is not
    linear (``--material neohookean`` on the cantilever): then truncated Newton."""
    if scene.default_method == "cg" and not isinstance(scene.body.material, snede.LinearElastic):
        return "newton"
    return scene.default_method


def picture_arguments(scene, method: str) -> dict:
    """The keyword arguments of ``plotting.plot_body`` for the scene's picture (after its run):
    title, displacement scale, the fixed vertices, the scene's decoration and its own."""
    mesh = scene.body.mesh
    fixed = None if scene.fixed is None else np.asarray(scene.fixed(mesh.points), dtype=bool) & mesh.live_vertices
    return {"title": f"{scene.name}: {type(scene.body.material).__name__}, {method}", "scale": scene.plot_scale,
            "decorate": scene.decorate, "fixed": fixed, **(scene.picture() if scene.picture else {})}


class SerialOnly(snede.Error, NotImplementedError):
    """The scene cannot run on several MPI ranks; raised on every rank alike."""


def draw_picture(scene, method: str, folder: Path, outcome: dict) -> dict:
    """The picture of the scene after its run, as ``{"png": path}``. A failed run's state is
    drawn with its reason in the title, never as if it were a solution; a state holding NaN or
    Inf is not drawn at all, nor a failed one displaced by more than a thousand times the body's
    size, which no picture shows (matplotlib's projection fails on it: 'Singular matrix'); the
    summary's reason says what went wrong."""
    u = scene.body.displacement
    if not np.isfinite(u).all():
        return {}
    points = scene.body.mesh.points
    size = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    if not outcome["converged"] and np.abs(u).max() > 1e3 * size:
        return {}
    arguments = picture_arguments(scene, method)
    if not outcome["converged"]:
        arguments["title"] += f"\nNOT converged: {outcome['reason']}"
    return {"png": str(plot_body(scene.body, folder / f"{scene.name}.png", **arguments))}


def _world():
    """MPI.COMM_WORLD when the run has several ranks (mpirun -n N), else None."""
    from mpi4py import MPI

    return MPI.COMM_WORLD if MPI.COMM_WORLD.size > 1 else None


def run(scene, method: str | None, rtol: float | None, out: Path, progress: bool = True) -> dict:
    """Solve (or evolve) the scene with ``method`` (None: ``fitting_method(scene)``), write the
    series, the picture and summary.json; the summary."""
    method = method or fitting_method(scene)
    scene.require_method(method)
    rtol = rtol or scene.default_rtol
    body = scene.body
    folder = Path(out) / scene.name
    comm = _world()
    if comm is not None:
        # Several MPI ranks (issue 18): a static solve and the series over all of them.
        from snede.app.distributed_scene import solve_distributed, unsupported

        if (why := unsupported(scene, method)) is not None:
            raise SerialOnly(f"{scene.name} on {comm.size} MPI ranks: {why}; it runs on one rank only "
                             "(without mpirun)")
        if comm.rank == 0:
            folder.mkdir(parents=True, exist_ok=True)
        writer = SeriesWriter(folder / scene.name, comm=comm)
        outcome = solve_distributed(scene, method, rtol, writer, comm)
        if comm.rank != 0:
            return {"scene": scene.name, "rank": comm.rank, **outcome}
    else:
        folder.mkdir(parents=True, exist_ok=True)
        writer = SeriesWriter(folder / scene.name)
        outcome = (scene.evolve or partial(solve_once, scene))(method, rtol, writer, folder, progress)
    files = {**draw_picture(scene, method, folder, outcome), **outcome.pop("files", {})}
    value = scene.probe(body)
    summary = {
        "scene": scene.name,
        "description": scene.description,
        "cells": body.mesh.n_cells,
        "points": body.mesh.n_points,
        "material": type(body.material).__name__,
        "method": method,
        "rtol": rtol,
        **outcome,
        "probe": scene.probe_name,
        "value": value,
        "analytic": scene.analytic,
        "error_percent": None if scene.analytic is None else 100 * abs(value - scene.analytic) / abs(scene.analytic),
        "max_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "files": {"xdmf": str(writer.xdmf_path), "h5": str(writer.h5_path), **files},
        **scene.details,
    }
    (folder / "summary.json").write_text(json.dumps(summary, indent=2))
    if not summary["converged"]:
        log.warning("%s did not converge: %s after %d iterations", scene.name, summary["reason"], summary["iterations"])
    return summary


def print_table(summaries) -> None:
    print(f"{'scene':<11} {'cells':>7} {'material':<18} {'method':<8} {'it':>6} {'reason':<24} {'s':>7} "
          f"{'probe':<30} {'value':>11} {'analytic':>10} {'error %':>8}")
    for s in summaries:
        analytic = "" if s["analytic"] is None else f"{s['analytic']:.4g}"
        error = "" if s["error_percent"] is None else f"{s['error_percent']:.4g}"
        print(f"{s['scene']:<11} {s['cells']:>7} {s['material']:<18} {s['method']:<8} {s['iterations']:>6} "
              f"{s['reason']:<24} {s['seconds']:>7.2f} {s['probe']:<30} {s['value']:>11.4g} {analytic:>10} {error:>8}")
    for s in summaries:
        others = [path for kind, path in s["files"].items() if kind not in ("xdmf", "h5")]
        print(f"  {s['scene']}: " + ", ".join([f"{s['files']['xdmf']} (ParaView)", *others]))
        if s.get("notes"):
            print(f"  {s['scene']}: {s['notes']}")
