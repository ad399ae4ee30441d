"""Benchmark: what one small edit costs on a snede.Body, against mesh size — the §6.5
refine-around and one move of the §3.2 scalpel — and how much of it the body adds (its
per-vertex data and PETSc vectors reissued, its per-element data recomputed) over the same edit
on a bare mesh.

    .venv/bin/python -u studies/benchmarks/edit_costs.py [--sizes 12 26 55] [--calls 30] [--quick]

Kuhn boxes snede.meshing.box((1, 1, 1), (n, n, n)) of 6n³ tetrahedra (n = 12, 26, 55: about
10⁴, 10⁵, 10⁶). The body is neo-Hookean (E = 30 kPa, ν = 0.3), fixed on its face x = 0, with
a non-zero displacement for the refinements (none for the cuts, which meet the deformed body). Each edit is made on the body's mesh and, identically, on a bare copy
of the mesh (no Body); the edits are deterministic, so both meshes stay equal and 'body − mesh'
is what the body's watchers cost.

* refine: ``refine_around`` at a random interior point down to 2/3 of the mesh spacing h,
  each call on the mesh the previous calls left (a handful of cells per call, as a needle's
  tip refines). Medians over ``--calls`` calls: cells created, milliseconds on the body, on the
  bare mesh, the difference, and 'locate': the point location the call starts with (the
  bisection hierarchy's ``locate_all`` at the same point, timed alone). 'first': the first
  call on a fresh body, which also grows the mesh's arrays from their exact initial size.
* cut: ``TetrahedralCutter.move`` of a blade 3h long pushed into the body from the top face
  h/5 per move (two sweep triangles each). Medians over the first ``--calls`` moves that
  dissected faces (those that add vertices: every third move or so): vertices added per move,
  milliseconds per move on the body, on the bare mesh, the difference.
"""
import argparse
import statistics
import time

import numpy as np

import snede
from cutting_rates import blade_path

REFINE_FACTOR = 2 / 3  # refine_around down to this fraction of the mesh spacing
MOVE_FRACTION = 0.2  # scalpel move in mesh spacings


def timed(operation) -> float:
    start = time.perf_counter()
    operation()
    return time.perf_counter() - start


def body_and_mesh(n: int, displaced: bool):
    """(body, bare mesh): the same box twice, the first carrying a Body fixed at x = 0, displaced
    or not (a scalpel cuts the deformed body: undisplaced, it cuts both meshes alike)."""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))
    body = snede.Body(mesh, snede.NeoHookean(E=3e4, nu=0.3))
    body.fix(np.flatnonzero(mesh.points[:, 0] == 0.0))
    if displaced:
        body.displacement = 1e-3 * np.sin(mesh.points)
    return body, snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))


def refine_costs(n: int, calls: int) -> dict:
    body, bare = body_and_mesh(n, displaced=True)
    mesh = body.mesh
    for m in (mesh, bare):
        m._bisection()  # the labelling, once per mesh, outside the timing
    h = REFINE_FACTOR / n
    points = np.random.default_rng(n).uniform(0.1, 0.9, (calls + 1, 3))
    first = timed(lambda: body.refine_around(points[0], h))
    bare.refine_around(points[0], h)
    created, on_body, on_mesh, locate = [], [], [], []
    for point in points[1:]:
        cells = mesh.n_cells
        locate.append(timed(lambda: mesh._bisection().locate_all(point)))
        on_body.append(timed(lambda: body.refine_around(point, h)))
        on_mesh.append(timed(lambda: bare.refine_around(point, h)))
        created.append(mesh.n_cells - cells)
    assert mesh.n_cells == bare.n_cells
    return {"tets": 6 * n ** 3, "first": first, "created": statistics.median(created), "body": statistics.median(on_body),
            "mesh": statistics.median(on_mesh), "locate": statistics.median(locate)}


def cut_costs(n: int, calls: int) -> dict:
    body, bare = body_and_mesh(n, displaced=False)
    path = blade_path(n)
    step = MOVE_FRACTION * (path[1] - path[0])  # path[k] is k spacings further in
    start = path[1] - step  # the blade's middle h/2 outside the front face; the first move places it
    cutters = [snede.TetrahedralCutter(body), snede.TetrahedralCutter(bare)]
    added, on_body, on_mesh = [], [], []
    for k in range(20 * calls):
        points = body.mesh.n_points
        seconds = [timed(lambda: cutter.move(start + k * step)) for cutter in cutters]
        if body.mesh.n_points > points:  # a move that added vertices (the dissecting ones)
            on_body.append(seconds[0])
            on_mesh.append(seconds[1])
            added.append(body.mesh.n_points - points)
        if len(added) == calls:
            break
    assert body.mesh.n_points == bare.n_points
    return {"moves": k + 1, "added": statistics.median(added), "body": statistics.median(on_body),
            "mesh": statistics.median(on_mesh)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[12, 26, 55],
                        help="box divisions n (6n³ tetrahedra); default 12 26 55 (10 368, 105 456, 998 250)")
    parser.add_argument("--calls", type=int, default=30, help="refine_around calls and scalpel moves per size")
    parser.add_argument("--quick", action="store_true", help="sizes 12 and 26, 10 calls")
    arguments = parser.parse_args()
    sizes, calls = ((12, 26), 10) if arguments.quick else (arguments.sizes, arguments.calls)
    print(f"milliseconds, medians over {calls} calls; body − mesh: what the Body's watchers add to the same edit")
    header = (f"{'tets':>8} | {'refine: cells':>13} {'first':>6} {'body':>6} {'mesh':>6} {'body−mesh':>9} {'locate':>6} | "
              f"{'cut: vertices':>13} {'body':>6} {'mesh':>6} {'body−mesh':>9}")
    print(header)
    print("-" * len(header))
    for n in sizes:
        refine, cut = refine_costs(n, calls), cut_costs(n, calls)
        print(f"{refine['tets']:>8} | {refine['created']:>13g} {1e3 * refine['first']:>6.2f} {1e3 * refine['body']:>6.2f} "
              f"{1e3 * refine['mesh']:>6.2f} {1e3 * (refine['body'] - refine['mesh']):>9.2f} "
              f"{1e3 * refine['locate']:>6.2f} | {cut['added']:>13g} {1e3 * cut['body']:>6.2f} {1e3 * cut['mesh']:>6.2f} "
              f"{1e3 * (cut['body'] - cut['mesh']):>9.2f}", flush=True)


if __name__ == "__main__":
    main()
