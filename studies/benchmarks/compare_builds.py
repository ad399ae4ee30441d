"""Two builds of snede on the same workloads, interleaved in one run (issue 36: a restructuring
keeps every benchmark within noise): a tetrahedral cut with a Newton solve after each of 41
moves (10 368 tetrahedra, neo-Hookean), a 3D needle insertion (linear, haptic loop), dynamic
relaxation of a cantilever to (6.9) at 1e-6, and a 2D Delaunay cut of a 160 × 160 sheet.
Prints the best seconds of each workload per build and their ratio.

A build is a folder holding the `snede` package with its compiled `_snede` module beside it:

    bash studies/benchmarks/package_build.sh REV /tmp/snede-REV    # a worktree at REV, built (about 5 minutes)
    bash studies/benchmarks/package_build.sh HEAD /tmp/snede-head
    .venv/bin/python studies/benchmarks/compare_builds.py /tmp/snede-REV /tmp/snede-head   # about 1 minute

Not a test: time it on a quiet machine; only the ratios of one run mean anything.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

WORKLOADS = r'''
import json, sys, time, warnings
import numpy as np
import snede
warnings.simplefilter("ignore")


def cut():
    mesh = snede.meshing.box((0.1, 0.05, 0.05), (24, 12, 12))
    body = snede.Body(mesh, snede.NeoHookean(E=5e3, nu=0.4), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    solver = snede.StaticSolver(body, "newton", rtol=1e-4)
    solver.solve()
    cutter = snede.TetrahedralCutter(body)
    start = time.perf_counter()
    for k in range(41):
        x = 0.0101 + 0.002 * k
        cutter.move(np.array([[x, 0.0251, 0.0301], [x, 0.0251, 0.0601]]))
        assert solver.solve().converged
    return time.perf_counter() - start


def needle():
    mesh = snede.meshing.box((0.1, 0.1, 0.1), (2, 2, 2))
    mesh.refine_uniform(3)
    body = snede.Body(mesh, snede.LinearElastic(34e3, 0.34))
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    insertion = snede.NeedleInsertion(body, (-0.005, 0.0513, 0.0489), (1.0, 0.0, 0.0),
                                      snede.FrictionProfile.figure_6_4(), radius=1e-3, h_ref=0.1 / 48, method="cg",
                                      rtol=1e-3, solves_per_update=1)
    start = time.perf_counter()
    assert insertion.insert(0.06, 0.5 * 0.1 / 48).converged
    return time.perf_counter() - start


def relax():
    mesh = snede.meshing.box((0.3, 0.05, 0.05), (48, 8, 8))
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    relaxation = snede.DynamicRelaxation(body, damping=15.0)
    start = time.perf_counter()
    assert relaxation.run(rtol=1e-6, max_steps=200000).converged
    return time.perf_counter() - start


def delaunay():
    mesh = snede.meshing.rectangle((0.1, 0.1), (160, 160))
    body = snede.Body(mesh, snede.LinearElastic(34e3, 0.34), thickness=0.01)
    body.fix(np.isclose(mesh.points[:, 1], 0.0))
    cutter = snede.DelaunayCutter(body)
    start = time.perf_counter()
    cutter.cut(np.array([[-0.01, 0.0513], [0.0497, 0.0521], [0.07, 0.081], [0.0303, 0.0905], [0.0201, 0.0702]]))
    return time.perf_counter() - start


print(json.dumps({name: globals()[name]() for name in sys.argv[1].split(",")}))
'''
NAMES = "cut,needle,relax,delaunay"


def site_packages() -> str:
    """This interpreter's site-packages (numpy, petsc4py, ...), without its editable snede."""
    return next(p for p in sys.path if p.endswith("site-packages"))


def run(build: Path) -> dict[str, float]:
    # -S: no .pth files, so the editable install of the checkout does not shadow the build.
    done = subprocess.run([sys.executable, "-S", "-c", WORKLOADS, NAMES], capture_output=True, text=True,
                          env={"PYTHONPATH": f"{build}:{site_packages()}", "PATH": "/usr/bin:/bin"})
    if done.returncode:
        raise SystemExit(f"{build}: {done.stderr[-3000:]}")
    return json.loads(done.stdout.splitlines()[-1])


def main() -> None:
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    builds = [Path(a).resolve() for a in sys.argv[1:]]
    for build in builds:
        if not list((build / "snede").glob("_snede*.so")):
            raise SystemExit(f"{build}: no snede/_snede*.so (see package_build.sh)")
    best: list[dict[str, float]] = [{}, {}]
    for repeat in range(5):
        for index in (0, 1) if repeat % 2 == 0 else (1, 0):
            for name, seconds in run(builds[index]).items():
                best[index][name] = min(best[index].get(name, float("inf")), seconds)
        print(f"round {repeat + 1}/5 done", file=sys.stderr, flush=True)
    print(f"{'workload':<10} {'first [s]':>10} {'second [s]':>11} {'second/first':>13}")
    for name in NAMES.split(","):
        print(f"{name:<10} {best[0][name]:>10.3f} {best[1][name]:>11.3f} {best[1][name] / best[0][name]:>13.3f}")


if __name__ == "__main__":
    main()
