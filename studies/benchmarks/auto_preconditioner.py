"""Benchmark: where multigrid starts to pay — the threshold of preconditioner="auto" (issue 31).

    .venv/bin/python studies/benchmarks/auto_preconditioner.py      # about 40 s

The cantilever block 0.4 × 0.1 × 0.1 m (Kuhn boxes 4n × n × n, no bisection history, so mg
coarsens by aggregation), clamped at x = 0, gravity, rtol 1e-6, solved from rest: linear CG on
LinearElastic (E = 100 kPa, ν = 0.3) and Newton on NeoHookean (E = 30 kPa, ν = 0.3), each with
no preconditioner and with mg, best of 3 runs. The last column is none's time over mg's: above 1
mg is faster. "auto" picks mg from 1 000 cells (StaticOptions::multigrid_from_cells, engine/solvers/static_options.hpp).
"""
import time
import warnings

import numpy as np

import snede


def best_time(body, method: str, preconditioner: str, repeats: int = 3) -> float:
    best = float("inf")
    for _ in range(repeats):
        body.displacement = np.zeros_like(body.displacement)
        solver = snede.StaticSolver(body, method, rtol=1e-6, preconditioner=preconditioner)
        start = time.perf_counter()
        result = solver.solve()
        best = min(best, time.perf_counter() - start)
        if not result.converged:
            raise RuntimeError(f"{preconditioner} did not converge: {result.reason}")
    return best


def main() -> None:
    warnings.simplefilter("ignore")
    print(f"{'cells':>7} {'material':>13} {'method':>6} {'none s':>8} {'mg s':>8} {'none/mg':>7}")
    for n in (2, 3, 4, 6, 8, 12):
        for material, method in ((snede.LinearElastic(1e5, 0.3), "cg"), (snede.NeoHookean(3e4, 0.3), "newton")):
            mesh = snede.meshing.box((0.4, 0.1, 0.1), (4 * n, n, n))
            body = snede.Body(mesh, material, density=1000.0)
            body.fix(np.isclose(mesh.points[:, 0], 0.0))
            body.add_gravity((0.0, 0.0, -9.81))
            none, mg = best_time(body, method, "none"), best_time(body, method, "mg")
            print(f"{mesh.n_cells:>7} {type(material).__name__:>13} {method:>6} {none:>8.4f} {mg:>8.4f} "
                  f"{none / mg:>7.2f}", flush=True)


if __name__ == "__main__":
    main()
