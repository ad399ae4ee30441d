"""Benchmark: the cost of one sweep triangle of snede.TetrahedralCutter (§3.2) against mesh size.

    .venv/bin/python studies/benchmarks/cutting_rates.py [--sizes 6 12 26 55] [--repeats 3] [--quick]

Kuhn boxes snede.meshing.box((1, 1, 1), (n, n, n)) of 6n³ tetrahedra, from about 10³ (n = 6)
to about 10⁶ (n = 55), all cut by the same scalpel path in units of the mesh spacing h = 1/n:
a blade 3h long, in a plane tilted against the mesh's faces, starting h/2 outside the front
face (z = 1) and pushed 5 moves of h each into the body (each move is two sweep triangles,
processed here with cut_triangle so that each triangle is timed alone: CutResult.seconds).
So every mesh sees the same cut, dissecting a handful of faces per sweep triangle.

Columns (milliseconds per sweep triangle, medians over the triangles of ``--repeats`` cuts,
each on a fresh mesh):

* first move: the two triangles of the first move, the first contact with the body: no earlier
  sweep to start from, so the selector scans the boundary faces (O(boundary), ~n²).
* no dissection: later triangles that dissected nothing (selection and snapping only).
* dissecting, no removal / with removal: later triangles that dissected faces, with
  remove_degeneracies False / True (threshold 0.01); 'removal' is the difference.
* with Body: the same on a snede.Body (LinearElastic): the body's PETSc vectors are reissued
  after each sweep that adds vertices.
* full count: the time of one mesh.connected_components() call (from Python), an O(n) pass
  over all elements, for comparison: the cutter does not make it after every sweep. It
  counts the body's pieces (§3.3: free pieces are fixed) by a search from the elements the
  sweep changed, which stops once the searches meet around the incision's edge; 'search' is
  the median number of elements it visited (CutResult.piece_search). Only a sweep that
  separates a piece relabels all elements.
* later: all triangles after the first move (remove_degeneracies=True, bare mesh), dissecting
  or not; ratio: 'later' over the smallest mesh's.

The issue's goal is a cost independent of the mesh size, at most 1 ms per sweep triangle at 10⁵
tetrahedra; the last line says what was measured.
"""
import argparse
import statistics
import time

import numpy as np

import snede

BLADE = 3.0  # blade length in mesh spacings
MOVES = 5  # moves of one mesh spacing each; the first crosses the front face
START = -0.5  # the blade starts this many spacings outside the front face


def blade_path(n: int) -> np.ndarray:
    """(MOVES + 1, 2, 3) blade positions for the box of n divisions, in units of h = 1/n."""
    h = 1.0 / n
    normal = np.array([0.9, 0.35, 0.25])
    normal /= np.linalg.norm(normal)
    down = np.array([0.0, 0.0, -1.0]) - normal * -normal[2]  # −z projected into the cut plane
    down /= np.linalg.norm(down)
    blade = np.cross(normal, down)
    centre = np.array([0.5 + 0.31 * h, 0.5 + 0.17 * h, 1.0])  # off the mesh's vertex layers
    path = []
    for k in range(MOVES + 1):
        middle = centre + down * ((START + k) * h) / -down[2]  # z = 1 − (START + k) h
        path.append([middle - 0.5 * BLADE * h * blade, middle + 0.5 * BLADE * h * blade])
    return np.array(path)


def triangles(path) -> list[np.ndarray]:
    """The sweep triangles of the moves, as TetrahedralCutter.move makes them: (p0, p1, q1) and
    (p0, q1, q0) for the move from (p0, p1) to (q0, q1)."""
    out = []
    for (p0, p1), (q0, q1) in zip(path[:-1], path[1:]):
        out.append(np.array([p0, p1, q1]))
        out.append(np.array([p0, q1, q0]))
    return out


def run(n: int, remove: bool, body: bool):
    """One cut on a fresh box; a list of (move index, CutResult) per sweep triangle."""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))
    target = snede.Body(mesh, snede.LinearElastic(1e4, 0.25)) if body else mesh
    cutter = snede.TetrahedralCutter(target, remove_degeneracies=remove)
    reports = [(k // 2, cutter.cut_triangle(triangle)) for k, triangle in enumerate(triangles(blade_path(n)))]
    if n <= 12:
        mesh.validate()
    return reports


def median_ms(values) -> float:
    return 1e3 * statistics.median(values) if values else float("nan")


def measure(n: int, repeats: int) -> dict:
    start = time.perf_counter()
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))
    build = time.perf_counter() - start
    components = min(_timed(mesh.connected_components) for _ in range(3))
    row = {"n": n, "tets": mesh.n_cells, "boundary": len(mesh.boundary_faces()), "build_s": build,
           "components_ms": 1e3 * components}
    for name, remove, body in (("plain", False, False), ("removal", True, False), ("body", True, True)):
        first, idle, dissecting, faces, later, search = [], [], [], [], [], []
        for _ in range(repeats):
            for move, report in run(n, remove, body):
                if move == 0:
                    first.append(report.seconds)
                    continue
                later.append(report.seconds)
                if report.faces_dissected > 0:
                    dissecting.append(report.seconds)
                    faces.append(report.faces_dissected)
                    search.append(report.piece_search)
                else:
                    idle.append(report.seconds)
        row[f"{name}_first"] = median_ms(first)
        row[f"{name}_idle"] = median_ms(idle)
        row[f"{name}_later"] = median_ms(later)
        row[f"{name}_dissecting"] = median_ms(dissecting)
        row[f"{name}_faces"] = statistics.median(faces) if faces else 0
        row[f"{name}_count"] = len(dissecting)
        row[f"{name}_search"] = statistics.median(search) if search else 0
    return row


def _timed(operation) -> float:
    start = time.perf_counter()
    operation()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs="+", default=[6, 9, 12, 18, 26, 38, 55],
                        help="box divisions n (6n³ tetrahedra); default 6 … 55 (1296 … 998250)")
    parser.add_argument("--repeats", type=int, default=3, help="cuts per size and variant (fresh meshes)")
    parser.add_argument("--quick", action="store_true", help="sizes 6, 12, 26 and one repeat")
    arguments = parser.parse_args()
    sizes, repeats = ((6, 12, 26), 1) if arguments.quick else (arguments.sizes, arguments.repeats)
    print(f"blade {BLADE:g} h, {MOVES} moves of 1 h from {-START:g} h outside the front face; milliseconds per sweep "
          f"triangle (CutResult.seconds), medians over {repeats} cut(s) per cell; first/later/no diss./+removal: "
          "bare mesh with removal; dissecting: without removal; w/ Body: on a Body, with removal")
    header = (f"{'tets':>8} {'n':>3} {'boundary':>8} {'build s':>7} | {'first':>6} {'later':>6} {'no diss.':>8} | "
              f"{'dissecting':>10} {'+removal':>8} {'removal':>7} {'w/ Body':>8} | {'faces':>5} {'#':>3} | "
              f"{'full count':>10} {'search':>6} | {'ratio':>6}")
    print(header)
    print("-" * len(header))
    rows = []
    for n in sizes:
        row = measure(n, repeats)
        rows.append(row)
        ratio = row["removal_later"] / rows[0]["removal_later"]
        print(f"{row['tets']:>8} {n:>3} {row['boundary']:>8} {row['build_s']:>7.2f} | {row['removal_first']:>6.2f} "
              f"{row['removal_later']:>6.2f} {row['removal_idle']:>8.2f} | {row['plain_dissecting']:>10.2f} "
              f"{row['removal_dissecting']:>8.2f} "
              f"{row['removal_dissecting'] - row['plain_dissecting']:>+7.2f} {row['body_dissecting']:>8.2f} | "
              f"{row['removal_faces']:>5g} {row['removal_count']:>3} | {row['components_ms']:>10.2f} "
              f"{row['removal_search']:>6g} | {ratio:>6.1f}", flush=True)
    near = min(rows, key=lambda row: abs(np.log(row["tets"] / 1e5)))
    verdict = "met" if near["removal_later"] <= 1.0 else "NOT met"
    first, last = rows[0], rows[-1]
    print(f"\ngoal ≤ 1 ms per sweep triangle at ~10⁵ tetrahedra: {near['removal_later']:.2f} ms per sweep triangle "
          f"({near['removal_dissecting']:.2f} ms when it dissects) at {near['tets']} tetrahedra: {verdict}. From "
          f"{first['tets']} to {last['tets']} tetrahedra the time per sweep triangle grows "
          f"×{last['removal_later'] / first['removal_later']:.0f} (×{last['tets'] / first['tets']:.0f} elements), "
          f"the first contact ×{last['removal_first'] / first['removal_first']:.0f} "
          f"(×{last['boundary'] / first['boundary']:.0f} boundary faces); the piece search visits "
          f"{first['removal_search']:g} → {last['removal_search']:g} elements per dissecting sweep, where a full "
          f"count would cost {last['components_ms']:.0f} ms at {last['tets']}.")


if __name__ == "__main__":
    main()
