"""Static solves against mesh size and preconditioner (issue 15), in one run:

1. CG on the linear cantilever (1 × 0.2 × 0.2 m, E = 1e5 Pa, ν = 0.3, gravity, fixed at x = 0,
   rtol 1e-8) for h, h/2, h/4 (and h/8 without --quick): iterations and seconds for each
   preconditioner — unpreconditioned CG's count grows like 1/h, GAMG's and mg's should not.
   Every mesh is the 5 × 1 × 1 Kuhn box bisected uniformly (3 levels per halving of h), so
   that mg has its hierarchy and every preconditioner sees the same mesh.
2. The issue's neo-Hookean block: 0.2 × 0.05 × 0.05 m, 98 304 tetrahedra, E = 1e5 Pa,
   ν = 0.3, gravity, fixed at x = 0, rtol 1e-6, with each method; and the same problem (mesh
   size, energy, load) in FEniCSx (Debian's python3-dolfinx 0.5.2, run by /usr/bin/python3:
   Newton with full steps, CG + GAMG with the rigid-body near null space), if installed.
   mg's bisection levels need a bisection hierarchy: they run on the 4 × 1 × 1 Kuhn box bisected
   12 times (the same vertices and element count as the 64 × 16 × 16 grid, other diagonals and
   another numbering), and GAMG and mg's grid levels are timed on that mesh too; on the
   generated mesh mg coarsens on a background grid (issue 31), or by aggregation.

    .venv/bin/python studies/benchmarks/static_solve_scaling.py            # about 2 minutes
    .venv/bin/python studies/benchmarks/static_solve_scaling.py --quick    # about 90 s
    .venv/bin/python studies/benchmarks/static_solve_scaling.py --block    # the block only, about 80 s

Not a test: times depend on the machine and its load; compare the ratios of one run.
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

import snede

sys.path.insert(0, str(Path(__file__).resolve().parent))
from work_units import work_unit_flops, work_unit_seconds  # noqa: E402

BLOCK_DIVISIONS = (64, 16, 16)  # 6 · 64 · 16 · 16 = 98 304 tetrahedra


def cantilever(n: int):
    mesh = snede.meshing.box((1.0, 0.2, 0.2), (5, 1, 1))
    mesh.refine_uniform(3 * int(np.log2(n)))  # h/2 every 3 bisections: the (5n, n, n) grid's size
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


def block(refined: bool = False):
    if refined:
        mesh = snede.meshing.box((0.2, 0.05, 0.05), (4, 1, 1))
        mesh.refine_uniform(12)  # 24 · 2^12 = 98 304 tetrahedra
    else:
        mesh = snede.meshing.box((0.2, 0.05, 0.05), BLOCK_DIVISIONS)
    body = snede.Body(mesh, snede.NeoHookean(1e5, 0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


def timed_solve(body, method: str, **options):
    """(solver, result, seconds) of one solve."""
    solver = snede.StaticSolver(body, method, **options)
    start = time.perf_counter()
    result = solver.solve()
    return solver, result, time.perf_counter() - start


def cantilever_table(levels) -> None:
    print("1. CG on the linear cantilever (rtol 1e-8)")
    print(f"{'n':>3} {'tetrahedra':>10} {'dofs':>8} {'preconditioner':<15} {'iterations':>10} {'seconds':>8}  reason")
    counts = {}
    for pc in ("none", "jacobi", "icc", "gamg", "mg"):
        for n in levels:
            body = cantilever(n)
            _, result, seconds = timed_solve(body, "cg", rtol=1e-8, preconditioner=pc)
            counts.setdefault(pc, []).append(result.iterations)
            print(f"{n:>3} {body.mesh.n_cells:>10} {3 * body.mesh.n_points:>8} {pc:<15} {result.iterations:>10} "
                  f"{seconds:>8.3f}  {result.reason}", flush=True)
    for pc, values in counts.items():
        print(f"   {pc}: iterations at h/{levels[-1] // levels[0]} ÷ at h = {values[-1] / values[0]:.2f}")


FENICSX_BLOCK = textwrap.dedent("""
    import json, sys, time
    import numpy as np, ufl
    from mpi4py import MPI
    from petsc4py import PETSc
    from dolfinx import fem, mesh
    from dolfinx.fem.petsc import NonlinearProblem
    from dolfinx.nls.petsc import NewtonSolver

    start = time.perf_counter()
    if len(sys.argv) > 1:  # snede's mesh, from an .npz (FEniCSx renumbers it for locality)
        given = np.load(sys.argv[1])
        domain = mesh.create_mesh(MPI.COMM_WORLD, given["cells"], given["points"],
                                  ufl.Mesh(ufl.VectorElement("Lagrange", "tetrahedron", 1)))
    else:
        domain = mesh.create_box(MPI.COMM_WORLD, [np.zeros(3), np.array([0.2, 0.05, 0.05])], [64, 16, 16],
                                 mesh.CellType.tetrahedron)
    V = fem.VectorFunctionSpace(domain, ("CG", 1))
    facets = mesh.locate_entities_boundary(domain, 2, lambda x: np.isclose(x[0], 0.0))
    bc = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), fem.locate_dofs_topological(V, 2, facets), V)
    u, v = fem.Function(V), ufl.TestFunction(V)
    E, nu, rho = 1e5, 0.3, 1000.0
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    F = ufl.Identity(3) + ufl.grad(u)
    J = ufl.det(F)
    # snede's neo-Hookean (4.6): W = mu/2 (I1 - 3) - mu ln J + lambda/2 (J - 1)^2
    W = mu / 2 * (ufl.tr(F.T * F) - 3) - mu * ufl.ln(J) + lmbda / 2 * (J - 1) ** 2
    Pi = W * ufl.dx - ufl.dot(fem.Constant(domain, PETSc.ScalarType((0, 0, -9.81 * rho))), u) * ufl.dx
    problem = NonlinearProblem(ufl.derivative(Pi, u, v), u, [bc])
    solver = NewtonSolver(MPI.COMM_WORLD, problem)
    solver.rtol, solver.atol, solver.convergence_criterion, solver.max_it = 1e-6, 0.0, "residual", 50
    ksp = solver.krylov_solver
    options, prefix = PETSc.Options(), ksp.getOptionsPrefix()
    options[f"{prefix}ksp_type"], options[f"{prefix}pc_type"], options[f"{prefix}ksp_rtol"] = "cg", "gamg", 1e-3
    ksp.setFromOptions()
    coordinates = PETSc.Vec().createWithArray(V.tabulate_dof_coordinates()[:, :3].ravel().copy())
    coordinates.setBlockSize(3)
    solver.A.setNearNullSpace(PETSc.NullSpace().createRigidBody(coordinates))
    calls = []  # every CG iteration after the first residual of a solve is one CG iteration
    ksp.setMonitor(lambda k, it, r: calls.append(it))
    setup = time.perf_counter() - start
    start = time.perf_counter()
    iterations, converged = solver.solve(u)
    seconds = time.perf_counter() - start
    print(json.dumps(dict(newton=int(iterations), converged=bool(converged), seconds=seconds, setup=setup,
                          linear=sum(1 for it in calls if it > 0), tets=domain.topology.index_map(3).size_global,
                          u_min=float(u.x.array.reshape(-1, 3)[:, 2].min()))))
""")


def fenicsx_block(mesh=None) -> dict | None:
    """FEniCSx on its own 64 × 16 × 16 box, or on `mesh` (snede's, passed through a file)."""
    python = shutil.which("python3", path="/usr/bin")
    if python is None:
        return None
    with tempfile.TemporaryDirectory() as folder:
        arguments = []
        if mesh is not None:
            arguments = [f"{folder}/mesh.npz"]
            np.savez(arguments[0], points=mesh.points, cells=mesh.cells.astype(np.int64))
        run = subprocess.run([python, "-c", FENICSX_BLOCK, *arguments], capture_output=True, text=True, timeout=900)
    if run.returncode != 0:
        print(f"   FEniCSx did not run ({run.stderr.strip().splitlines()[-1] if run.stderr.strip() else run.returncode})")
        return None
    return json.loads(run.stdout.strip().splitlines()[-1])


def block_table() -> None:
    print("\n2. The neo-Hookean block, 98 304 tetrahedra, rtol 1e-6")
    print("   (fills: the preconditioner's fills; WU: the solve in products of the mesh's assembled AIJ tangent,\n"
          "    timed in this run; flop WU: its logged flops in the flops of one product, issue 49; refresh ratio 0:\n"
          "    the levels filled once per solve, -static_mg_refresh_ratio 0; lag 1: filled at every Newton step)")
    print(f"{'solver':<44} {'outer':>6} {'CG':>6} {'fills':>5} {'seconds':>8} {'WU':>6} {'flop WU':>7} "
          f"{'u_z min [m]':>12}  reason")
    runs = [
        ("snede newton, mg (bisected mesh)", "newton", {"preconditioner": "mg"}),
        ("snede newton, gamg (bisected mesh)", "newton", {"preconditioner": "gamg"}),
        ("snede newton, mg on a grid (bisected)", "newton", {"preconditioner": "mg", "petsc_options":
                                                             {"mg_coarsening": "grid"}}),
        ("snede newton, mg on a grid (the default)", "newton", {"preconditioner": "mg"}),
        ("snede newton, mg on a grid, refresh ratio 0", "newton",
         {"preconditioner": "mg", "petsc_options": {"mg_refresh_ratio": 0}}),
        ("snede newton, mg on a grid, lag 1", "newton",
         {"preconditioner": "mg", "petsc_options": {"snes_lag_preconditioner": 1}}),
        ("snede newton, mg by aggregation", "newton", {"preconditioner": "mg", "petsc_options":
                                                       {"mg_coarsening": "aggregation"}}),
        ("snede newton, no preconditioner", "newton", {"preconditioner": "none"}),
        ("snede newton, jacobi", "newton", {"preconditioner": "jacobi"}),
        ("snede newton, gamg", "newton", {"preconditioner": "gamg"}),
        ("snede newton, gamg, lag 3", "newton", {"preconditioner": "gamg",
                                                  "petsc_options": {"snes_lag_preconditioner": 3}}),
        ("snede ncg (Polak-Ribière, secant)", "ncg", {}),
    ]
    seconds_of = {}
    unit = {}
    for label, method, options in runs:
        refined = "bisected" in label
        body = block(refined=refined)
        if refined not in unit:
            unit[refined] = (work_unit_seconds(body), work_unit_flops(body))
        solver, result, seconds = timed_solve(body, method, rtol=1e-6, **options)
        seconds_of[label] = seconds
        unit_seconds, unit_flops = unit[refined]
        print(f"{label:<44} {result.iterations:>6} {result.linear_iterations:>6} {solver.preconditioner_fills:>5} "
              f"{seconds:>8.2f} {seconds / unit_seconds:>6.0f} {result.flops / unit_flops:>7.0f} "
              f"{body.displacement[:, 2].min():>12.6f}  {result.reason}", flush=True)
    peers = {}
    for mesh_label, mesh in (("", None), (" (bisected mesh)", block(refined=True).mesh)):
        peer = fenicsx_block(mesh)
        if peer is None:
            print("   FEniCSx: not installed (apt-get install python3-dolfinx); no comparison")
            return
        peers[mesh_label] = peer
        label = f"FEniCSx 0.5.2 newton, CG + gamg{mesh_label}"
        print(f"{label:<44} {peer['newton']:>6} {peer['linear']:>6} {'':>5} {peer['seconds']:>8.2f} {'':>6} {'':>7} "
              f"{peer['u_min']:>12.6f}  "
              f"{'converged' if peer['converged'] else 'NOT converged'} (full steps; {peer['tets']} tetrahedra; "
              f"+ {peer['setup']:.1f} s forms and set-up)", flush=True)
    for label in ("snede newton, mg (bisected mesh)", "snede newton, gamg (bisected mesh)", "snede newton, gamg",
                  "snede newton, gamg, lag 3"):
        peer_label = " (bisected mesh)" if "bisected" in label else ""
        print(f"   {label}: {seconds_of[label] / peers[peer_label]['seconds']:.2f} × FEniCSx's solve time on the "
              f"same mesh")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="cantilever to h/4 only")
    parser.add_argument("--block", action="store_true", help="the neo-Hookean block only")
    args = parser.parse_args()
    if not args.block:
        cantilever_table((2, 4, 8) if args.quick else (2, 4, 8, 16))
    block_table()


if __name__ == "__main__":
    main()
