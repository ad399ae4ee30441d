"""Benchmark: static Newton solves of membranes (triangles in 3D) with each preconditioner
(issue 31: mg for every mesh the solver accepts).

    .venv/bin/python studies/benchmarks/membrane_preconditioners.py           # about 40 s
    .venv/bin/python studies/benchmarks/membrane_preconditioners.py --quick   # the smaller sizes only

Scenes, neo-Hookean E = 100 kPa, ν = 0.3, 1 mm thick, Newton rtol 1e-6:

* taut sheet: a flat unit square (n × n squares, 2n² triangles) whose rim is pulled out by
  10 %, starting from the homogeneous stretch, under 1 mN per free vertex across its plane — a
  unique, stable equilibrium;
* slack sheet: the same, starting from rest with only the rim moved: the first Newton step
  meets elements with no stiffness across the sheet, along which the load pulls;
* hanging skin: the boundary of a 0.4 × 0.1 × 0.1 m box (36 n² triangles) held at x = 0 under
  gravity (1000 kg/m³); it sags by about its own length into folds, where compressed elements
  make the tangent indefinite (several equilibria: the final sag differs between rows);
* organ skin: the closed skins of docs/results/membranes_on_organs.md (E = 5 kPa, ν = 0.45, held
  along the top tenth): snede.meshing.ellipsoid(h=0.01)'s, and those of SOFA's liver filled by
  gmsh with 1 500 and 6 000 tetrahedra (studies/benchmarks/organ_meshes.py).

One row per scene, size and preconditioner: whether the solve converged (PETSc's reason),
Newton and CG iterations, seconds, and the time without a preconditioner over this one.
Compare rows of one run (the machine is shared).
"""
import argparse
import sys
import time
from pathlib import Path
import warnings

import numpy as np

import snede

sys.path.insert(0, str(Path(__file__).resolve().parent))

PRECONDITIONERS = ("none", "jacobi", "gamg", "mg")


def sheet(n: int, taut: bool) -> snede.Body:
    flat = snede.meshing.rectangle((1.0, 1.0), (n, n))
    mesh = snede.Mesh(np.c_[flat.points, np.zeros(flat.n_points)], flat.cells)
    body = snede.Body(mesh, snede.NeoHookean(1e5, 0.3), thickness=0.001)
    rim = np.unique(mesh.boundary_faces())
    stretch = 0.1 * (mesh.points - [0.5, 0.5, 0.0])
    stretch[:, 2] = 0
    body.fix(rim, stretch[rim])
    if taut:
        body.displacement = stretch  # every element stretched by 10 % before the load
    body.add_nodal_force(np.setdiff1d(np.arange(mesh.n_points), rim), (0.0, 0.0, -1e-3))
    return body


def hanging_skin(n: int) -> snede.Body:
    surface, _ = snede.meshing.boundary_surface(snede.meshing.box((0.4, 0.1, 0.1), (4 * n, n, n)))
    body = snede.Body(surface, snede.NeoHookean(1e5, 0.3), thickness=0.001, density=1000.0)
    body.fix(np.isclose(surface.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


def organ_skin(source: str) -> snede.Body:
    """The closed skin of docs/results/membranes_on_organs.md: E = 5 kPa, ν = 0.45, held along
    the top tenth of its height under gravity."""
    from organ_meshes import organ_mesh

    volume = snede.meshing.ellipsoid(h=0.01) if source == "ellipsoid" else organ_mesh("liver", int(source))
    surface, _ = snede.meshing.boundary_surface(volume)
    body = snede.Body(surface, snede.NeoHookean(5e3, 0.45), thickness=0.001, density=1000.0)
    z = surface.points[:, 2]
    body.fix(z >= z.max() - 0.1 * np.ptp(z))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="the smaller sizes only")
    args = parser.parse_args()
    sizes = (8, 16) if args.quick else (8, 16, 32)
    scenes = [("taut sheet", lambda n: sheet(n, taut=True), sizes), ("slack sheet", lambda n: sheet(n, taut=False), sizes),
              ("hanging skin", hanging_skin, (2, 4) if args.quick else (2, 4, 6)),
              ("organ skin", organ_skin, ("ellipsoid", "1500") if args.quick else ("ellipsoid", "1500", "6000"))]
    warnings.simplefilter("ignore", snede.LockingWarning)
    print(f"{'scene':>13} {'triangles':>9} {'pc':>7} | {'reason':>22} {'Newton':>6} {'CG':>6} {'seconds':>8} "
          f"{'none/pc':>7} | {'min u_z [m]':>11}")
    print("-" * 104)
    for name, make, sizes in scenes:
        for n in sizes:
            plain = None
            for pc in PRECONDITIONERS:
                body = make(n)
                solver = snede.StaticSolver(body, "newton", rtol=1e-6, preconditioner=pc, max_iterations=5000)
                start = time.perf_counter()
                result = solver.solve()
                seconds = time.perf_counter() - start
                if pc == "none":
                    plain = seconds
                print(f"{name:>13} {body.mesh.n_cells:>9} {pc:>7} | {result.reason:>22} {result.iterations:>6} "
                      f"{result.linear_iterations:>6} {seconds:>8.2f} {plain / seconds:>7.2f} | "
                      f"{body.displacement[:, 2].min():>11.4f}", flush=True)
        print()


if __name__ == "__main__":
    main()
