"""3D needle insertion rates (issue 17) beside the thesis's Figure 6.14 (§6.9), in one run.

The thesis's cube: 10 cm, fixed at the bottom, E = 34 kPa, ν = 0.34; a needle of radius 1 mm
enters from the left at mid-height and goes 70 mm in, with the Figure 6.4 stand-in friction
profile (per unit of shaft surface, N/m²) and static friction twice the dynamic. The start mesh
is the 2 × 2 × 2 Kuhn box bisected 3 times (384 tetrahedra, edges 25 mm); the needle refines
along its shaft (within r of the axis) and around its tip to h_ref. Each update moves the needle
by h_ref / 2 and relaxes until no needle node changes between stick and slip (rtol 1e-3, (6.9)).

Printed per case: the final element count, updates, solves (rearrangements), the update rate
(solves per second, as the thesis's Table 6.5 counts them), CG iterations per solve, seconds, and
the tip-region deflection. The thesis: linear, 2420 elements, 5 s; neo-Hookean, 29 562 elements,
1364 s (Pentium III, 1 GHz).

    .venv/bin/python benchmarks/needle3d_rates.py                 # about 2 minutes
    .venv/bin/python benchmarks/needle3d_rates.py --deflection    # linear against neo-Hookean, about 2 minutes
    .venv/bin/python benchmarks/needle3d_rates.py --thesis-size   # near 29 562 elements, one solve per update, about 70 s

Not a test: times depend on the machine and its load; compare the ratios of one run.
"""
from __future__ import annotations

import time

import numpy as np

import snede
from snede.scenes import needle3d

SIZE, DEPTH, RADIUS = 0.1, 0.07, 1e-3
ENTRY, DIRECTION = (-0.005, 0.05, 0.05), (1.0, 0.0, 0.0)


def cube(material, start: int = 2, levels: int = 3):
    """The cube: the start × start × start Kuhn box bisected `levels` times, fixed at the bottom."""
    mesh = snede.meshing.box((SIZE, SIZE, SIZE), (start, start, start))
    mesh.refine_uniform(levels)
    body = snede.Body(mesh, material)
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    return body


def insert(material, h_ref: float, preconditioner: str, solves_per_update: int | None = None, entry=ENTRY,
           friction_scale: float = 1.0, start: int = 2, levels: int = 3, inexact: bool = False):
    body = cube(material, start, levels)
    method = "cg" if isinstance(material, snede.LinearElastic) else "newton"
    options = {"pc_type": preconditioner, **({"snes_ksp_ew": None} if inexact and method == "newton" else {})}
    needle = snede.NeedleInsertion(body, entry, DIRECTION, snede.FrictionProfile.figure_6_4(friction_scale), radius=RADIUS,
                                   h_ref=h_ref, method=method, rtol=1e-3, solves_per_update=solves_per_update,
                                   petsc_options=options)
    start = time.perf_counter()
    report = needle.insert(DEPTH, 0.5 * h_ref)
    seconds = time.perf_counter() - start
    tip = np.linalg.norm(body.mesh.points + body.displacement - needle.tip, axis=1) < 2 * h_ref
    deflection = float(np.abs(body.displacement[tip, 2]).max()) if tip.any() else float("nan")
    return body, needle, report, seconds, deflection


def deflection_table() -> None:
    """Linear against neo-Hookean under the profile scaled by 100: the 2D sheet's force per
    length spread over its 1 cm thickness, a force per area (about 100 s)."""
    print("\nLinear against neo-Hookean, profile × 100 (N/m²), h_ref 0.1 m/48, the scene's entry:")
    for name, material in (("linear", snede.LinearElastic(34e3, 0.34)), ("neo-Hookean", snede.NeoHookean(34e3, 0.34))):
        body, needle, report, seconds, _ = insert(material, SIZE / 48, "mg", entry=needle3d.ENTRY, friction_scale=100.0)
        x = body.mesh.points + body.displacement
        tip = np.linalg.norm(x - needle.tip, axis=1) < 0.004
        print(f"   {name:<12} {body.mesh.n_cells} tetrahedra, {report.rearrangements} solves, {seconds:.1f} s; "
              f"max |u| {np.abs(body.displacement).max() * 1e3:.4f} mm, mean u_x within 4 mm of the tip "
              f"{body.displacement[tip, 0].mean() * 1e3:.4f} mm", flush=True)


def thesis_size_table() -> None:
    """Near the thesis's 29 562 neo-Hookean elements: the 3 × 3 × 3 box bisected twice as the
    start mesh, one solve per update (the haptic loop), mg, Newton exact and inexact
    (Eisenstat–Walker); the linear material at the larger size for the update rate (about 70 s)."""
    print("\nNear the thesis's element count: start 3 × 3 × 3 bisected twice, one solve per update, mg:")
    neo_hookean, linear = snede.NeoHookean(34e3, 0.34), snede.LinearElastic(34e3, 0.34)
    for material, divisions, inexact in ((neo_hookean, 64, False), (neo_hookean, 64, True), (neo_hookean, 72, False),
                                         (neo_hookean, 72, True), (linear, 72, False)):
        body, needle, report, seconds, _ = insert(material, SIZE / divisions, "mg", 1, entry=needle3d.ENTRY, start=3,
                                                  levels=2, inexact=inexact)
        newton = {False: ", exact Newton", True: ", inexact Newton (snes_ksp_ew)"}[inexact] if material is neo_hookean else ""
        print(f"   {type(material).__name__}{newton}, h_ref 0.1 m/{divisions}: {body.mesh.n_cells} tetrahedra, {report}; "
              f"{seconds:.2f} s, {report.updates / seconds:.1f} updates/s", flush=True)


def main() -> None:
    import sys

    if "--deflection" in sys.argv[1:]:
        deflection_table()
        return
    if "--thesis-size" in sys.argv[1:]:
        thesis_size_table()
        return
    print(__doc__.splitlines()[0])
    print(f"{'material':<12} {'h_ref [mm]':>10} {'pc':<5} {'elements':>9} {'updates':>8} {'solves':>7} "
          f"{'solves/s':>9} {'CG/solve':>9} {'seconds':>8} {'|u_z| near tip [mm]':>20}  result")
    deflections = {}
    for name, material in (("linear", snede.LinearElastic(34e3, 0.34)), ("neo-Hookean", snede.NeoHookean(34e3, 0.34))):
        for h_ref in (0.005, 0.0035, 0.0025):
            for pc in ("none", "mg"):
                body, needle, report, seconds, deflection = insert(material, h_ref, pc)
                deflections[(name, h_ref, pc)] = deflection
                print(f"{name:<12} {h_ref * 1e3:>10.2f} {pc:<5} {body.mesh.n_cells:>9} {report.updates:>8} "
                      f"{report.rearrangements:>7} {report.update_rate:>9.1f} {report.mean_iterations:>9.1f} "
                      f"{seconds:>8.2f} {deflection * 1e3:>20.4f}  "
                      f"{'converged' if report.converged else report.reason}", flush=True)
    for h_ref in (0.005, 0.0035, 0.0025):
        linear, neo = deflections[("linear", h_ref, "mg")], deflections[("neo-Hookean", h_ref, "mg")]
        print(f"   h_ref {h_ref * 1e3:.2f} mm: tip-region deflection linear {linear * 1e3:.4f} mm, neo-Hookean "
              f"{neo * 1e3:.4f} mm (difference {(neo - linear) * 1e3:+.4f} mm)")
    print("   thesis (P3 1 GHz): linear 2420 elements 5 s; neo-Hookean 29 562 elements 1364 s")
    print("\nThe thesis's haptic loop (one solve per update, pending rearrangements carried over), neo-Hookean, mg,")
    print("the needle scene's entry off the grid lines:")
    for divisions in (64, 80):
        body, needle, report, seconds, _ = insert(snede.NeoHookean(34e3, 0.34), SIZE / divisions, "mg", 1,
                                                  entry=needle3d.ENTRY)
        print(f"   h_ref 0.1 m/{divisions}: {body.mesh.n_cells} tetrahedra, {report}; {seconds:.2f} s", flush=True)


if __name__ == "__main__":
    main()
