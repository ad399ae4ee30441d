"""Benchmark: refining an elastic body in the middle of a simulation (§6.5 refine-around) costs
time proportional to the cells it creates, because one refine_around call is one mesh change
for the body's watchers (the solver vectors are reissued once, the state carried over once).

    .venv/bin/python studies/benchmarks/body_refinement.py [--divisions 26] [--depths 4 6 8 10 12]

A Kuhn box of 6·n³ tetrahedra (n = 26: 105,456) carries a neo-Hookean Body with a non-zero
displacement; refine_around(x, size / 2^depth) at a fixed interior point for each depth on a
fresh body. Prints the cells created, seconds, microseconds per created cell, how often the
model reissued its vectors (generation steps), and the same refinement on the bare mesh (no
watchers but the bisection hierarchy) for the ratio.
"""
import argparse
import time

import numpy as np

import snede


def refine(divisions, depth, with_body):
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (divisions,) * 3)
    mesh._bisection()  # labelling outside the timing
    body = None
    if with_body:
        body = snede.Body(mesh, snede.NeoHookean(E=3e4, nu=0.3))
        body.displacement = 1e-3 * np.sin(mesh.points)
    generation = body._model.generation if body else 0
    n_cells = mesh.n_cells
    start = time.perf_counter()
    mesh.refine_around((0.31, 0.47, 0.53), 1.0 / 2 ** depth)
    seconds = time.perf_counter() - start
    reissues = body._model.generation - generation if body else 0
    return mesh.n_cells - n_cells, seconds, reissues


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--divisions", type=int, default=26)
    parser.add_argument("--depths", type=int, nargs="+", default=[4, 6, 8, 10, 12])
    args = parser.parse_args()
    print(f"box {args.divisions}^3 Kuhn: {6 * args.divisions ** 3} tetrahedra")
    print(f"{'depth':>5} {'created':>9} {'body s':>8} {'us/cell':>8} {'reissues':>8} {'mesh s':>8} {'body/mesh':>9}")
    for depth in args.depths:
        created, seconds, reissues = refine(args.divisions, depth, True)
        _, bare, _ = refine(args.divisions, depth, False)
        print(f"{depth:>5} {created:>9} {seconds:>8.3f} {1e6 * seconds / max(created, 1):>8.1f} {reissues:>8} "
              f"{bare:>8.3f} {seconds / bare:>9.2f}", flush=True)


if __name__ == "__main__":
    main()
