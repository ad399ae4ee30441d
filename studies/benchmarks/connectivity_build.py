"""Benchmark: building the §7 connectivity of Kuhn-split boxes (10^4 .. 10^6 tetrahedra).

    .venv/bin/python studies/benchmarks/connectivity_build.py [--sizes 22 46 55] [--repeat 3]

Prints, per box: cells, points, seconds to generate the cell array (numpy), seconds for
snede.Mesh (input checks, orientation, face matching), seconds for validate() (7.1)–(7.5),
bytes per element held by the mesh (connectivity + coordinates), and the growth of the
process's peak RSS while building. Times are the best of --repeat runs.
"""
import argparse
import resource
import time

import snede


def peak_rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def best_time(function, repeat):
    best, result = float("inf"), None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[12, 26, 55],
                        help="divisions n of the n×n×n box (6n³ tetrahedra); default 12 26 55")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    print(f"{'divisions':>9} {'cells':>10} {'points':>9} {'generate s':>11} {'Mesh() s':>9} "
          f"{'validate s':>10} {'bytes/cell':>10} {'RSS growth MB':>13}")
    for n in args.sizes:
        rss_before = peak_rss_bytes()
        generate, template = best_time(lambda: snede.meshing.box((1, 1, 1), (n, n, n)), 1)
        points, cells = template.points, template.cells
        del template
        build, mesh = best_time(lambda: snede.Mesh(points, cells), args.repeat)
        check, _ = best_time(mesh.validate, 1)
        rss_growth = (peak_rss_bytes() - rss_before) / 2**20
        print(f"{n:>9} {mesh.n_cells:>10} {mesh.n_points:>9} {generate:>11.3f} {build:>9.3f} "
              f"{check:>10.3f} {mesh.memory_bytes() / mesh.n_cells:>10.1f} {rss_growth:>13.1f}", flush=True)


if __name__ == "__main__":
    main()
