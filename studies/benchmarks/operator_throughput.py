"""Tangent products: the matrix-free shell against PETSc's assembled AIJ and BAIJ(3) matrices,
on Kuhn boxes of 10^4 to 10^6 tetrahedra, for the four materials (issue 15). Prints one table:
ms per product, ns per tetrahedron, each format's time as a ratio to the shell's (measured in
this run), bytes per tetrahedron of the operator (the shell: its per-element data; assembled:
the values and indices PETSc stores), the cost of one assembly in shell products, and ‖Ax − Jx‖/‖Jx‖.

    .venv/bin/python studies/benchmarks/operator_throughput.py            # 10^4, 10^5, 10^6 tetrahedra
    .venv/bin/python studies/benchmarks/operator_throughput.py --quick    # 10^4 and 10^5

Not a test: times depend on the machine and its load; compare the ratios of one run.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import snede

MATERIALS = {
    "LinearElastic": lambda: snede.LinearElastic(1e5, 0.3),
    "StVenantKirchhoff": lambda: snede.StVenantKirchhoff(1e5, 0.3),
    "NeoHookean": lambda: snede.NeoHookean(1e5, 0.3),
    "VerondaWestmann": lambda: snede.VerondaWestmann(1e5, 0.3, 4.0),
}
# Bytes the shell streams per tetrahedron: 4 vertex ids (int32) and Z⁻¹, |τ| (10 doubles).
SHELL_BYTES_PER_TET = 4 * 4 + 10 * 8


def median_seconds(call, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def stored_bytes(A, fmt: str) -> float:
    """Bytes of values and column indices (32-bit) PETSc stores for A: one index per value in
    AIJ, one per 3 × 3 block in BAIJ (PETSc counts memory itself only with -malloc_debug)."""
    values = A.getInfo()["nz_allocated"]
    rows = A.getSize()[0]
    if fmt == "aij":
        return values * (8 + 4) + (rows + 1) * 4
    return values * 8 + values / 9 * 4 + (rows / 3 + 1) * 4


def measure(n: int, name: str, repeats: int) -> list[dict]:
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))
    body = snede.Body(mesh, MATERIALS[name]())
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    u = 1e-3 * np.random.default_rng(0).normal(size=(mesh.n_points, 3))
    shell = body.tangent_operator(u)
    x, y = shell.createVecs()
    x.setRandom()
    shell_seconds = median_seconds(lambda: shell.mult(x, y), repeats)
    reference = y.copy()
    shell.mult(x, reference)
    rows = [dict(tets=mesh.n_cells, material=name, format="shell", seconds=shell_seconds,
                 bytes=SHELL_BYTES_PER_TET, assembly=0.0, error=0.0)]
    for fmt in ("aij", "baij"):
        start = time.perf_counter()
        A = body.assemble_tangent(u, format=fmt)
        assembly = time.perf_counter() - start
        seconds = median_seconds(lambda: A.mult(x, y), repeats)
        A.mult(x, y)
        error = (y - reference).norm() / reference.norm()
        memory = stored_bytes(A, fmt)
        rows.append(dict(tets=mesh.n_cells, material=name, format=fmt.upper(), seconds=seconds,
                         bytes=memory / mesh.n_cells, assembly=assembly, error=error))
        A.destroy()
    for row in rows:
        row["ratio"] = shell_seconds / row["seconds"]
        row["assembly_in_products"] = row["assembly"] / shell_seconds
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10^4 and 10^5 tetrahedra only")
    parser.add_argument("--materials", nargs="*", default=list(MATERIALS), choices=list(MATERIALS))
    args = parser.parse_args()
    sizes = (12, 26) if args.quick else (12, 26, 55)  # 6n³: 10 368, 105 456, 998 250 tetrahedra
    print(f"{'tetrahedra':>10} {'material':<18} {'format':<6} {'ms/product':>10} {'ns/tet':>7} "
          f"{'× shell':>8} {'bytes/tet':>9} {'assembly=products':>18} {'rel. error':>10}")
    for n in sizes:
        for name in args.materials:
            for row in measure(n, name, repeats=7 if n < 40 else 3):
                print(f"{row['tets']:>10} {row['material']:<18} {row['format']:<6} {row['seconds'] * 1e3:>10.3f} "
                      f"{row['seconds'] / row['tets'] * 1e9:>7.1f} {row['ratio']:>8.2f} {row['bytes']:>9.0f} "
                      f"{row['assembly_in_products']:>18.0f} {row['error']:>10.1e}", flush=True)
    print("'× shell': the shell's time divided by this format's (above 1: faster than the shell). "
          "'assembly=products': one assembly (sparsity and values) costs this many shell products.")


if __name__ == "__main__":
    main()
