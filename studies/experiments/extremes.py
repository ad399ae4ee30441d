"""Numerical behaviour at the extremes: ν up to 0.499 (locking), E from 1e2 to 1e9 Pa,
Veronda-Westmann γ up to 50, elements of aspect ratio down to 1e-4, dynamic time steps from
0.5 to 1.5 × critical, and loads that invert St. Venant-Kirchhoff. Every run ends converged
or with a named reason (SolveResult.reason, or the exception's class and message).

    .venv/bin/python -m studies.experiments.extremes [--quick] [--out DIR]

Writes extremes.md and extremes.csv into docs/results/. Where P1 tetrahedra lock it also
warns at run time with the measured stiffening (snede.LockingWarning; the library itself
already warns when such a body is built).
"""
from __future__ import annotations

import time
import warnings

import numpy as np

import snede
from studies.experiments.cantilever import (DEPTH, HEIGHT, LENGTH, YOUNG, cantilever_body, timoshenko_deflection,
                                            tip_deflections)
from studies.experiments.common import (Column, PageTemplate, markdown_table, options_prefix, parse_arguments, run_solve,
                                        write_csv)
from studies.experiments.tradeoff import MESHES, critical_damping_estimate, cylinder_body, tip_sag

LOCKING_RATIO = 0.9  # below this fraction of beam theory's deflection, call the mesh locked
EULER_BUCKLING_STRESS = np.pi**2 / 48  # × E: a cube as a column clamped at its base, π²EI/(4L²) over its area
TABLE_4_4_DAMPING = {"NeoHookean": 21.0, "VerondaWestmann": 27.0}  # η (1/s) for the small cylinder


def static(body, method: str, label: str, rtol: float = 1e-8, criterion: str = "6.9", max_iterations: int = 20000,
           petsc_options=None):
    return run_solve(lambda: snede.StaticSolver(body, method, preconditioner="none", rtol=rtol, criterion=criterion,
                                                max_iterations=max_iterations, options_prefix=options_prefix(label),
                                                petsc_options=petsc_options).solve())


def dynamic(body, damping: float, label: str, dt: float | None = None, rtol: float = 1e-4, max_steps: int = 50000):
    return run_solve(lambda: snede.DynamicRelaxation(body, damping=damping, dt=dt,
                                                     options_prefix=options_prefix(label)).run(rtol, max_steps))


def row(case: str, setting: str, material: str, solver: str, outcome, quantity: str, value: float,
        reference: float | None = None, note: str = "", **extra) -> dict:
    value = float(value) + 0.0  # no "-0"
    ratio = value / reference if reference not in (None, 0) and np.isfinite(value) else None
    return {"case": case, "setting": setting, "material": material, "solver": solver,
            "converged": outcome.converged, "reason": outcome.reason, "seconds": outcome.seconds,
            "iterations": outcome.iterations, "linear_iterations": outcome.linear_iterations,
            "quantity": quantity, "value": value, "reference": reference, "ratio": ratio, "note": note, **extra}


def locking_rows(sizes, ratios_nu) -> list[dict]:
    """ν → ½ on the cantilever. Beam theory barely depends on ν (only the shear term, through
    G), so the reference is the ν = 0 deflection on the same mesh scaled by Timoshenko's
    ratio: it cancels the discretization error ν does not cause."""
    rows = []
    for n in sizes:
        base = None
        for material_name, make, method in (("LinearElastic", snede.LinearElastic, "cg"),
                                            ("NeoHookean", snede.NeoHookean, "newton")):
            for nu in ratios_nu:
                if material_name == "NeoHookean" and nu < max(ratios_nu):
                    continue  # one nonlinear row per mesh: locking is a property of the element
                body, tip = cantilever_body(n, make(YOUNG, nu))
                outcome = static(body, method, f"nu_{n}")
                value = float(tip_deflections(body, tip).mean())
                if base is None:
                    base = value
                reference = base * timoshenko_deflection(poisson=nu) / timoshenko_deflection(poisson=0.0)
                fraction = value / reference
                note = ""
                if fraction < LOCKING_RATIO:
                    note = f"locks: {fraction:.0%} of beam theory"
                    warnings.warn(f"P1 tetrahedra lock at ν = {nu} ({material_name}, "
                                  f"{n}×{n // 4}×{n // 4} cantilever): "
                                  f"the tip deflects {fraction:.0%} of what beam theory predicts on this mesh; results "
                                  "for nearly incompressible material on linear tetrahedra are far too stiff",
                                  snede.LockingWarning, stacklevel=2)
                rows.append(row("ν → ½ (locking)", f"ν = {nu}, {n}×{n // 4}×{n // 4}", material_name, method, outcome,
                                "tip deflection [m]", value, reference, note, poisson=nu))
    return rows


def young_rows(n: int, moduli, cylinder_mesh) -> list[dict]:
    """E from 1e2 to 1e9 Pa: the cantilever with the load scaled by E (same strains: the
    deflection must not change), and the cylinder under its own weight (from barely moving
    to hanging like a rope)."""
    rows = []
    for material_name, make, method in (("LinearElastic", snede.LinearElastic, "cg"),
                                        ("NeoHookean", snede.NeoHookean, "newton")):
        reference = None
        for young in sorted(moduli, key=lambda e: e != YOUNG):  # E = 1e6 first: the reference
            body, tip = cantilever_body(n, make(young, 0.3), load=3.0 * young / YOUNG)
            outcome = static(body, method, f"young_{n}")
            value = float(tip_deflections(body, tip).mean())
            reference = reference or value
            rows.append(row("E (cantilever, load ∝ E)", f"E = {young:g} Pa, F = {3.0 * young / YOUNG:g} N",
                            material_name, method, outcome, "tip deflection [m] (reference: E = 1e6)", value,
                            reference, f"relative change {abs(value / reference - 1):.1e}"))
    for young in moduli:
        linear, tip = cylinder_body(cylinder_mesh, snede.LinearElastic(young, 0.3))
        static(linear, "cg", "young_cylinder_linear")
        linear_sag = tip_sag(linear, tip)
        for method in ("newton", "ncg"):
            body, _ = cylinder_body(cylinder_mesh, snede.NeoHookean(young, 0.3))
            outcome = static(body, method, f"young_cylinder_{method}", rtol=1e-6, max_iterations=5000)
            value = tip_sag(body, tip)
            rows.append(row("E (cylinder, gravity)", f"E = {young:g} Pa", "NeoHookean", method, outcome,
                            "tip sag [m] (reference: linear)", value, linear_sag,
                            f"sag = {value / 0.1:.2g} × length" if outcome.converged else ""))
    return rows


def veronda_rows(gammas, cylinder_mesh, cantilever_n: int, max_steps: int) -> list[dict]:
    """Veronda-Westmann γ up to 50: the cylinder under gravity (static and dynamic) and the
    cantilever at a load that stretches it far."""
    rows = []
    damping = TABLE_4_4_DAMPING["VerondaWestmann"]
    for gamma in gammas:
        for method in ("newton", "ncg", "dynamic CFL", "dynamic 0.9 × critical"):
            body, tip = cylinder_body(cylinder_mesh, snede.VerondaWestmann(1e4, 0.3, gamma))
            note = ""
            if method == "dynamic CFL":
                outcome = dynamic(body, damping, "gamma_cfl", max_steps=max_steps)
                note = f"η = {damping:g} 1/s (Table 4.4)"
            elif method == "dynamic 0.9 × critical":
                critical = snede.DynamicRelaxation(body, damping=damping,
                                                   options_prefix=options_prefix("gamma_critical"))
                critical_dt, cfl_dt = critical.critical_time_step(), critical.cfl_time_step
                outcome = dynamic(body, damping, "gamma_critical_run", dt=0.9 * critical_dt, max_steps=max_steps)
                note = f"critical Δt = {critical_dt:.3g} s = {critical_dt / cfl_dt:.2f} × CFL"
            else:
                outcome = static(body, method, f"gamma_{method}", rtol=1e-6, max_iterations=5000)
            rows.append(row("Veronda-Westmann γ (cylinder, gravity)", f"γ = {gamma:g}", "VerondaWestmann", method,
                            outcome, "tip sag [m]", tip_sag(body, tip), note=note))
    for gamma in gammas:
        for load in (300.0, 3000.0):
            body, tip = cantilever_body(cantilever_n, snede.VerondaWestmann(YOUNG, 0.0, gamma), load=load)
            outcome = static(body, "newton", "gamma_cantilever", rtol=1e-6, max_iterations=500)
            rows.append(row("Veronda-Westmann γ (cantilever)", f"γ = {gamma:g}, F = {load:g} N", "VerondaWestmann",
                            "newton", outcome, "tip deflection [m]", float(tip_deflections(body, tip).mean())))
    return rows


def sliver_mesh(n: int, target: float):
    """The n × n/4 × n/4 cantilever box with one interior node (a quarter along, mid-height,
    mid-depth) moved along +x towards its neighbour, by a bisected amount that makes the
    smallest aspect ratio (mesh.quality(), min height / max edge) about ``target``. The two
    nodes share an edge, and the node stops short of its neighbour: no cell inverts (checked)."""
    box = snede.meshing.box((LENGTH, HEIGHT, DEPTH), (n, n // 4, n // 4))
    spacing = LENGTH / n
    node = int(np.argmin(np.linalg.norm(box.points - [n // 4 * spacing, HEIGHT / 2, DEPTH / 2], axis=1)))
    low, high = 0.0, 1.0  # fraction of the spacing moved; aspect ratio falls as it grows
    for _ in range(60):
        middle = 0.5 * (low + high)
        points = box.points.copy()
        points[node, 0] += middle * spacing
        if snede.Mesh(points, box.cells).quality().aspect_ratio.min() > target:
            low = middle
        else:
            high = middle
    points = box.points.copy()
    points[node, 0] += high * spacing
    mesh = snede.Mesh(points, box.cells)
    if mesh.n_reoriented:
        raise RuntimeError("moving the node inverted a cell")
    return mesh


def sliver_rows(n: int, targets, max_steps: int) -> list[dict]:
    """Elements of aspect ratio down to 1e-4: the same beam and connectivity with one node
    moved; the tip deflection should hardly change, but the smallest element sets the
    explicit time step (§4.5.6)."""
    rows = []
    regular, tip = cantilever_body(n, snede.LinearElastic(YOUNG, 0.0))
    static(regular, "cg", "sliver_reference")
    reference = float(tip_deflections(regular, tip).mean())
    damping = critical_damping_estimate(regular, regular.displacement)
    for target in targets:
        mesh = sliver_mesh(n, target)
        aspect = float(mesh.quality().aspect_ratio.min())
        for method in ("cg", "ncg", "dynamic"):
            body, tip = cantilever_body(n, snede.LinearElastic(YOUNG, 0.0), mesh=mesh)
            if method == "dynamic":
                outcome = dynamic(body, damping, "sliver_dynamic", max_steps=max_steps)
                dt = snede.DynamicRelaxation(body, damping=damping, options_prefix=options_prefix("dt")).dt
                note = f"CFL Δt = {dt:.2g} s"
            else:
                outcome = static(body, method, f"sliver_{method}", rtol=1e-8, max_iterations=50000)
                note = ""
            rows.append(row("aspect ratio (one node moved)", f"min aspect ratio {aspect:.1e}, {n}×{n // 4}×{n // 4}",
                            "LinearElastic", method, outcome, "tip deflection [m] (reference: unmoved mesh)",
                            float(tip_deflections(body, tip).mean()), reference, note, min_aspect_ratio=aspect))
    return rows


def time_step_rows(n: int, cylinder_mesh, factors, max_steps: int) -> list[dict]:
    """Dynamic relaxation with Δt = factor × the critical step of §4.4.1
    (DynamicRelaxation.critical_time_step), against the static solution."""
    rows = []
    beam, tip = cantilever_body(n, snede.LinearElastic(YOUNG, 0.0))
    cylinder, cylinder_tip = cylinder_body(cylinder_mesh)
    for name, body, probe, method, damping in (
            ("cantilever, LinearElastic", beam, lambda b: float(tip_deflections(b, tip).mean()), "cg", None),
            ("cylinder, NeoHookean", cylinder, lambda b: tip_sag(b, cylinder_tip), "newton",
             TABLE_4_4_DAMPING["NeoHookean"])):
        static(body, method, "dt_static", rtol=1e-8, criterion="6.8",
               petsc_options=None if method == "cg" else {"snes_linesearch_type": "cp"})
        reference = probe(body)
        damping = damping or critical_damping_estimate(body, body.displacement)
        zero = np.zeros_like(body.displacement)
        body.displacement = zero
        critical = snede.DynamicRelaxation(body, damping=damping, options_prefix=options_prefix("critical"))
        critical_dt, cfl_dt = critical.critical_time_step(), critical.cfl_time_step
        for factor in factors:
            body.displacement = zero
            outcome = dynamic(body, damping, "dt", dt=factor * critical_dt, max_steps=max_steps)
            value = probe(body)
            rows.append(row("time step (dynamic relaxation)", f"Δt = {factor:g} × critical ({critical_dt:.3g} s; "
                            f"CFL {cfl_dt:.3g} s)", name, "dynamic", outcome, "tip deflection/sag [m] "
                            "(reference: static)", value, reference, f"η = {damping:.3g} 1/s", factor=factor))
    return rows


def top_face_loads(mesh, pressure: float):
    """Nodal forces of a uniform pressure (Pa, along −z) on the boundary faces at the top
    (z = max): each triangle gives a third of its force to each of its vertices, so corner
    nodes are not overloaded. Returns (vertices, forces (n, 3))."""
    faces = mesh.boundary_faces()
    corners = mesh.points[faces]
    top = np.all(np.isclose(corners[:, :, 2], mesh.points[:, 2].max()), axis=1)
    areas = 0.5 * np.linalg.norm(np.cross(corners[top, 1] - corners[top, 0], corners[top, 2] - corners[top, 0]), axis=1)
    share = np.zeros(mesh.n_points)
    np.add.at(share, faces[top], np.repeat(areas[:, None] / 3, 3, axis=1))
    vertices = np.flatnonzero(share)
    return vertices, np.outer(share[vertices], (0.0, 0.0, -pressure))


def inversion_rows(divisions: int, stresses) -> list[dict]:
    """A 0.1 m cube, E = 1e4 Pa, ν = 0.3, fixed at its bottom, its top face pressed down
    uniformly with s·E. St. Venant-Kirchhoff softens in compression and has no compressed
    equilibrium beyond about 0.2E (uniaxially): it goes through itself (det F < 0), which it
    allows; neo-Hookean's energy becomes infinite there, so it cannot."""
    rows = []
    for material_name, make in (("StVenantKirchhoff", snede.StVenantKirchhoff), ("NeoHookean", snede.NeoHookean)):
        for stress in stresses:
            for method in ("newton", "ncg"):
                mesh = snede.meshing.box((0.1, 0.1, 0.1), (divisions,) * 3)
                body = snede.Body(mesh, make(1e4, 0.3))
                body.fix(np.isclose(mesh.points[:, 2], 0.0))
                top, forces = top_face_loads(mesh, stress * 1e4)
                body.add_nodal_force(top, forces)
                outcome = static(body, method, f"invert_{method}", rtol=1e-6, max_iterations=5000)
                inverted = len(body.inverted_elements(body.displacement))
                note = f"{inverted} of {mesh.n_cells} cells inverted" if inverted else ""
                if inverted and outcome.converged:
                    note += ": an equilibrium of a body that passed through itself"
                rows.append(row("compression (inversion)", f"top pressure {stress:g}·E", material_name, method,
                                outcome, "mean top displacement / height",
                                -float(body.displacement[top, 2].mean()) / 0.1, note=note, inverted_elements=inverted))
    return rows


COLUMNS = [Column("case", "case"), Column("setting", "setting"), Column("material", "material"),
           Column("solver", "solver"), Column("converged", "converged"), Column("reason", "reason"),
           Column("seconds", "seconds", "{:.2f}"), Column("iterations", "its"), Column("value", "value", "{:.4g}"),
           Column("ratio", "value / reference", "{:.3g}"), Column("note", "note")]


def _outcomes(rows) -> str:
    """'setting solver: reason' for each row, joined."""
    return "; ".join(f"{r['setting']} {r['solver']}: {r['reason'] if not r['converged'] else 'converged'}"
                     for r in rows)


def findings(rows, template: PageTemplate) -> list[str]:
    """The bullet points of the markdown (snippets of ``template``), each filled from the rows it
    summarises."""
    def pick(case_start, **match):
        return [r for r in rows if r["case"].startswith(case_start) and all(r[k] == v for k, v in match.items())]

    snippet = template.snippet
    bullets = []
    locking = pick("ν")
    locked = [r for r in locking if r["note"].startswith("locks")]
    linear_cg = [r for r in locking if r["material"] == "LinearElastic"]
    stiffest = [r for r in linear_cg if r["poisson"] == max(r["poisson"] for r in linear_cg)]
    if locking:
        bullets.append(snippet(
            "locking",
            locks=snippet("locked", runs="; ".join(f"{r['setting']} {r['material']}: {r['ratio']:.0%}" for r in locked))
            if locked else snippet("not_locked"),
            threshold=LOCKING_RATIO,
            refinement=snippet("refinement", ratios=" → ".join(f"{r['ratio']:.0%} ({r['setting']})" for r in stiffest))
            if len(stiffest) > 1 else "",
            iterations=", ".join(f"{r['iterations']} ({r['setting']})" for r in linear_cg)))
    scaled = pick("E (cantilever")
    if scaled:
        neo = [r for r in scaled if r["material"] == "NeoHookean"]
        stalled = [r for r in neo if r["reason"] == "DIVERGED_LINE_SEARCH"]
        bullets.append(snippet(
            "scaled", worst=max(abs(r["ratio"] - 1) for r in scaled if r["material"] == "LinearElastic"),
            outcomes=_outcomes(neo),
            stalled=snippet("line_search_stalls", changes=", ".join(f"{abs(r['ratio'] - 1):.0e}" for r in stalled))
            if stalled else ""))
    cylinder = pick("E (cylinder")
    if cylinder:
        stuck = [r for r in cylinder if r["solver"] == "ncg" and not r["converged"] and r["iterations"] == 0]
        bullets.append(snippet("cylinder", outcomes=_outcomes(cylinder),
                               ncg=snippet("ncg_stuck" if stuck else "ncg_first_step")))
    veronda = pick("Veronda-Westmann γ (cylinder")
    if veronda:
        newton = [r for r in veronda if r["solver"] == "newton"]
        critical_rows = [r for r in veronda if r["solver"] == "dynamic 0.9 × critical"]
        bullets.append(snippet(
            "veronda", sags=" → ".join(f"{r['value']:.3g} m" for r in newton),
            iterations=" → ".join(str(r["iterations"]) for r in newton),
            cfl=_outcomes([r for r in veronda if r["solver"] == "dynamic CFL"]), critical=_outcomes(critical_rows),
            notes="; ".join(f"{r['setting']}: {r['note']}" for r in critical_rows)))
    far = pick("Veronda-Westmann γ (cantilever")
    if far:
        domain = any(r["reason"] == "DIVERGED_FUNCTION_DOMAIN" for r in far)
        bullets.append(snippet("far", outcomes=_outcomes(far), domain=snippet("function_domain") if domain else ""))
    slivers = pick("aspect")
    if slivers:
        static_rows = [r for r in slivers if r["solver"] == "cg"]
        dynamic_rows = [r for r in slivers if r["solver"] == "dynamic"]
        spread = max(abs(r["ratio"] - 1) for r in static_rows)
        bullets.append(snippet(
            "slivers", aspects=", ".join(f"{r['min_aspect_ratio']:.0e}" for r in static_rows),
            ratios=", ".join(f"{r['ratio']:.3f}" for r in static_rows),
            change=snippet("small_change" if spread < 0.02 else "changes_answer"),
            iterations=", ".join(str(r["iterations"]) for r in static_rows), first=static_rows[0]["iterations"],
            notes=", ".join(r["note"] for r in dynamic_rows),
            ends=", ".join(r["reason"] if not r["converged"] else "converged" for r in dynamic_rows)))
    steps = pick("time step")
    if steps:
        above = [r for r in steps if r["factor"] > 1 and r["converged"]]
        below = [r for r in steps if r["factor"] <= 1 and not r["converged"]]
        bullets.append(snippet(
            "time_step",
            runs="; ".join(f"{r['material']}, {r['setting'].split(' (')[0]}: "
                           + (snippet("settled", ratio=r["ratio"]) if r["converged"] else r["reason"]) for r in steps),
            above=snippet("settled_above", runs=", ".join(f"{r['material']} at {r['factor']:g} ×" for r in above))
            if above else snippet("none_settled_above"),
            below=snippet("unsettled_below", runs=", ".join(f"{r['material']} at {r['factor']:g} ×" for r in below))
            if below else ""))
    compression = pick("compression")
    if compression:
        through = [r for r in compression if r["converged"] and r["inverted_elements"]]
        neo_failed = [r for r in compression if r["material"] == "NeoHookean" and not r["converged"]]
        bullets.append(snippet(
            "inversion", through=", ".join(f"{r['setting']} {r['solver']}" for r in through) or snippet("none"),
            neo_failed=snippet("neo_failed", outcomes=_outcomes(neo_failed)) if neo_failed else "",
            buckling=EULER_BUCKLING_STRESS))
    return bullets


def describe(rows, quick: bool, minutes: float) -> str:
    """extremes.md: studies/templates/extremes.md filled with the findings and a table per case."""
    template = PageTemplate("extremes")
    by_case = {}
    for entry in rows:
        by_case.setdefault(entry["case"], []).append(entry)
    failed = [r for r in rows if not r["converged"]]
    return template.page(
        quick_flag=" --quick" if quick else "",
        run=template.snippet("quick_run") if quick else template.snippet("full_run", minutes=minutes),
        n_runs=len(rows), n_converged=len(rows) - len(failed), n_failed=len(failed),
        findings="\n".join(findings(rows, template)),
        cases="\n\n".join(template.snippet("case", case=case, table=markdown_table(case_rows, COLUMNS))
                           for case, case_rows in by_case.items()))


def main(argv=None) -> list[dict]:
    start = time.perf_counter()
    arguments = parse_arguments(__doc__, argv)
    quick = arguments.quick
    cylinder_mesh = snede.meshing.cylinder(0.1, 0.03, 0.02, seed=1) if quick else snede.Mesh.read(
        MESHES / "cylinder_small.msh")
    rows = []
    rows += locking_rows((8,) if quick else (16, 32), (0.0, 0.3, 0.49, 0.499) if quick else
                         (0.0, 0.3, 0.45, 0.49, 0.499))
    rows += young_rows(8 if quick else 16, (1e2, 1e6, 1e9) if quick else (1e2, 1e4, 1e6, 1e9), cylinder_mesh)
    rows += veronda_rows((1.0, 50.0) if quick else (1.0, 8.0, 20.0, 50.0), cylinder_mesh, 8 if quick else 16,
                         max_steps=2000 if quick else 20000)
    rows += sliver_rows(8 if quick else 16, (1e-2, 1e-4) if quick else (1e-1, 1e-2, 1e-3, 1e-4),
                        max_steps=2000 if quick else 20000)
    rows += time_step_rows(8 if quick else 16, cylinder_mesh, (0.5, 1.5) if quick else (0.5, 0.9, 1.0, 1.1, 1.5),
                           max_steps=3000 if quick else 30000)
    rows += inversion_rows(2 if quick else 4, (0.1, 0.3, 3.0) if quick else (0.1, 0.15, 0.3, 1.0, 3.0))
    print(markdown_table(rows, COLUMNS))
    out = arguments.out
    write_csv(out / "extremes.csv", rows)
    (out / "extremes.md").write_text(describe(rows, quick, (time.perf_counter() - start) / 60))
    print(f"wrote {out / 'extremes.md'}, extremes.csv")
    return rows


if __name__ == "__main__":
    main()
