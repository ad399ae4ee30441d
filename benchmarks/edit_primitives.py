"""Benchmark: operations per second of each local edit primitive on a mesh of about 10^5 cells.

    .venv/bin/python benchmarks/edit_primitives.py [--operations 2000] [--body]

Meshes: a jittered right-triangle square of 224×224×2 = 100,352 triangles and a jittered
Kuhn box of 6·26³ = 105,456 tetrahedra. Each primitive is tried --operations times on random
edges / cells / vertices of a fresh mesh; prints attempts per second, how many were done and
refused, and the mean time per attempt. With --body a linear-elastic Body is attached, so
every edit also carries the state over and reissues the solver vectors when the vertex count
changes (the cost a simulation pays).
"""
import argparse
import time

import numpy as np

import snede


def jittered(mesh, rng, amount):
    x = mesh.points
    inside = np.all((x > 1e-9) & (x < 1 - 1e-9), axis=1)
    x[inside] += rng.uniform(-amount, amount, size=x[inside].shape)
    return snede.Mesh(x, mesh.cells)


def attempts(mesh, name, rng):
    cells = mesh.cells
    cell = int(rng.integers(len(cells)))
    a, b = (int(v) for v in rng.choice(cells[cell], 2, replace=False))
    if name == "flip":
        return lambda: mesh.flip_edge(a, b)
    if name == "split":
        return lambda: mesh.split_edge(a, b, 0.5)
    if name == "insert":
        weights = np.full(mesh.cell_dim + 1, 1.0 / (mesh.cell_dim + 1))
        return lambda: mesh.insert_vertex(cell, weights)
    if name == "collapse":
        return lambda: mesh.collapse_edge(a, b, 0.5)
    if name == "remove":
        return lambda: mesh.remove_vertex_by_flips(a)
    if name == "snap":
        return lambda: mesh.snap_vertex(a, [a, b], [0.8, 0.2])
    raise ValueError(name)


def run(make, names, operations, with_body, rng):
    for name in names:
        mesh = make()
        body = snede.Body(mesh, snede.LinearElastic(E=1e4, nu=0.3), thickness=0.01 if mesh.dim == 2 else None) \
            if with_body else None
        done = refused = 0
        seconds = 0.0
        for _ in range(operations):
            attempt = attempts(mesh, name, rng)  # choosing the edge is not timed
            start = time.perf_counter()
            result = attempt()
            seconds += time.perf_counter() - start
            done += bool(result)
            refused += not result
        print(f"{mesh.cell_dim}D {mesh.n_cells:>8} {name:>9} {operations / seconds:>12.0f} {done:>7} {refused:>8} "
              f"{1e6 * seconds / operations:>10.1f}", flush=True)
        del body


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--operations", type=int, default=2000)
    parser.add_argument("--body", action="store_true", help="attach a Body (state carried over by every edit)")
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    print(f"{'':2} {'cells':>8} {'edit':>9} {'attempts/s':>12} {'done':>7} {'refused':>8} {'us/attempt':>10}")
    run(lambda: jittered(snede.meshing.rectangle((1, 1), (224, 224)), rng, 0.1 / 224),
        ["flip", "split", "insert", "collapse", "remove", "snap"], args.operations, args.body, rng)
    run(lambda: jittered(snede.meshing.box((1, 1, 1), (26, 26, 26)), rng, 0.1 / 26),
        ["split", "insert", "collapse", "snap"], args.operations, args.body, rng)


if __name__ == "__main__":
    main()
