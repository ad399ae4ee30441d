"""Benchmark: every static solver on the Table 4.2 cylinder under gravity (Table 4.1).

    .venv/bin/python studies/benchmarks/cylinder_solvers.py [--mesh meshes/cylinder_small.msh]
        [--material neohookean] [--rtol 1e-3] [PETSc options]

Neo-Hookean (E = 1e4 Pa, ν = 0.3, ρ = 1000 kg/m³, g = 9.8 m/s², γ = 8 for
Veronda-Westmann), fixed at x = 0. Each solver starts from rest and stops at
‖r‖ ≤ rtol‖f_ext‖ (criterion (6.8), as in chapter 4). Prints iterations, seconds, MFLOP,
PETSc's reason and the tip deflection; a reference from truncated Newton at rtol 1e-10
gives each solution's relative error.
"""
import argparse
from pathlib import Path

import numpy as np

import snede

MESHES = Path(__file__).resolve().parents[2] / "meshes"
MATERIALS = {
    "linear": lambda: snede.LinearElastic(1e4, 0.3),
    "stvk": lambda: snede.StVenantKirchhoff(1e4, 0.3),
    "neohookean": lambda: snede.NeoHookean(1e4, 0.3),
    "veronda": lambda: snede.VerondaWestmann(1e4, 0.3, 8.0),
}


def cylinder_body(mesh_path, material):
    mesh = snede.Mesh.read(mesh_path)
    body = snede.Body(mesh, MATERIALS[material](), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], mesh.points[:, 0].min()))
    body.add_gravity((0.0, 0.0, -9.8))
    return body


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mesh", type=Path, default=MESHES / "cylinder_small.msh")
    parser.add_argument("--material", choices=sorted(MATERIALS), default="neohookean")
    parser.add_argument("--rtol", type=float, default=1e-3)
    args, _ = parser.parse_known_args()

    reference = cylinder_body(args.mesh, args.material)
    snede.StaticSolver(reference, "newton", rtol=1e-10, criterion="6.8", options_prefix="reference_").solve()
    u_ref = reference.displacement
    tip = np.argmax(reference.mesh.points[:, 0])
    print(f"{args.mesh.name}: {reference.mesh.n_cells} tetrahedra, {reference.mesh.n_points} nodes, {args.material}; "
          f"reference tip deflection {u_ref[tip, 2]:.5f} m\n")
    # The thesis's solvers are unpreconditioned (§4.4); "newton mg" is snede's default for the mesh.
    runs = [("newton", dict(method="newton", preconditioner="none")),
            ("newton mg", dict(method="newton", preconditioner="mg")),
            ("ncg PRP secant", dict(method="ncg", line_search="snede_secant", ncg_type="prp")),
            ("ncg FR secant", dict(method="ncg", line_search="snede_secant", ncg_type="fr")),
            ("ncg PRP newton-ls", dict(method="ncg", line_search="snede_newton", ncg_type="prp"))]
    if args.material == "linear":
        runs.insert(0, ("linear cg", dict(method="cg", preconditioner="none")))
    print(f"{'solver':<20} {'iterations':>10} {'linear':>7} {'seconds':>8} {'MFLOP':>8} {'error %':>8}  reason")
    for name, settings in runs:
        body = cylinder_body(args.mesh, args.material)
        prefix = name.replace(" ", "_").replace("-", "_") + "_"
        result = snede.StaticSolver(body, rtol=args.rtol, criterion="6.8", max_iterations=100000,
                                    options_prefix=prefix, **settings).solve()
        error = np.linalg.norm(body.displacement - u_ref) / np.linalg.norm(u_ref)
        print(f"{name:<20} {result.iterations:>10} {result.linear_iterations:>7} {result.seconds:>8.3f} "
              f"{result.flops / 1e6:>8.1f} {100 * error:>8.3f}  {result.reason}", flush=True)
    if hasattr(snede, "DynamicRelaxation"):
        body = cylinder_body(args.mesh, args.material)
        dynamic = snede.DynamicRelaxation(body, damping=21.0)
        result = dynamic.run(rtol=args.rtol, max_steps=200000)
        error = np.linalg.norm(body.displacement - u_ref) / np.linalg.norm(u_ref)
        print(f"{'dynamic (eta=21)':<20} {result.iterations:>10} {0:>7} {result.seconds:>8.3f} "
              f"{result.flops / 1e6:>8.1f} {100 * error:>8.3f}  {result.reason}")


if __name__ == "__main__":
    main()
