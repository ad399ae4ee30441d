"""Benchmark: local mesh edits per second from Python on meshes of ~100k cells, bare and with
an elastic Body attached (edit by edit, and inside one ``mesh.batch()``).

    .venv/bin/python studies/benchmarks/edit_primitives.py [--edits 2000] [--triangles 224] [--box 26] [--body]

Meshes: ``meshing.rectangle`` with n × n × 2 triangles (n = 224: 100,352) and the Kuhn box
``meshing.box`` with 6·n³ tetrahedra (n = 26: 105,456). Each primitive is applied at
``--edits`` random places (cells drawn without replacement from the initial mesh, so edits
rarely touch each other); only the edit calls are timed, argument picking is not. Columns:
edits attempted, how many were done (the rest were refused, e.g. a flip of a boundary edge),
edits per second, microseconds per edit. With ``--body`` the same edits run again with a
linear elastic Body on the mesh — first edit by edit (each edit reissues the body's vectors,
O(n)), then all inside one ``mesh.batch()`` (one reissue) — and the slowdown against the bare
mesh is printed as a ratio from the same run.
"""
import argparse
import time

import numpy as np

import snede


def sheet(n):
    return snede.meshing.rectangle((1.0, 1.0), (n, n))


def box(n):
    return snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))


def edits_for(mesh, rng):
    """name → function(element id, cell vertices) performing one edit there."""
    k = mesh.cell_dim + 1

    def weights():
        w = rng.uniform(0.1, 1.0, k)
        return w / w.sum()

    table = {
        "split_edge": lambda e, cell: mesh.split_edge(cell[0], cell[1], 0.5),
        "insert_vertex": lambda e, cell: mesh.insert_vertex(e, weights()),
        "collapse_edge": lambda e, cell: mesh.collapse_edge(cell[0], cell[1], 0.5),
        "snap_vertex": lambda e, cell: mesh.snap_vertex(cell[0], cell, weights()),
    }
    if mesh.cell_dim == 2:
        table["flip_edge"] = lambda e, cell: mesh.flip_edge(cell[0], cell[1])
        table["remove_vertex_by_flips"] = lambda e, cell: mesh.remove_vertex_by_flips(cell[0])
    return table


def run(make_mesh, name, n_edits, mode, seed=1):
    """Seconds spent in the edit calls and edits done; mode: 'bare', 'body' or 'batch'."""
    mesh = make_mesh()
    body = None
    if mode != "bare":
        body = snede.Body(mesh, snede.LinearElastic(E=1e4, nu=0.3), thickness=0.01 if mesh.dim == 2 else None)
    rng = np.random.default_rng(seed)
    edit = edits_for(mesh, rng)[name]
    picked = rng.choice(mesh.cell_ids, size=min(n_edits, mesh.n_cells), replace=False).tolist()
    seconds, done = 0.0, 0
    batch = mesh.batch() if mode == "batch" else None
    if batch:
        batch.__enter__()
    for e in picked:
        try:
            cell = mesh.element_vertices(e)
        except ValueError:  # removed by an earlier edit
            continue
        start = time.perf_counter()
        result = edit(e, cell)
        seconds += time.perf_counter() - start
        done += bool(result)
    if batch:
        start = time.perf_counter()
        batch.__exit__(None, None, None)
        seconds += time.perf_counter() - start
    mesh.validate()
    return seconds, done, len(picked)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--edits", type=int, default=2000)
    parser.add_argument("--triangles", type=int, default=224, help="rectangle divisions n (2n² triangles)")
    parser.add_argument("--box", type=int, default=26, help="box divisions n (6n³ tetrahedra)")
    parser.add_argument("--body", action="store_true", help="also time with a Body attached")
    args = parser.parse_args()
    meshes = [(f"{2 * args.triangles ** 2} triangles", lambda: sheet(args.triangles)),
              (f"{6 * args.box ** 3} tetrahedra", lambda: box(args.box))]
    header = f"{'mesh':>18} {'edit':>23} {'tried':>6} {'done':>6} {'edits/s':>9} {'us/edit':>8}"
    if args.body:
        header += f" {'body us':>9} {'x bare':>7} {'batch us':>9} {'x bare':>7}"
    print(header)
    for label, make in meshes:
        for name in edits_for(make(), np.random.default_rng(0)):
            seconds, done, tried = run(make, name, args.edits, "bare")
            line = (f"{label:>18} {name:>23} {tried:>6} {done:>6} {tried / seconds:>9.0f} "
                    f"{1e6 * seconds / tried:>8.1f}")
            if args.body:
                with_body, _, _ = run(make, name, args.edits, "body")
                batched, _, _ = run(make, name, args.edits, "batch")
                line += (f" {1e6 * with_body / tried:>9.1f} {with_body / seconds:>7.1f}"
                         f" {1e6 * batched / tried:>9.1f} {batched / seconds:>7.1f}")
            print(line, flush=True)


if __name__ == "__main__":
    main()
