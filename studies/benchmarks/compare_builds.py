"""Two builds of snede on the same workloads, interleaved in one run (issue 36: a restructuring
keeps every benchmark within noise):

* cut: a tetrahedral cut with a Newton solve after each of 41 moves (10 368 tetrahedra, neo-Hookean);
* needle: a 3D needle insertion (linear, haptic loop);
* relax: dynamic relaxation of a cantilever to (6.9) at 1e-6;
* delaunay: a 2D Delaunay cut of a 160 × 160 sheet;
* organ_mg: a serial Newton solve with preconditioner "mg" of a neo-Hookean liver (E = 50 kPa, about 20 000
  of gmsh's tetrahedra from studies/benchmarks/organ_meshes.py) sagging under gravity;
* box_cg_none, box_cg_jacobi: a serial linear CG solve of a 32³ box (196 608 tetrahedra) under
  gravity, preconditioner "none" or "jacobi";
* ranks_gamg_1, ranks_gamg_2: StaticSolver(body, "newton", preconditioner="gamg",
  comm=MPI.COMM_WORLD) on a neo-Hookean 20³ box under gravity, on 1 rank and (under mpirun) on 2
  ranks; the time includes making the solver, which distributes the body.

Each round runs every serial workload of a build in one fresh process, and the 2-rank ones in one
mpirun; rounds alternate which build goes first. Prints (a markdown table) the median seconds of
each workload per build, the spread of its rounds ((max - min) / median) and the ratio of the
medians; the seconds of every round go to stderr.

A build is a folder holding the `snede` package with its compiled `_snede` module beside it:

    bash studies/benchmarks/package_build.sh REV /tmp/snede-REV    # a worktree at REV, built (about 5 minutes)
    bash studies/benchmarks/package_build.sh HEAD /tmp/snede-head
    .venv/bin/python studies/benchmarks/compare_builds.py /tmp/snede-REV /tmp/snede-head   # about 1 minute

Options: --rounds N (default 3), --only a,b (a subset of the workloads), --no-mpi (skip the
2-rank run, e.g. without mpirun). Not a test: time it on a quiet machine; only the ratios of one
run mean anything.
"""
from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent

WORKLOADS = r'''
import json, sys, time, warnings
import numpy as np
import snede
warnings.simplefilter("ignore")
BENCHMARKS = sys.argv[2]  # this folder, for organ_meshes.py


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


def timed_solve(body, method, **settings):
    """Seconds to make a StaticSolver and solve from rest (making it distributes the body on ranks)."""
    start = time.perf_counter()
    assert snede.StaticSolver(body, method, **settings).solve().converged
    return time.perf_counter() - start


def organ_mg():
    sys.path.insert(0, BENCHMARKS)
    from organ_meshes import organ_mesh
    mesh = organ_mesh("liver", 20000)
    body = snede.Body(mesh, snede.NeoHookean(E=5e4, nu=0.4), density=1000.0)
    z = mesh.points[:, 2]
    # Held by its lowest fifth (under the left lobe): the right lobe sags by about 0.2 m, 20 Newton iterations.
    body.fix(z < z.min() + 0.2 * (z.max() - z.min()))
    body.add_gravity((0.0, 0.0, -9.81))
    return timed_solve(body, "newton", preconditioner="mg")


def box_cg(preconditioner):
    mesh = snede.meshing.box((0.1, 0.1, 0.1), (32, 32, 32))
    body = snede.Body(mesh, snede.LinearElastic(34e3, 0.34), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return timed_solve(body, "cg", preconditioner=preconditioner)


def box_cg_none():
    return box_cg("none")


def box_cg_jacobi():
    return box_cg("jacobi")


def ranks_gamg():
    from mpi4py import MPI
    mesh = snede.meshing.box((0.1, 0.1, 0.1), (20, 20, 20))
    body = snede.Body(mesh, snede.NeoHookean(E=5e3, nu=0.4), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    MPI.COMM_WORLD.Barrier()
    seconds = timed_solve(body, "newton", preconditioner="gamg", comm=MPI.COMM_WORLD)
    return MPI.COMM_WORLD.allreduce(seconds, op=MPI.MAX)


times = {name: globals()[name]() for name in sys.argv[1].split(",")}
if "mpi4py.MPI" not in sys.modules or sys.modules["mpi4py.MPI"].COMM_WORLD.rank == 0:
    print(json.dumps(times))
'''
SERIAL = ("cut", "needle", "relax", "delaunay", "organ_mg", "box_cg_none", "box_cg_jacobi", "ranks_gamg")
ON_TWO_RANKS = ("ranks_gamg",)
# (ranks, the workload's function in WORKLOADS, its name in the table)
WORKLOADS_BY_RANKS = ([(1, name, f"{name}_1" if name in ON_TWO_RANKS else name) for name in SERIAL]
                      + [(2, name, f"{name}_2") for name in ON_TWO_RANKS])
MPIRUN_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
              "OMPI_MCA_rmaps_base_oversubscribe": "1"}


def site_packages() -> str:
    """This interpreter's site-packages (numpy, petsc4py, ...), without its editable snede."""
    return next(p for p in sys.path if p.endswith("site-packages"))


def run(build: Path, names: list[str], ranks: int) -> dict[str, float]:
    """Seconds of each workload in one process of `build` (on `ranks` MPI ranks under mpirun if > 1)."""
    # -S: no .pth files, so the editable install of the checkout does not shadow the build.
    command = [sys.executable, "-S", "-c", WORKLOADS, ",".join(names), str(BENCHMARKS)]
    env = {"PYTHONPATH": f"{build}:{site_packages()}", "PATH": "/usr/bin:/bin"}
    if ranks > 1:
        command = ["mpirun", "-n", str(ranks), "-x", "PYTHONPATH", *command]
        env.update(MPIRUN_ENV)
    done = subprocess.run(command, capture_output=True, text=True, env=env)
    if done.returncode:
        raise SystemExit(f"{build} ({ranks} rank(s)): {done.stderr[-3000:]}")
    return json.loads(done.stdout.splitlines()[-1])


def spread(samples: list[float]) -> float:
    return (max(samples) - min(samples)) / statistics.median(samples)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("builds", nargs=2, type=Path, help="the first and the second build folder")
    parser.add_argument("--rounds", type=int, default=3, help="runs of every workload per build (default 3)")
    parser.add_argument("--only", help="comma-separated workloads (default all): " + ", ".join(
        label for _, _, label in WORKLOADS_BY_RANKS))
    parser.add_argument("--no-mpi", action="store_true", help="skip the workloads on 2 ranks")
    arguments = parser.parse_args()
    if arguments.rounds < 1:
        parser.error(f"--rounds must be at least 1, got {arguments.rounds}")
    builds = [build.resolve() for build in arguments.builds]
    for build in builds:
        if not list((build / "snede").glob("_snede*.so")):
            parser.error(f"{build}: no snede/_snede*.so (see package_build.sh)")
    workloads = [workload for workload in WORKLOADS_BY_RANKS if workload[0] == 1 or not arguments.no_mpi]
    if arguments.only:
        chosen = arguments.only.split(",")
        unknown = set(chosen) - {label for _, _, label in workloads}
        if unknown:
            parser.error(f"unknown workloads {sorted(unknown)}; available: {[label for _, _, label in workloads]}")
        workloads = [workload for workload in workloads if workload[2] in chosen]
    if any(ranks > 1 for ranks, _, _ in workloads) and shutil.which("mpirun") is None:
        parser.error("no mpirun on PATH for the 2-rank workloads (or pass --no-mpi)")
    samples: list[dict[str, list[float]]] = [{}, {}]
    for repeat in range(arguments.rounds):
        for index in (0, 1) if repeat % 2 == 0 else (1, 0):
            for ranks in sorted({ranks for ranks, _, _ in workloads}):
                names = [name for r, name, _ in workloads if r == ranks]
                labels = {name: label for r, name, label in workloads if r == ranks}
                for name, seconds in run(builds[index], names, ranks).items():
                    samples[index].setdefault(labels[name], []).append(seconds)
        print(f"round {repeat + 1}/{arguments.rounds} done", file=sys.stderr, flush=True)
    print("| workload | first: median [s] | spread | second: median [s] | spread | second/first |")
    print("|---|--:|--:|--:|--:|--:|")
    for _, _, label in workloads:
        first, second = samples[0][label], samples[1][label]
        ratio = statistics.median(second) / statistics.median(first)
        print(f"| {label} | {statistics.median(first):.3f} | {spread(first):.0%} | {statistics.median(second):.3f} "
              f"| {spread(second):.0%} | {ratio:.3f} |")
    print("raw seconds: " + json.dumps({"first": samples[0], "second": samples[1]}), file=sys.stderr)


if __name__ == "__main__":
    main()
