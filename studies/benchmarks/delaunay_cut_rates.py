"""Benchmark: the cost of one scalpel move of snede.DelaunayCutter (§5.2.2) against mesh size.

    .venv/bin/python studies/benchmarks/delaunay_cut_rates.py [--sizes 10 32 100 316 707] [--moves 40] [--quick]

Unit squares of n × n × 2 triangles, from 200 (n = 10) to about 10⁶ (n = 707), all cut by the
same path in units of the mesh spacing h = 1/n: the scalpel starts h outside the left side
at mid-height and moves in steps of ε_edge = h̄/3 (the default threshold) along a line
tilted 0.1 rad against the grid, ``--moves`` moves into the body (on the smallest mesh it
leaves the body first: only the moves before the exit count); three such incisions, at
heights 0.5, 0.3 and 0.7, so that the medians are over about 120 moves. Columns (microseconds,
CutResult.seconds):

* entry: the first incision's move that crosses the boundary (a scan of the boundary edges, O(√n) here).
* move: median and 90th percentile of the moves after the entry fix-up (remeshing around
  the active node: flips, node removal, incision splits).
* flips / splits per move: how much remeshing a move does (the same at every size if the
  work is local).
* body µs: the median move when the mesh carries a plane-stress ``snede.Body`` (linear,
  unloaded): a move that adds or removes vertices reissues the body's PETSc vectors once
  (O(n)); the last column is how many moves did.

The entry includes the first edit of a fresh mesh, which grows the connectivity's arrays
(amortized, O(n) once).

The issue's goal is a constant time per move, at most 50 µs at 10⁶ triangles; the last line
says what was measured.
"""
import argparse
import statistics
import time

import numpy as np

import snede


def cut(n: int, moves: int, on_body: bool):
    """The reports of the benchmark's moves on an n × n square (a bare mesh or a Body), from the
    one after the entry until the exit, of three incisions (at mid-height, then 0.3 and 0.7);
    the first entry's report; the seconds to build the mesh; the number of triangles."""
    start = time.perf_counter()
    mesh = snede.meshing.rectangle((1.0, 1.0), (n, n))
    build = time.perf_counter() - start
    triangles = mesh.n_cells
    cutter = snede.DelaunayCutter(snede.Body(mesh, snede.LinearElastic(1.0, 0.3), thickness=0.01) if on_body else mesh)
    h = 1.0 / n
    direction = np.array([np.cos(0.1), np.sin(0.1)])
    cutting, entries = [], []
    for height in (0.5, 0.3, 0.7):
        cutter.lift()
        origin = np.array([-h, height + 0.37 * h])
        reports = [cutter.move(origin + k * cutter.eps_edge * direction)
                   for k in range(int(3 * h / cutter.eps_edge) + moves)]
        entry = next(i for i, r in enumerate(reports) if r.entries)
        entries.append(reports[entry])
        for r in reports[entry + 1:]:
            if r.exits:
                break
            cutting.append(r)
    return cutting, entries[0], build, triangles


def measure(n: int, moves: int) -> dict:
    cutting, entry, build, triangles = cut(n, moves, on_body=False)
    on_body, _, _, _ = cut(n, moves, on_body=True)
    seconds = [r.seconds for r in cutting]
    return {"n": n, "triangles": triangles, "build_s": build, "entry_us": 1e6 * entry.seconds,
            "median_us": 1e6 * statistics.median(seconds), "p90_us": 1e6 * np.percentile(seconds, 90),
            "flips": sum(r.flips for r in cutting) / len(cutting),
            "splits": sum(r.incision_splits for r in cutting) / len(cutting), "moves": len(cutting),
            "body_us": 1e6 * statistics.median(r.seconds for r in on_body),
            "body_edits": sum(1 for r in on_body if r.nodes_inserted or r.nodes_removed)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 32, 100, 316, 707])
    parser.add_argument("--moves", type=int, default=40)
    parser.add_argument("--quick", action="store_true", help="sizes 10, 32, 100")
    arguments = parser.parse_args()
    sizes = (10, 32, 100) if arguments.quick else arguments.sizes
    header = (f"{'triangles':>9} {'n':>4} {'build s':>7} | {'entry µs':>8} | {'move µs':>7} {'p90 µs':>7} | "
              f"{'flips':>5} {'splits':>6} {'moves':>5} | {'body µs':>7} {'editing':>7}")
    print(header)
    print("-" * len(header))
    rows = []
    for n in sizes:
        row = measure(n, arguments.moves)
        rows.append(row)
        print(f"{row['triangles']:>9} {n:>4} {row['build_s']:>7.2f} | {row['entry_us']:>8.0f} | {row['median_us']:>7.1f} "
              f"{row['p90_us']:>7.1f} | {row['flips']:>5.2f} {row['splits']:>6.2f} {row['moves']:>5} | "
              f"{row['body_us']:>7.1f} {row['body_edits']:>7}", flush=True)
    last, first = rows[-1], rows[0]
    verdict = "met" if last["triangles"] >= 9e5 and last["median_us"] <= 50 else "NOT met (or not measured at 10⁶)"
    print(f"\ngoal ≤ 50 µs per move at 10⁶ triangles: {last['median_us']:.1f} µs at {last['triangles']}: {verdict}. "
          f"From {first['triangles']} to {last['triangles']} triangles a move costs ×"
          f"{last['median_us'] / first['median_us']:.1f}; the entry ×{last['entry_us'] / first['entry_us']:.0f}.")


if __name__ == "__main__":
    main()
