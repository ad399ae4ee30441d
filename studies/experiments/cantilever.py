"""§3.3 cantilever: Table 3.1 (linear CG on structured meshes, tip error against beam
theory) and the nonlinear materials at larger loads (geometric nonlinearity).

    .venv/bin/python -m studies.experiments.cantilever [--quick] [--out DIR]

Writes cantilever.md, cantilever.csv (one row per solve) and cantilever.png (tip error
against element size, log-log, with the thesis's points) into docs/results/.
"""
from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

import snede
from studies.experiments.common import (Column, PageTemplate, markdown_table, options_prefix, parse_arguments, pyplot,
                                        run_solve, save_figure, write_csv)

LENGTH, HEIGHT, DEPTH, YOUNG, LOAD = 1.2, 0.2, 0.3, 1e6, 3.0
SHEAR_COEFFICIENT = 5 / 6  # Timoshenko's κ for a rectangular section
# Table 3.1: divisions along l -> (nodes, CG iterations, avg error %, max error %)
THESIS_TABLE_3_1 = {16: (425, 377, 29.0, 29.3), 24: (1225, 561, 15.1, 15.3), 32: (2673, 723, 8.6, 8.8),
                    40: (4961, 882, 5.2, 5.3), 48: (8181, 1044, 3.2, 3.3)}
VERONDA_GAMMA = 8.0
NONLINEAR_MATERIALS = {
    "StVenantKirchhoff": lambda: snede.StVenantKirchhoff(YOUNG, 0.0),
    "NeoHookean": lambda: snede.NeoHookean(YOUNG, 0.0),
    f"VerondaWestmann γ={VERONDA_GAMMA:g}": lambda: snede.VerondaWestmann(YOUNG, 0.0, VERONDA_GAMMA),
}
# Newton with PETSc's cp line search (a secant on the directional derivative): the default
# energy-based backtracking stalls near ‖r‖ ≈ 1e-6‖f‖ on this beam, where energy decreases
# fall below round-off, and reports DIVERGED_LINE_SEARCH before (6.8) with 1e-8 is met.
NEWTON_OPTIONS = {"snes_linesearch_type": "cp"}


def beam_deflection(load: float = LOAD, young: float = YOUNG) -> float:
    """Euler-Bernoulli tip deflection y = 4F/(Ed)(l/h)³ of §3.3 (8.64e-3 m for 3 N)."""
    return 4 * load / (young * DEPTH) * (LENGTH / HEIGHT) ** 3


def timoshenko_deflection(load: float = LOAD, young: float = YOUNG, poisson: float = 0.0) -> float:
    """Beam theory with shear deformation: y + F l/(κ G A), G = E/(2(1 + ν)). The limit a
    converging FEM approaches (apart from 3D effects at the clamped end)."""
    shear_modulus = young / (2 * (1 + poisson))
    return beam_deflection(load, young) + load * LENGTH / (SHEAR_COEFFICIENT * shear_modulus * HEIGHT * DEPTH)


def elastica_tip(load: float, young: float = YOUNG) -> tuple[float, float]:
    """Tip deflection and tip shortening (m) of the inextensible elastica, the exact large-
    deflection beam (Bisshopp and Drucker): with α = F l²/(EI) and arc length s ∈ [0, 1],
    θ'' = −α cos θ, θ(0) = 0, θ'(1) = 0, solved by shooting on θ'(0) (bisection, RK4).
    A check for the nonlinear materials' geometric stiffening, independent of the FEM."""
    alpha = load * LENGTH**2 / (young * DEPTH * HEIGHT**3 / 12)
    steps = 400
    step = 1.0 / steps

    def integrate(curvature0):
        def rate(state):
            angle, curvature, _, _ = state
            return (curvature, -alpha * math.cos(angle), math.sin(angle), math.cos(angle))

        state = (0.0, curvature0, 0.0, 0.0)
        for _ in range(steps):
            k1 = rate(state)
            k2 = rate(tuple(x + 0.5 * step * k for x, k in zip(state, k1)))
            k3 = rate(tuple(x + 0.5 * step * k for x, k in zip(state, k2)))
            k4 = rate(tuple(x + step * k for x, k in zip(state, k3)))
            state = tuple(x + step / 6 * (a + 2 * b + 2 * c + d) for x, a, b, c, d in zip(state, k1, k2, k3, k4))
        return state

    low, high = 0.0, alpha  # θ'(1) < 0 at θ'(0) = 0 and ≥ 0 at θ'(0) = α
    for _ in range(50):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if integrate(middle)[1] < 0 else (low, middle)
    _, _, height, length = integrate(0.5 * (low + high))
    return height * LENGTH, (1 - length) * LENGTH


def cantilever_body(n: int, material, load: float = LOAD, mesh=None, formulation: str = "p1"):
    """The §3.3 beam on snede.meshing.box with n × n/4 × n/4 cubes (6 tetrahedra each), or on
    ``mesh`` (the same beam meshed otherwise), fixed at x = 0, ``load`` newtons along −y split
    over the tip nodes (x = l), in ``formulation`` (snede.formulations()). Returns (body, tip
    vertex indices)."""
    if n < 4 or n % 4:
        raise ValueError(f"divisions along the length must be a positive multiple of 4, got {n}")
    if mesh is None:
        mesh = snede.meshing.box((LENGTH, HEIGHT, DEPTH), (n, n // 4, n // 4))
    body = snede.Body(mesh, material, formulation=formulation)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(mesh.points[:, 0], LENGTH))
    body.add_nodal_force(tip, (0.0, -load / len(tip), 0.0))
    return body, tip


def tip_deflections(body, tip) -> np.ndarray:
    """−u_y at the tip nodes (m)."""
    return -body.displacement[tip, 1]


def linear_cg(body, label: str):
    """Table 3.1's solve: linear CG until ‖r‖ < 1e-8‖f_ext‖ (criterion (6.8))."""
    return run_solve(lambda: snede.StaticSolver(body, "cg", preconditioner="none",
                                                rtol=1e-8, criterion="6.8", max_iterations=100000,
                                                options_prefix=options_prefix(label)).solve())


def table_3_1_rows(sizes) -> list[dict]:
    analytic, with_shear = beam_deflection(), timoshenko_deflection()
    rows = []
    for n in sizes:
        body, tip = cantilever_body(n, snede.LinearElastic(YOUNG, 0.0))
        outcome = linear_cg(body, f"table31_{n}")
        deflection = tip_deflections(body, tip)
        errors = 100 * np.abs(analytic - deflection) / analytic
        thesis = THESIS_TABLE_3_1.get(n, (None,) * 4)
        rows.append({
            "part": "table_3_1", "elements": f"{n} × {n // 4} × {n // 4}", "n": n, "h": LENGTH / n,
            "nodes": body.mesh.n_points, "tetrahedra": body.mesh.n_cells, "material": "LinearElastic",
            "load": LOAD, "method": "cg", "converged": outcome.converged, "reason": outcome.reason,
            "iterations": outcome.iterations, "seconds": outcome.seconds,
            "tip_deflection": float(deflection.mean()), "all_below_analytic": bool(np.all(deflection < analytic)),
            "avg_error_pct": float(errors.mean()), "max_error_pct": float(errors.max()),
            "avg_error_vs_timoshenko_pct": float(100 * (1 - deflection.mean() / with_shear)),
            "thesis_nodes": thesis[0], "thesis_iterations": thesis[1],
            "thesis_avg_error_pct": thesis[2], "thesis_max_error_pct": thesis[3]})
    return rows


def small_strain_equivalent(material) -> snede.LinearElastic:
    """The linear material a hyperelastic one reduces to at small strain. St. Venant-Kirchhoff
    and neo-Hookean keep (E, ν); Veronda-Westmann's exponential adds 2μ(2γ − 1) to λ
    (§4.3.4), so at ν = 0, γ = 8 it is a nearly incompressible (ν' ≈ 0.48) stiffer solid."""
    if not isinstance(material, snede.VerondaWestmann):
        return snede.LinearElastic(YOUNG, 0.0)
    return snede.LinearElastic(*veronda_small_strain_constants())


def veronda_small_strain_constants() -> tuple[float, float]:
    """(E', ν') of Veronda-Westmann (E, ν = 0, γ) at small strain: μ' = μ, λ' = λ + 2μ(2γ − 1)."""
    mu = YOUNG / 2
    lam = 2 * mu * (2 * VERONDA_GAMMA - 1)
    return mu * (3 * lam + 2 * mu) / (lam + mu), lam / (2 * (lam + mu))


def nonlinear_rows(sizes, loads) -> list[dict]:
    rows = []
    elastica = {load: elastica_tip(load) for load in loads}
    for n in sizes:
        linear_body, tip = cantilever_body(n, snede.LinearElastic(YOUNG, 0.0))
        linear_cg(linear_body, f"linear_{n}")
        linear_per_newton = tip_deflections(linear_body, tip).mean() / LOAD
        for name, make in NONLINEAR_MATERIALS.items():
            equivalent_body, _ = cantilever_body(n, small_strain_equivalent(make()))
            linear_cg(equivalent_body, f"equivalent_{n}")
            equivalent_per_newton = tip_deflections(equivalent_body, tip).mean() / LOAD
            for load in loads:
                body, _ = cantilever_body(n, make(), load)
                outcome = run_solve(lambda: snede.StaticSolver(body, "newton", preconditioner="none",
                                                               rtol=1e-8, criterion="6.8", max_iterations=500,
                    options_prefix=options_prefix(f"nonlinear_{n}"), petsc_options=NEWTON_OPTIONS).solve())
                deflection = float(tip_deflections(body, tip).mean())
                rows.append({
                    "part": "nonlinear", "elements": f"{n} × {n // 4} × {n // 4}", "n": n, "h": LENGTH / n,
                    "nodes": body.mesh.n_points, "tetrahedra": body.mesh.n_cells, "material": name, "load": load,
                    "method": "newton", "converged": outcome.converged, "reason": outcome.reason,
                    "iterations": outcome.iterations, "linear_iterations": outcome.linear_iterations,
                    "seconds": outcome.seconds, "tip_deflection": deflection,
                    "linear_tip_deflection": linear_per_newton * load,
                    "ratio_to_linear": deflection / (linear_per_newton * load),
                    "equivalent_linear_tip_deflection": equivalent_per_newton * load,
                    "ratio_to_equivalent_linear": deflection / (equivalent_per_newton * load),
                    "elastica_ratio": elastica[load][0] / beam_deflection(load),
                    "tip_shortening": float(body.displacement[tip, 0].mean() * -1),
                    "elastica_tip_shortening": elastica[load][1],
                    "inverted_elements": len(body.inverted_elements(body.displacement))})
                print(f"{n:>3} {name:<22} {load:>6g} N  {outcome.reason:<22} {outcome.iterations:>4} Newton "
                      f"{outcome.linear_iterations:>6} CG {outcome.seconds:8.2f} s  "
                      f"ratio {rows[-1]['ratio_to_linear']:.4f}",
                      flush=True)
    return rows


def plot(table, path: Path) -> None:
    plt = pyplot()
    figure, axes = plt.subplots(figsize=(6.4, 4.6))
    h = np.array([row["h"] for row in table])
    axes.loglog(h, [row["avg_error_pct"] for row in table], "o-", color="C0", label="snede, average")
    axes.loglog(h, [row["max_error_pct"] for row in table], "^-", color="C0", mfc="none", label="snede, maximum")
    axes.loglog(h, [row["avg_error_vs_timoshenko_pct"] for row in table], "s:", color="C2",
                label="snede, average vs. beam theory with shear")
    thesis = [row for row in table if row["thesis_avg_error_pct"] is not None]
    if thesis:
        h_thesis = [row["h"] for row in thesis]
        axes.loglog(h_thesis, [row["thesis_avg_error_pct"] for row in thesis], "o--", color="C3",
                    label="thesis Table 3.1, average")
        axes.loglog(h_thesis, [row["thesis_max_error_pct"] for row in thesis], "^--", color="C3", mfc="none",
                    label="thesis Table 3.1, maximum")
    axes.loglog(h, table[0]["avg_error_pct"] * (h / h[0]) ** 2, color="0.6", lw=0.8, label="∝ h²")
    axes.set_xlabel("element size l/n [m]")
    axes.set_ylabel("tip deflection error [%]")
    axes.set_title("§3.3 cantilever, linear CG, ‖r‖ < 1e-8 ‖f‖")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    save_figure(figure, path, 120)


TABLE_COLUMNS = [
    Column("elements", "elements (l×h×d)"), Column("nodes", "nodes"), Column("thesis_nodes", "thesis nodes"),
    Column("tetrahedra", "tetrahedra"), Column("iterations", "CG iterations"),
    Column("thesis_iterations", "thesis iterations"), Column("avg_error_pct", "avg error %", "{:.1f}"),
    Column("thesis_avg_error_pct", "thesis avg %", "{:.1f}"), Column("max_error_pct", "max error %", "{:.1f}"),
    Column("thesis_max_error_pct", "thesis max %", "{:.1f}"),
    Column("avg_error_vs_timoshenko_pct", "avg error vs. shear beam %", "{:.1f}"),
    Column("seconds", "seconds", "{:.2f}"), Column("reason", "reason")]
NONLINEAR_COLUMNS = [
    Column("elements", "elements"), Column("material", "material"), Column("load", "load [N]", "{:g}"),
    Column("iterations", "Newton its"), Column("linear_iterations", "CG its"), Column("seconds", "seconds", "{:.2f}"),
    Column("reason", "reason"), Column("tip_deflection", "tip deflection [m]", "{:.4g}"),
    Column("linear_tip_deflection", "linear (ν=0) [m]", "{:.4g}"), Column("ratio_to_linear", "ratio", "{:.3f}"),
    Column("elastica_ratio", "elastica ratio", "{:.3f}"),
    Column("ratio_to_equivalent_linear", "ratio to small-strain equivalent", "{:.3f}"),
    Column("tip_shortening", "tip shortening −u_x [m]", "{:.3g}"),
    Column("elastica_tip_shortening", "elastica shortening [m]", "{:.3g}")]


def sign_change_divisions(table) -> int:
    """The n at which the FEM tip deflection would reach the Euler-Bernoulli value, if the
    finest mesh's error against the shear-corrected value falls like h²."""
    finest = table[-1]
    shear_pct = 100 * (1 - beam_deflection() / timoshenko_deflection())
    return int(round(finest["n"] * np.sqrt(finest["avg_error_vs_timoshenko_pct"] / shear_pct)))


def describe(table, nonlinear, quick: bool, minutes: float) -> str:
    """cantilever.md: studies/templates/cantilever.md filled with the run's tables and verdicts."""
    template = PageTemplate("cantilever")
    compared = [row for row in table if row["thesis_avg_error_pct"] is not None]
    falling = all(a["avg_error_pct"] > b["avg_error_pct"] for a, b in zip(table, table[1:]))
    below = all(row["all_below_analytic"] for row in table)
    close = all(row["max_error_pct"] - row["avg_error_pct"] < 1 for row in table)
    differs = ""
    if compared:
        differs = template.snippet(
            "differs", n_compared=len(compared),
            ratio_errors=np.mean([row["avg_error_pct"] / row["thesis_avg_error_pct"] for row in compared]),
            ratio_iterations=np.mean([row["iterations"] / row["thesis_iterations"] for row in compared]),
            shear_pct=100 * (timoshenko_deflection() / beam_deflection() - 1), sign_change=sign_change_divisions(table))
    small = [row for row in nonlinear if row["load"] == min(r["load"] for r in nonlinear)]
    large = [row for row in nonlinear if row["load"] == max(r["load"] for r in nonlinear)]
    classic = [row for row in large if not row["material"].startswith("Veronda") and row["converged"]]
    veronda_small = [row for row in small if row["material"].startswith("Veronda")]

    def by_mesh(rows):
        meshes = dict.fromkeys(row["elements"] for row in rows)
        return "; ".join(f"{mesh}: " + ", ".join(f"{row['ratio_to_linear']:.3f}" for row in rows
                                                  if row["elements"] == mesh) for mesh in meshes)

    large_load = template.snippet("no_large_load")
    if classic:
        refined = (len({row["n"] for row in classic}) > 1
                   and classic[-1]["ratio_to_linear"] < classic[0]["ratio_to_linear"])
        large_load = template.snippet("large_load", load=large[0]["load"], ratios=by_mesh(classic),
                                      elastica=large[0]["elastica_ratio"],
                                      refined=template.snippet("moves_towards_elastica" if refined else "neither"))
    veronda = ""
    if veronda_small:
        young, poisson = veronda_small_strain_constants()
        veronda = template.snippet(
            "veronda", ratios=", ".join(f"{row['ratio_to_linear']:.3f} on {row['elements']}" for row in veronda_small),
            load=veronda_small[0]["load"], gamma=VERONDA_GAMMA, young_ratio=young / YOUNG, poisson=poisson,
            equivalent_ratios=", ".join(f"{row['ratio_to_equivalent_linear']:.3f}" for row in veronda_small))
    failed = [row for row in nonlinear if not row["converged"]]
    return template.page(
        quick_flag=" --quick" if quick else "",
        run=template.snippet("quick_run") if quick else template.snippet(
            "full_run", nonlinear_meshes=" and ".join(dict.fromkeys(row["elements"] for row in nonlinear)),
            minutes=minutes),
        length=LENGTH, height=HEIGHT, depth=DEPTH, young=YOUNG, load=LOAD, beam=beam_deflection(),
        timoshenko=timoshenko_deflection(), table=markdown_table(table, TABLE_COLUMNS),
        falls=template.snippet("falls" if falling else "does_not_fall"),
        below=template.snippet("below" if below else "not_below"),
        spread=template.snippet("close_spread" if close else "wide_spread"), differs=differs,
        nonlinear_table=markdown_table(nonlinear, NONLINEAR_COLUMNS),
        small_ratios=by_mesh([row for row in small if not row["material"].startswith("Veronda")]),
        large=large_load, veronda=veronda,
        failed="; ".join(f"{row['material']} at {row['load']:g} N on {row['elements']}: {row['reason']}"
                         for row in failed) if failed else template.snippet("none"))


def main(argv=None) -> dict:
    start = time.perf_counter()
    arguments = parse_arguments(__doc__, argv)
    sizes = (8, 12, 16) if arguments.quick else tuple(THESIS_TABLE_3_1)
    nonlinear_sizes, loads = ((8,), (LOAD, 300.0)) if arguments.quick else ((16, 24), (LOAD, 30.0, 300.0))
    table = table_3_1_rows(sizes)
    print(markdown_table(table, TABLE_COLUMNS), flush=True)
    nonlinear = nonlinear_rows(nonlinear_sizes, loads)
    print(markdown_table(nonlinear, NONLINEAR_COLUMNS), flush=True)
    out = arguments.out
    write_csv(out / "cantilever.csv", table + nonlinear)
    plot(table, out / "cantilever.png")
    (out / "cantilever.md").write_text(describe(table, nonlinear, arguments.quick, (time.perf_counter() - start) / 60))
    print(f"wrote {out / 'cantilever.md'}, cantilever.csv, cantilever.png")
    return {"table_3_1": table, "nonlinear": nonlinear}


if __name__ == "__main__":
    main()
