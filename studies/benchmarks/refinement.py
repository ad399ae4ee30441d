"""Benchmark: conforming bisection refinement (§6.5) of Kuhn-split boxes and right-triangle squares.

    .venv/bin/python studies/benchmarks/refinement.py [--divisions 26] [--levels 2] [--depth 10]

Uniform refinement: a box of 6·n³ tetrahedra (n = 26: 105,456) refined --levels times,
and a square of about as many right triangles; prints cells split per second, the bytes
per cell held by the mesh (connectivity + coordinates, mesh.memory_bytes()) before and
after, and the bytes per cell of the bisection hierarchy (labels, parent/child tree).
Refine-around: seconds for refine_around(x, h = size / 2^depth) from a 4×4×4 box and from
the n-box (and the 2D analogues), with the cells it added.
"""
import argparse
import time

import numpy as np

import snede


def timed(function):
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


def hierarchy_bytes(mesh) -> int:
    return mesh._bisection().memory_bytes()


def uniform(make, levels):
    mesh = make()
    cells_before, bytes_before = mesh.n_cells, mesh.memory_bytes() / mesh.n_cells
    labelling, _ = timed(mesh._bisection)
    seconds, split = timed(lambda: mesh.refine_uniform(levels))
    print(f"{mesh.dim}D {cells_before:>10} {mesh.n_cells:>10} {labelling:>10.3f} {seconds:>9.3f} "
          f"{split / seconds:>14.0f} {bytes_before:>11.1f} {mesh.memory_bytes() / mesh.n_cells:>10.1f} "
          f"{hierarchy_bytes(mesh) / mesh.n_cells:>12.1f}", flush=True)


def around(make, point, depth):
    mesh = make()
    mesh._bisection()
    cells_before = mesh.n_cells
    seconds, split = timed(lambda: mesh.refine_around(point, 2.0 ** -depth))
    print(f"{mesh.dim}D {cells_before:>10} {depth:>6} {seconds:>9.4f} {mesh.n_cells - cells_before:>11} "
          f"{split / seconds:>14.0f}", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--divisions", type=int, default=26, help="n of the n×n×n box (6n³ tetrahedra)")
    parser.add_argument("--levels", type=int, default=2, help="levels of uniform refinement")
    parser.add_argument("--depth", type=int, default=10, help="refine_around to h = size / 2^depth")
    args = parser.parse_args()
    n = args.divisions
    box = lambda k: (lambda: snede.meshing.box((1, 1, 1), (k, k, k)))  # noqa: E731
    square = lambda k: (lambda: snede.meshing.rectangle((1, 1), (k, k)))  # noqa: E731
    square_n = int(round(np.sqrt(6 * n**3 / 2)))  # about as many triangles as tetrahedra

    print(f"uniform refinement, {args.levels} levels")
    print(f"{'':2} {'cells':>10} {'after':>10} {'labelling s':>10} {'refine s':>9} {'splits/s':>14} "
          f"{'bytes/cell':>11} {'after':>10} {'hierarchy':>12}")
    uniform(box(n), args.levels)
    uniform(square(square_n), args.levels)

    print(f"\nrefine_around(x, size / 2^{args.depth})")
    print(f"{'':2} {'cells':>10} {'depth':>6} {'seconds':>9} {'cells added':>11} {'splits/s':>14}")
    for make, point in ((box(4), (0.3, 0.55, 0.7)), (box(n), (0.3, 0.55, 0.7)),
                        (square(4), (0.3, 0.55)), (square(square_n), (0.3, 0.55))):
        around(make, np.array(point), args.depth)


if __name__ == "__main__":
    main()
