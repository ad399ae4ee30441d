"""Benchmark: memory a scene costs by solution method ("model only what the scene requires").

    .venv/bin/python studies/benchmarks/memory_by_method.py [--divisions 40]

Each row runs in a fresh process (PETSc with -malloc_debug, so that its allocations are
counted): a box of 5n × n × n Kuhn-split cubes with a neo-Hookean body fixed on one side
under gravity, then one iteration of the method. Prints the bytes PETSc holds for the
method's objects (vectors, shell, KSP/SNES/TS work space) per degree of freedom, and the
process's RSS growth. A static scene holds no velocity or mass vectors; the dynamic one
does (velocity, inverse mass, TS work vectors).
"""
import argparse
import json
import subprocess
import sys

PROBE = r"""
import json, os, sys
import numpy as np
import snede

def rss():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")

n, method = int(sys.argv[1]), sys.argv[2]
before = rss()
petsc_before = snede._snede.petsc_allocated_bytes()
mesh = snede.meshing.box((0.1, 0.02, 0.02), (5 * n, n, n))
body = snede.Body(mesh, snede.NeoHookean(3e4, 0.3))
body.fix(np.isclose(mesh.points[:, 0], 0.0))
body.add_gravity((0, 0, -9.81))
solver = None  # kept alive while measuring
if method == "dynamic":
    solver = snede.DynamicRelaxation(body, damping=20.0)
    solver.step(1)
elif method != "baseline":
    solver = snede.StaticSolver(body, method, rtol=1e-6, max_iterations=1, options_prefix="memory_",
                                preconditioner="none")  # the methods' own memory (§4.4)
    solver.solve()
print(json.dumps({"rss": rss() - before, "petsc": snede._snede.petsc_allocated_bytes() - petsc_before,
                  "cells": mesh.n_cells, "dofs": mesh.n_points * 3}))
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--divisions", type=int, default=12, help="the box has 5n × n × n cubes (default 12)")
    args = parser.parse_args()
    rows = {}
    for method in ("baseline", "ncg", "newton", "dynamic"):
        out = subprocess.run([sys.executable, "-c", PROBE, str(args.divisions), method, "-malloc_debug"],
                             capture_output=True, text=True, check=True)
        rows[method] = json.loads(out.stdout.strip().splitlines()[-1])
    base = rows["baseline"]
    print(f"box of {base['cells']} tetrahedra, {base['dofs']} dofs")
    print(f"{'method':<10} {'PETSc MB':>9} {'PETSc bytes/dof':>16} {'process RSS growth MB':>22}")
    for method, row in rows.items():
        print(f"{method:<10} {row['petsc'] / 2**20:>9.2f} {row['petsc'] / base['dofs']:>16.1f} {row['rss'] / 2**20:>22.1f}")


if __name__ == "__main__":
    main()
