"""Benchmark: volumetric locking and the smoothed formulation (issue 35), error against time.

    .venv/bin/python studies/benchmarks/locking.py           # about 3 minutes
    .venv/bin/python studies/benchmarks/locking.py --quick   # the smallest meshes only (about 20 s)

Three tables, for "p1" (the thesis's constant-strain tetrahedron) and "smoothed" (shear part
on edge patches, bulk part on vertex patches; snede.formulations()):

1. Cantilever 1 × 0.1 × 0.1 m, linear elastic, E = 1 MPa, clamped at x = 0, 1 N in −z on the
   end face lumped by area; the mean u_z over the end face against quadratic tetrahedra in
   FEniCSx on 80 × 8 × 8 boxes (140 k dofs; studies/benchmarks/locking_reference_fenicsx.py), at
   ν = 0.3, 0.45, 0.49, 0.499, on Kuhn boxes of 3 840, 24 576 and 30 720 tetrahedra.
2. Hollow sphere (radii 0.5 and 1 m) under an internal pressure of 1 kPa, linear elastic,
   E = 1 MPa, meshed by gmsh: the mean radial displacement of the inner and the outer
   surface against Lamé's solution u_r = p a³ / (E (b³ − a³)) ((1 − 2ν) r + (1 + ν) b³ / (2 r²)).
   The outer surface's vertices within 10° of the six half-axes are held at the exact
   displacement.
3. Cost on one mesh (the 24 576-tetrahedron cantilever, neo-Hookean ν = 0.49): milliseconds per
   tangent product, force evaluation and assembled tangent, and per Newton step of the
   cantilever's solve with mg; the smoothed/p1 ratio (goal of issue 35: ≤ 2 per Newton step).

Every solve is Newton with preconditioner "mg", rtol 1e-8, and must converge. Times are one
core's; compare rows of one run (the machine is shared).
"""
import argparse
import time
import warnings

import numpy as np

import snede

FORMULATIONS = ("p1", "smoothed")
POISSON = (0.3, 0.45, 0.49, 0.499)
YOUNG = 1e6
# Mean u_z (m) on the end face from FEniCSx P2, 80 × 8 × 8 boxes, 140 k dofs, MUMPS (the issue's
# 452 k dofs gave −4.002e-2 at ν = 0.3 and −3.952e-2 at 0.49: within 0.13 % of these):
# /usr/bin/python3 studies/benchmarks/locking_reference_fenicsx.py --divisions 80
CANTILEVER_REFERENCE = {0.3: -4.00216e-02, 0.45: -3.96390e-02, 0.49: -3.94692e-02, 0.499: -3.93960e-02}
CANTILEVER_MESHES = ((40, 4, 4), (64, 8, 8), (80, 8, 8))
SPHERE_SIZES = (0.2, 0.12, 0.08)
INNER, OUTER, PRESSURE = 0.5, 1.0, 1e3


def solve(body) -> tuple[float, object]:
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner="mg")
    start = time.perf_counter()
    result = solver.solve()
    seconds = time.perf_counter() - start
    if not result.converged:
        raise RuntimeError(f"a solve did not converge: {result.reason}")
    return seconds, result


def cantilever(divisions, poisson: float, formulation: str, material=None):
    mesh = snede.meshing.box((1.0, 0.1, 0.1), divisions)
    body = snede.Body(mesh, material or snede.LinearElastic(YOUNG, poisson), formulation=formulation)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    end = mesh.faces_where(lambda x: np.isclose(x[:, 0], 1.0), interior=False)
    corners = mesh.points[end]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    load = np.zeros((mesh.n_points, 3))
    np.add.at(load[:, 2], end.ravel(), -np.repeat(area / 3 / area.sum(), 3))
    body.add_nodal_force(np.arange(mesh.n_points), load)
    return body, np.unique(end)


def lame_sphere(r: np.ndarray, poisson: float) -> np.ndarray:
    return PRESSURE * INNER**3 / (YOUNG * (OUTER**3 - INNER**3)) * (
        (1 - 2 * poisson) * r + (1 + poisson) * OUTER**3 / (2 * r**2))


def sphere(mesh, poisson: float, formulation: str):
    body = snede.Body(mesh, snede.LinearElastic(YOUNG, poisson), formulation=formulation)
    faces = mesh.boundary_faces()
    corners = mesh.points[faces]
    radius = np.linalg.norm(corners.mean(axis=1), axis=1)
    inner = faces[radius < 0.5 * (INNER + OUTER)]
    c = mesh.points[inner]
    normal = 0.5 * np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])  # area × unit normal
    normal *= np.sign(np.einsum("ij,ij->i", normal, c.mean(axis=1)))[:, None]  # away from the centre
    load = np.zeros((mesh.n_points, 3))
    for k in range(3):
        np.add.at(load, inner[:, k], PRESSURE * normal / 3)
    body.add_nodal_force(np.arange(mesh.n_points), load)
    # The outer surface's vertices within 10° of the six half-axes are held at the exact
    # displacement (radial, so the rigid motions are removed without a reaction the exact
    # solution does not have).
    r = np.linalg.norm(mesh.points, axis=1)
    caps = (r > OUTER - 1e-9) & (np.abs(mesh.points).max(axis=1) > np.cos(np.radians(10)) * r)
    body.fix(caps, lame_sphere(r[caps], poisson)[:, None] * mesh.points[caps] / r[caps, None])
    return body, np.unique(inner), np.unique(faces[radius >= 0.5 * (INNER + OUTER)])


def radial(body, vertices) -> float:
    x = body.mesh.points[vertices]
    return float(np.mean(np.einsum("ij,ij->i", body.displacement[vertices], x) / np.linalg.norm(x, axis=1)))


def cantilever_table(meshes) -> None:
    print("\n## Cantilever (mean tip u_z against FEniCSx P2, 140 k dofs)\n")
    print("| tetrahedra | ν | formulation | tip u_z (m) | error | Newton | CG | solve s |")
    print("|---|---|---|---|---|---|---|---|")
    for poisson in POISSON:
        for divisions in meshes:
            for formulation in FORMULATIONS:
                body, end = cantilever(divisions, poisson, formulation)
                seconds, result = solve(body)
                tip = body.displacement[end, 2].mean()
                error = 100 * (tip / CANTILEVER_REFERENCE[poisson] - 1)
                print(f"| {body.mesh.n_cells} | {poisson} | {formulation} | {tip:.5e} | {error:+.1f} % | "
                      f"{result.iterations} | {result.linear_iterations} | {seconds:.2f} |", flush=True)


def sphere_table(sizes) -> None:
    print("\n## Hollow sphere under internal pressure (mean radial displacement against Lamé's solution)\n")
    print("| tetrahedra | ν | formulation | inner u_r error | outer u_r error | Newton | CG | solve s |")
    print("|---|---|---|---|---|---|---|---|")
    meshes = {h: snede.meshing.hollow_sphere(INNER, OUTER, h, seed=1) for h in sizes}
    for poisson in POISSON:
        for h, mesh in meshes.items():
            for formulation in FORMULATIONS:
                body, inner, outer = sphere(mesh, poisson, formulation)
                seconds, result = solve(body)
                errors = [100 * (radial(body, vertices) / np.mean(lame_sphere(np.linalg.norm(mesh.points[vertices], axis=1), poisson)) - 1)
                          for vertices in (inner, outer)]
                print(f"| {mesh.n_cells} | {poisson} | {formulation} | {errors[0]:+.1f} % | {errors[1]:+.1f} % | "
                      f"{result.iterations} | {result.linear_iterations} | {seconds:.2f} |", flush=True)


def best_of(function, repeats: int) -> float:
    function()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return 1e3 * min(times)


def cost_table(divisions) -> None:
    print(f"\n## Cost on one mesh (cantilever {divisions}, neo-Hookean ν = 0.49; ms, best of several)\n")
    print("| formulation | tangent product | forces | assembled tangent (aij) | Newton step (mg) | Newton, CG its |")
    print("|---|---|---|---|---|---|")
    rows = {}
    for formulation in FORMULATIONS:
        body, _ = cantilever(divisions, 0.49, formulation, snede.NeoHookean(YOUNG, 0.49))
        u = 1e-3 * np.random.default_rng(0).standard_normal((body.mesh.n_points, 3))
        product = best_of(lambda: body.tangent_apply(u, u), 20)
        forces = best_of(lambda: body.internal_forces(u), 20)
        assembly = best_of(lambda: body.assemble_tangent(u, "aij"), 3)
        seconds, result = solve(body)
        step = 1e3 * seconds / result.iterations
        rows[formulation] = (product, forces, assembly, step)
        print(f"| {formulation} | {product:.2f} | {forces:.2f} | {assembly:.1f} | {step:.0f} | "
              f"{result.iterations}, {result.linear_iterations} |", flush=True)
    ratio = [s / p for s, p in zip(rows["smoothed"], rows["p1"])]
    print(f"| smoothed / p1 | {ratio[0]:.1f}× | {ratio[1]:.1f}× | {ratio[2]:.1f}× | {ratio[3]:.1f}× | |")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="the smallest meshes only")
    args = parser.parse_args()
    warnings.simplefilter("ignore", snede.LockingWarning)  # the p1 rows lock on purpose
    cantilever_table(CANTILEVER_MESHES[:1] if args.quick else CANTILEVER_MESHES)
    sphere_table(SPHERE_SIZES[:1] if args.quick else SPHERE_SIZES)
    cost_table(CANTILEVER_MESHES[0] if args.quick else CANTILEVER_MESHES[1])
