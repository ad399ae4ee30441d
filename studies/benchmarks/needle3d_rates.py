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

    .venv/bin/python studies/benchmarks/needle3d_rates.py                 # about 2 minutes
    .venv/bin/python studies/benchmarks/needle3d_rates.py --deflection    # linear against neo-Hookean, about 2 minutes
    .venv/bin/python studies/benchmarks/needle3d_rates.py --thesis-size   # near 29 562 elements, one solve per update, about 70 s
    .venv/bin/python studies/benchmarks/needle3d_rates.py --haptic        # the haptic loop on the cube and on gmsh organs, WU per update, about 5 minutes
    .venv/bin/python studies/benchmarks/needle3d_rates.py --refinement    # cells the shaft's refinement adds to gmsh organs, about 1 minute

Not a test: times depend on the machine and its load; compare the ratios of one run.
"""
from __future__ import annotations

import math
import time

import numpy as np

import snede

SIZE, DEPTH, RADIUS = 0.1, 0.07, 1e-3
ENTRY, DIRECTION = (-0.005, 0.05, 0.05), (1.0, 0.0, 0.0)
OFF_GRID_ENTRY = (-0.005, 0.0513, 0.0489)  # off the Kuhn boxes' vertex planes, as the needle3d scene's


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
        body, needle, report, seconds, _ = insert(material, SIZE / 48, "mg", entry=OFF_GRID_ENTRY, friction_scale=100.0)
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
        body, needle, report, seconds, _ = insert(material, SIZE / divisions, "mg", 1, entry=OFF_GRID_ENTRY, start=3,
                                                  levels=2, inexact=inexact)
        newton = {False: ", exact Newton", True: ", inexact Newton (snes_ksp_ew)"}[inexact] if material is neo_hookean else ""
        print(f"   {type(material).__name__}{newton}, h_ref 0.1 m/{divisions}: {body.mesh.n_cells} tetrahedra, {report}; "
              f"{seconds:.2f} s, {report.updates / seconds:.1f} updates/s", flush=True)


ORGAN_BODIES = ("liver 10k", "liver 20k", "liver2 20k", "heart 10k", "heart 20k")  #: gmsh-filled public surfaces (organ_meshes.py)


def organ(name: str, material):
    """A gmsh organ (studies/benchmarks/organ_meshes.py) named like "liver 10k": about 10 000
    tetrahedra, no bisection history, held at its top tenth, and a needle line entering it from
    the left 1 cm before its outline at mid-height (off its vertices)."""
    from organ_meshes import organ_mesh

    surface, size = name.split()
    mesh = organ_mesh(surface, int(size[:-1]) * 1000)
    body = snede.Body(mesh, material)
    z = mesh.points[:, 2]
    body.fix(z >= z.max() - 0.1 * np.ptp(z))
    low, high = mesh.points.min(axis=0), mesh.points.max(axis=0)
    middle = 0.5 * (low + high)
    return body, (low[0] - 0.01, middle[1] + 1.3e-3, middle[2] - 0.7e-3)


def haptic_loop(body, entry, h_ref: float, step: float, depth: float, extrapolate: bool, options: dict):
    """One solve per update (§6.7) from the body's surface `depth` into it, `step` per update;
    the rate is updates per second of the insertion (the jump to the surface excluded)."""
    method = "cg" if isinstance(body.material, snede.LinearElastic) else "newton"
    needle = snede.NeedleInsertion(body, entry, DIRECTION, snede.FrictionProfile.figure_6_4(), radius=RADIUS,
                                   h_ref=h_ref, method=method, rtol=1e-3, solves_per_update=1,
                                   extrapolate=extrapolate, petsc_options=options)
    needle.advance(needle.surface_depth)
    start = time.perf_counter()
    report = needle.insert(needle.depth + depth, step)
    seconds = time.perf_counter() - start
    return needle, report, seconds


def tube_cells(depth: float, h_ref: float) -> float:
    """Cells of a tube of radius h_ref around `depth` of shaft filled with regular tetrahedra of
    edge h_ref (volume h³ / (6√2)): what the shaft's refinement cannot do with fewer of."""
    return math.pi * h_ref ** 2 * depth / (h_ref ** 3 / (6 * math.sqrt(2)))


def haptic_table() -> None:
    """Issue 50's goals: the haptic loop (one solve per update, §6.7) 30 mm into gmsh organs of 10k
    and 20k tetrahedra at h_ref 2.5 mm: ≤ 60 WU per update neo-Hookean, ≤ 1.2 solves per update,
    the mesh ≤ 1.3× its starting cells. WU: one product of the assembled AIJ tangent of the mesh at
    the end of the insertion, timed in this process (work_units.py). The cube (issue 33) beside."""
    import warnings

    from work_units import work_unit_seconds

    warnings.simplefilter("ignore")  # the organs' ν = 0.45 locking warning
    print("\nThe haptic loop (one solve per update, rtol 1e-3), r = 1 mm, Figure 6.4 stand-in profile;")
    print("cube: E = 34 kPa, ν = 0.34, h_ref 0.1 m/64, 0.5 h_ref per update, 60 mm; organs (gmsh, no bisection")
    print("history): E = 5 kPa, ν = 0.45, h_ref 2.5 mm, 1 mm per update, 30 mm from the surface:")
    print(f"{'body':<14} {'material':<12} {'predictor':<9} {'tets start':>10} {'end':>7} {'ratio':>5} {'updates':>7} "
          f"{'solves':>6} {'/update':>7} {'CG/solve':>8} {'s':>6} {'Hz':>6} {'WU ms':>6} {'WU/update':>9}  goals")
    for body_name in ("cube 0.1 m/64",) + ORGAN_BODIES:
        for material_name, extrapolate in (("neo-Hookean", False), ("neo-Hookean", True), ("linear", False)):
            model = snede.NeoHookean if material_name == "neo-Hookean" else snede.LinearElastic
            if body_name.startswith("cube"):
                body, entry = cube(model(34e3, 0.34), 3, 2), OFF_GRID_ENTRY
                h_ref, step, depth = SIZE / 64, 0.5 * SIZE / 64, 0.06
            else:
                body, entry = organ(body_name, model(5e3, 0.45))
                h_ref, step, depth = 2.5e-3, 1e-3, 0.03
            cells = body.mesh.n_cells
            needle, report, seconds = haptic_loop(body, entry, h_ref, step, depth, extrapolate, {})
            work_unit = work_unit_seconds(body)
            per_update = seconds / report.updates / work_unit
            print(f"{body_name:<14} {material_name:<12} {str(extrapolate):<9} {cells:>10} {body.mesh.n_cells:>7} "
                  f"{body.mesh.n_cells / cells:>5.2f} {report.updates:>7} {report.rearrangements:>6} "
                  f"{report.rearrangements / report.updates:>7.2f} {report.mean_iterations:>8.1f} {seconds:>6.1f} "
                  f"{report.updates / seconds:>6.1f} {1e3 * work_unit:>6.2f} {per_update:>9.0f}  "
                  + ("≤ 60 WU, ≤ 1.2 solves, ≤ 1.3×" if material_name == "neo-Hookean" and "cube" not in body_name else "")
                  + ("" if report.converged else f"  {report.reason}"), flush=True)


def refinement_table() -> None:
    """Issue 50, item 1: cells a needle's refinement adds along 30 mm of shaft into gmsh organs
    (h_ref 2.5 mm, r = 1 mm, 1 mm per update, linear material: the refinement does not depend on
    it), against the cells of a tube of radius h_ref (tube_cells)."""
    import warnings

    warnings.simplefilter("ignore")
    print("\nCells the shaft's refinement adds, 30 mm into gmsh organs, h_ref 2.5 mm, r = 1 mm:")
    print(f"{'body':<14} {'rule':<13} {'tets start':>10} {'end':>7} {'ratio':>5} {'added':>6} {'per mm':>6} "
          f"{'tube':>5} {'added/tube':>10}  goal")
    for body_name in ORGAN_BODIES:
        body, entry = organ(body_name, snede.LinearElastic(5e3, 0.45))
        cells = body.mesh.n_cells
        haptic_loop(body, entry, 2.5e-3, 1e-3, 0.03, False, {})
        added = body.mesh.n_cells - cells
        print(f"{body_name:<14} {body.mesh._bisection().rule:<13} {cells:>10} {body.mesh.n_cells:>7} "
              f"{body.mesh.n_cells / cells:>5.2f} {added:>6} {added / 30:>6.0f} {tube_cells(0.03, 2.5e-3):>5.0f} "
              f"{added / tube_cells(0.03, 2.5e-3):>10.1f}  ≤ 1.3×", flush=True)


def main() -> None:
    import sys

    if "--deflection" in sys.argv[1:]:
        deflection_table()
        return
    if "--haptic" in sys.argv[1:]:
        haptic_table()
        return
    if "--refinement" in sys.argv[1:]:
        refinement_table()
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
                                                  entry=OFF_GRID_ENTRY)
        print(f"   h_ref 0.1 m/{divisions}: {body.mesh.n_cells} tetrahedra, {report}; {seconds:.2f} s", flush=True)


if __name__ == "__main__":
    main()
