"""Reference tip deflections for studies/benchmarks/locking.py's cantilever, from a peer code:
quadratic tetrahedra (P2) in FEniCSx on a fine mesh, linear elasticity. Run with the system
Python, which has Debian's python3-dolfinx (FEniCSx 0.5.2); not a test dependency.

    /usr/bin/python3 studies/benchmarks/locking_reference_fenicsx.py [--divisions 120]

The cantilever: 1 × 0.1 × 0.1 m, E = 1 MPa, clamped at x = 0, a uniform traction of total
1 N in −z on the face x = 1; prints the mean of u_z over that face for each Poisson's ratio.
With 120 × 12 × 12 boxes (6 tetrahedra each) the P2 space has 452 k degrees of freedom.
"""
import argparse
import time

import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.fem.petsc import LinearProblem
from mpi4py import MPI
from petsc4py import PETSc

LENGTH, SIDE, YOUNG, LOAD = 1.0, 0.1, 1e6, 1.0


def tip_deflection(divisions: int, poisson: float) -> tuple[float, int, float]:
    domain = mesh.create_box(MPI.COMM_WORLD, [np.zeros(3), np.array([LENGTH, SIDE, SIDE])],
                             [divisions, divisions // 10, divisions // 10], mesh.CellType.tetrahedron)
    V = fem.VectorFunctionSpace(domain, ("Lagrange", 2))
    mu = YOUNG / (2 * (1 + poisson))
    lam = YOUNG * poisson / ((1 + poisson) * (1 - 2 * poisson))
    clamped = mesh.locate_entities_boundary(domain, 2, lambda x: np.isclose(x[0], 0.0))
    bc = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), fem.locate_dofs_topological(V, 2, clamped), V)
    end = mesh.locate_entities_boundary(domain, 2, lambda x: np.isclose(x[0], LENGTH))
    tags = mesh.meshtags(domain, 2, end, np.full(len(end), 1, dtype=np.int32))
    ds = ufl.Measure("ds", domain=domain, subdomain_data=tags)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)

    def sigma(w):
        eps = ufl.sym(ufl.grad(w))
        return 2 * mu * eps + lam * ufl.tr(eps) * ufl.Identity(3)

    traction = fem.Constant(domain, PETSc.ScalarType((0.0, 0.0, -LOAD / SIDE**2)))
    problem = LinearProblem(ufl.inner(sigma(u), ufl.grad(v)) * ufl.dx, ufl.dot(traction, v) * ds(1), bcs=[bc],
                            petsc_options={"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"})
    start = time.perf_counter()
    uh = problem.solve()
    seconds = time.perf_counter() - start
    mean_uz = fem.assemble_scalar(fem.form(uh[2] * ds(1))) / SIDE**2
    return mean_uz, V.dofmap.index_map.size_global * 3, seconds


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--divisions", type=int, default=120)
    args = parser.parse_args()
    print("| ν | mean u_z on x = 1 (m) | dofs | solve s |")
    print("|---|---|---|---|")
    for poisson in (0.3, 0.45, 0.49, 0.499):
        tip, dofs, seconds = tip_deflection(args.divisions, poisson)
        print(f"| {poisson} | {tip:.5e} | {dofs} | {seconds:.1f} |", flush=True)
