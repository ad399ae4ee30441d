"""Accuracy against wall time over mesh size × formulation × stopping tolerance × solver, for the
§3.3 cantilever (linear) and the Table 4.2 cylinder (neo-Hookean under gravity): the Pareto
frontier and the knobs to pick for 1 %, 5 % and 20 % error. The formulation (issue 35) is
"p1" on every mesh and "smoothed" (snede.formulations()) on the coarser ones.

    .venv/bin/python -m studies.experiments.tradeoff [--quick] [--out DIR]

The error is that of the tip deflection (mean over the nodes of the free end face: −u_y for
the cantilever, −u_z for the cylinder), a quantity every mesh defines, against a reference
extrapolated from three fine meshes solved at a tight tolerance. Writes tradeoff.md,
tradeoff.csv (one row per run) and tradeoff.png into docs/results/.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

import snede
from studies.experiments.cantilever import LENGTH, YOUNG, cantilever_body, tip_deflections
from studies.experiments.common import (Column, PageTemplate, markdown_table, options_prefix, parse_arguments, pyplot,
                                        run_solve, save_figure, write_csv)

MESHES = Path(__file__).resolve().parents[2] / "meshes"
TARGETS_PCT = (1.0, 5.0, 20.0)
CYLINDER_LENGTH, CYLINDER_RADIUS = 0.1, 0.03


@dataclass(frozen=True)
class MeshChoice:
    """A mesh of a scene: its label, its size h (m) and how to build the loaded body on it,
    returning (body, probe) with probe(body) the tip deflection (m)."""

    label: str
    h: float
    build: Callable[[], tuple]
    formulation: str = "p1"


@dataclass
class Scene:
    name: str
    material: str
    solvers: tuple
    meshes: list  # MeshChoice, the runs' meshes
    reference_meshes: list  # MeshChoice, coarse to fine, for the extrapolated reference
    reference_solve: Callable  # (body, prefix) -> SolveResult at a tight tolerance
    reference_settings: str  # how the reference was solved, in words
    reference_rtol: float


def cylinder_body(mesh, material=None, density: float = 1000.0, formulation: str = "p1"):
    """The Table 4.2 cylinder (Table 4.1 parameters: neo-Hookean E = 1e4 Pa, ν = 0.3 unless
    another material is given; ρ = 1000 kg/m³) fixed at its x = min face and sagging under
    gravity 9.8 m/s² along −z. Returns (body, tip vertex indices at x = max)."""
    body = snede.Body(mesh, material or snede.NeoHookean(1e4, 0.3), density=density, formulation=formulation)
    body.fix(np.isclose(mesh.points[:, 0], mesh.points[:, 0].min()))
    body.add_gravity((0.0, 0.0, -9.8))
    return body, np.flatnonzero(np.isclose(mesh.points[:, 0], mesh.points[:, 0].max()))


def tip_sag(body, tip) -> float:
    return float(-body.displacement[tip, 2].mean())


def labelled(label: str, formulation: str) -> str:
    return label if formulation == "p1" else f"{label} {formulation}"


def cylinder_choice(h: float, file: str | None = None, formulation: str = "p1") -> MeshChoice:
    def build():
        mesh = snede.Mesh.read(MESHES / file) if file else snede.meshing.cylinder(CYLINDER_LENGTH, CYLINDER_RADIUS, h,
                                                                                   seed=1)
        body, tip = cylinder_body(mesh, formulation=formulation)
        return body, lambda b: tip_sag(b, tip)

    return MeshChoice(labelled(file or f"gmsh h={h:g}", formulation), h, build, formulation)


def cantilever_choice(n: int, formulation: str = "p1") -> MeshChoice:
    def build():
        body, tip = cantilever_body(n, snede.LinearElastic(YOUNG, 0.0), formulation=formulation)
        return body, lambda b: float(tip_deflections(b, tip).mean())

    return MeshChoice(labelled(f"{n}×{n // 4}×{n // 4}", formulation), LENGTH / n, build, formulation)


def scenes(quick: bool) -> list[Scene]:
    cantilever_runs = (4, 8) if quick else (8, 12, 16, 24, 32, 48)
    cantilever_smoothed = (4,) if quick else (8, 12, 16, 24)
    cantilever_references = (12, 16, 24) if quick else (32, 48, 72)
    if quick:
        cylinder_runs = [cylinder_choice(0.03), cylinder_choice(0.02), cylinder_choice(0.03, formulation="smoothed")]
        cylinder_references = [cylinder_choice(h) for h in (0.015, 0.0106, 0.0075)]
    else:
        cylinder_runs = [cylinder_choice(0.016), cylinder_choice(0.0112, "cylinder_small.msh"), cylinder_choice(0.008),
                         cylinder_choice(0.0054, "cylinder_large.msh"), cylinder_choice(0.004),
                         cylinder_choice(0.016, formulation="smoothed"),
                         cylinder_choice(0.0112, "cylinder_small.msh", formulation="smoothed"),
                         cylinder_choice(0.008, formulation="smoothed")]
        cylinder_references = [cylinder_choice(h) for h in (0.005, 0.0035, 0.0025)]
    return [
        Scene("cantilever", "LinearElastic E = 1e6 Pa, ν = 0, 3 N at the tip (§3.3)",
              ("cg", "ncg", "newton", "dynamic"),
              [cantilever_choice(n) for n in cantilever_runs] + [cantilever_choice(n, "smoothed") for n in cantilever_smoothed],
              [cantilever_choice(n) for n in cantilever_references],
              lambda body, prefix: snede.StaticSolver(body, "cg", preconditioner="none",
                                                      rtol=1e-9, criterion="6.8", max_iterations=100000,
                                                      options_prefix=prefix).solve(),
              "linear CG, ‖r‖ ≤ 1e-9‖f_ext‖ (6.8; 1e-10 is below what CG attains in double precision here)", 1e-9),
        Scene("cylinder", "NeoHookean E = 1e4 Pa, ν = 0.3, ρ = 1000 kg/m³, gravity (Table 4.1)",
              ("ncg", "newton", "dynamic"), cylinder_runs, cylinder_references,
              lambda body, prefix: snede.StaticSolver(body, "newton", preconditioner="none",
                                                      rtol=1e-8, criterion="6.8", max_iterations=500,
                                                      options_prefix=prefix,
                                                      petsc_options={"snes_linesearch_type": "cp"}).solve(),
              "truncated Newton with the cp line search, ‖r‖ ≤ 1e-8‖f_ext‖ (6.8)", 1e-8),
    ]


def extrapolated_limit(h, values) -> dict:
    """Richardson extrapolation from three values on meshes h₁ > h₂ > h₃, assuming
    value(h) = limit − C h^p. ``limit`` takes p = 2 (the order of P1 displacements) from the
    two finest; ``order`` is p fitted to all three (bisection on [0.25, 6]) and
    ``limit_fitted`` the limit with it, as a check; both NaN without monotone convergence."""
    (h1, h2, h3), (v1, v2, v3) = h, values
    step_coarse, step_fine = v2 - v1, v3 - v2
    result = {"limit": v3 + step_fine * h3**2 / (h2**2 - h3**2), "order": float("nan"),
              "limit_fitted": float("nan")}

    def mismatch(p):
        return (h1**p - h2**p) / (h2**p - h3**p) - step_coarse / step_fine

    low, high = 0.25, 6.0
    if step_coarse * step_fine <= 0 or mismatch(low) * mismatch(high) > 0:
        return result
    for _ in range(100):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if mismatch(low) * mismatch(middle) > 0 else (low, middle)
    p = 0.5 * (low + high)
    return {**result, "order": p, "limit_fitted": v3 + step_fine * h3**p / (h2**p - h3**p)}


def reference(scene: Scene) -> dict:
    values, cells, seconds = [], [], 0.0
    for choice in scene.reference_meshes:
        body, probe = choice.build()
        result = scene.reference_solve(body, options_prefix(f"reference_{scene.name}"))
        if not result.converged:
            raise RuntimeError(f"the {scene.name} reference on {choice.label} did not converge: {result}")
        values.append(probe(body))
        cells.append(body.mesh.n_cells)
        seconds += result.seconds
    limit = extrapolated_limit([c.h for c in scene.reference_meshes], values)
    return {**limit, "values": values, "cells": cells, "seconds": seconds,
            "damping": critical_damping_estimate(body, body.displacement)}


def critical_damping_estimate(body, u) -> float:
    """§4.1: the fastest damping is η = 2√λ₁. The Rayleigh quotient u·f_ext / uᵀMu of a static
    solution u estimates λ₁ from above (a static deflection is close to the lowest mode)."""
    return float(2 * np.sqrt(np.sum(u * body.external_forces()) / np.sum(body.lumped_mass()[:, None] * u * u)))


def solve(body, solver: str, rtol: float, damping: float, label: str):
    prefix = options_prefix(label)
    if solver == "dynamic":
        return snede.DynamicRelaxation(body, damping=damping, options_prefix=prefix).run(rtol=rtol, max_steps=200000)
    return snede.StaticSolver(body, solver, preconditioner="none",
                              rtol=rtol, max_iterations=20000, options_prefix=prefix).solve()


def run_grid(scene: Scene, tolerances, ref: dict) -> list[dict]:
    rows = []
    for choice in scene.meshes:
        body, probe = choice.build()
        for solver in scene.solvers:
            for rtol in tolerances:
                body.displacement = np.zeros((body.mesh.n_points, 3))
                outcome = run_solve(lambda: solve(body, solver, rtol, ref["damping"], f"{scene.name}_{solver}"))
                value = probe(body)
                rows.append({
                    "scene": scene.name, "mesh": choice.label, "formulation": choice.formulation, "h": choice.h,
                    "cells": body.mesh.n_cells,
                    "points": body.mesh.n_points, "solver": solver, "rtol": rtol, "converged": outcome.converged,
                    "reason": outcome.reason, "iterations": outcome.iterations,
                    "linear_iterations": outcome.linear_iterations, "seconds": outcome.seconds,
                    "mflop": outcome.flops / 1e6, "tip_deflection": value,
                    "error_pct": 100 * abs(value - ref["limit"]) / abs(ref["limit"])})
                print(f"{scene.name:<10} {choice.label:<20} {solver:<8} rtol {rtol:<7g} {outcome.reason:<22} "
                      f"{outcome.seconds:8.3f} s  error {rows[-1]['error_pct']:8.3f} %", flush=True)
    return rows


def mark_pareto(rows: list[dict]) -> None:
    """pareto = True for the converged runs no other converged run beats in both time and error."""
    best_error = np.inf
    for row in sorted(rows, key=lambda r: (r["seconds"], r["error_pct"])):
        row["pareto"] = bool(row["converged"] and row["error_pct"] < best_error)
        if row["pareto"]:
            best_error = row["error_pct"]


def recommendations(rows: list[dict], scene: str) -> list[dict]:
    picks = []
    for target in TARGETS_PCT:
        good = [row for row in rows if row["converged"] and row["error_pct"] <= target]
        if good:
            best = min(good, key=lambda r: r["seconds"])
            picks.append({"scene": scene, "target_pct": target, **{k: best[k] for k in (
                "mesh", "formulation", "cells", "solver", "rtol", "seconds", "error_pct")}})
        else:
            best = min((row for row in rows if row["converged"]), key=lambda r: r["error_pct"])
            picks.append({"scene": scene, "target_pct": target, "mesh": "not reached in this grid",
                          "formulation": None, "cells": None, "solver": None, "rtol": None, "seconds": None,
                          "error_pct": None, "best_error_pct": best["error_pct"]})
    return picks


def tolerance_effect(rows: list[dict], tolerances) -> list[dict]:
    """Median over meshes of the change in the tip deflection caused by stopping at rtol
    instead of the tightest rtol of the grid, same mesh and solver (cf. Table 6.1)."""
    tightest = min(tolerances)
    table = []
    for rtol in sorted(tolerances, reverse=True):
        entry = {"rtol": rtol}
        for solver in dict.fromkeys(row["solver"] for row in rows):
            changes = []
            for mesh in dict.fromkeys(row["mesh"] for row in rows):
                pair = {r["rtol"]: r for r in rows if r["mesh"] == mesh and r["solver"] == solver}
                if pair[rtol]["converged"] and pair[tightest]["converged"]:
                    changes.append(100 * abs(pair[rtol]["tip_deflection"] / pair[tightest]["tip_deflection"] - 1))
            entry[solver] = float(np.median(changes)) if changes else None
        table.append(entry)
    return table


def time_to_accuracy_ratio(rows: list[dict], slow: str, fast: str, within_pct: float = 1.0) -> float:
    """Median over meshes of (time of the fastest ``slow`` run) / (time of the fastest ``fast``
    run) among the runs whose tip deflection is within ``within_pct`` of the mesh's converged
    value (the median of all solvers at the tightest rtol)."""
    tightest = min(row["rtol"] for row in rows)
    ratios = []
    for mesh in dict.fromkeys(row["mesh"] for row in rows):
        runs = [row for row in rows if row["mesh"] == mesh and row["converged"]]
        converged_value = np.median([row["tip_deflection"] for row in runs if row["rtol"] == tightest])
        fastest = {}
        for row in runs:
            if 100 * abs(row["tip_deflection"] / converged_value - 1) <= within_pct:
                fastest[row["solver"]] = min(fastest.get(row["solver"], np.inf), row["seconds"])
        if slow in fastest and fast in fastest and fastest[fast] > 0:
            ratios.append(fastest[slow] / fastest[fast])
    return float(np.median(ratios)) if ratios else float("nan")


def median_time_ratio(rows: list[dict], slow: str, fast: str) -> float:
    """Median over meshes and tolerances of the time ratio at the same rtol."""
    ratios = []
    for mesh in dict.fromkeys(row["mesh"] for row in rows):
        for rtol in dict.fromkeys(row["rtol"] for row in rows):
            pick = {r["solver"]: r for r in rows if r["mesh"] == mesh and r["rtol"] == rtol and r["converged"]}
            if slow in pick and fast in pick and pick[fast]["seconds"] > 0:
                ratios.append(pick[slow]["seconds"] / pick[fast]["seconds"])
    return float(np.median(ratios)) if ratios else float("nan")


def tolerance_sentence(rows: list[dict], tolerances, template: PageTemplate) -> str:
    """§6.8.2 compared: the change rtol = 0.01 causes in each static run's tip deflection
    (against the tightest rtol, same mesh and solver) next to that run's total error."""
    tightest = min(tolerances)
    static = [row for row in rows if row["solver"] != "dynamic" and row["converged"]]
    changes = []
    for row in static:
        if row["rtol"] == 1e-2:
            partner = next(r for r in static if r["scene"] == row["scene"] and r["mesh"] == row["mesh"]
                           and r["solver"] == row["solver"] and r["rtol"] == tightest)
            changes.append((100 * abs(row["tip_deflection"] / partner["tip_deflection"] - 1), row))
    if not changes:
        return template.snippet("tolerance_not_in_grid")
    change, worst = max(changes, key=lambda pair: pair[0] / pair[1]["error_pct"])
    share = change / worst["error_pct"]
    return template.snippet("tolerance", tightest=tightest, largest=max(c for c, _ in changes), solver=worst["solver"],
                            scene=worst["scene"], mesh=worst["mesh"], change=change, error=worst["error_pct"],
                            verdict=template.snippet("mesh_decides" if share < 0.2 else "tolerance_matters"))


def unreached_sentence(picks: list[dict], template: PageTemplate) -> str:
    missed = [pick for pick in picks if pick["error_pct"] is None]
    if not missed:
        return template.snippet("all_reached")
    return template.snippet("unreached", missed=", ".join(
        template.snippet("missed_target", target=p["target_pct"], scene=p["scene"], best=p["best_error_pct"])
        for p in missed))


def plot(all_rows: list[dict], scene_names, path: Path) -> None:
    plt = pyplot()
    figure, axes = plt.subplots(1, len(scene_names), figsize=(6.0 * len(scene_names), 4.8), squeeze=False)
    markers = {"cg": "o", "ncg": "s", "newton": "^", "dynamic": "D"}
    for axis, name in zip(axes[0], scene_names):
        rows = [row for row in all_rows if row["scene"] == name]
        meshes = list(dict.fromkeys(row["mesh"] for row in rows))
        for row in rows:
            axis.loglog(max(row["seconds"], 1e-4), max(row["error_pct"], 1e-6), markers[row["solver"]],
                        color=f"C{meshes.index(row['mesh'])}", mfc="none" if not row["converged"] else None, ms=5)
        frontier = sorted((row for row in rows if row["pareto"]), key=lambda r: r["seconds"])
        axis.step([max(r["seconds"], 1e-4) for r in frontier], [max(r["error_pct"], 1e-6) for r in frontier],
                  where="post", color="k", lw=1, label="Pareto frontier")
        for target in TARGETS_PCT:
            axis.axhline(target, color="0.7", lw=0.6, ls="--")
        for index, mesh in enumerate(meshes):
            axis.plot([], [], "o", color=f"C{index}", label=mesh)
        for solver, marker in markers.items():
            if any(row["solver"] == solver for row in rows):
                axis.plot([], [], marker, color="k", mfc="none", label=solver)
        axis.set_xlabel("solve wall time [s]")
        axis.set_ylabel("tip deflection error [%]")
        axis.set_title(name)
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(fontsize=7, ncol=2)
    save_figure(figure, path, 120)


RUN_COLUMNS = [Column("mesh", "mesh"), Column("cells", "cells"), Column("solver", "solver"),
               Column("rtol", "rtol", "{:g}"), Column("iterations", "iterations"),
               Column("seconds", "seconds", "{:.3f}"), Column("error_pct", "error %", "{:.3g}")]
PICK_COLUMNS = [Column("scene", "scene"), Column("target_pct", "target error %", "{:g}"), Column("mesh", "mesh"),
                Column("formulation", "formulation"), Column("cells", "cells"), Column("solver", "solver"), Column("rtol", "rtol", "{:g}"),
                Column("seconds", "seconds", "{:.3f}"), Column("error_pct", "error %", "{:.3g}"),
                Column("best_error_pct", "best error reached %", "{:.3g}")]
REFERENCE_COLUMNS = [
    Column("scene", "scene"), Column("meshes", "reference meshes (cells)"),
    Column("values", "tip deflection on each [m]"), Column("limit", "extrapolated (p = 2) [m]", "{:.6g}"),
    Column("order", "fitted order p", "{:.2f}"), Column("finest_error_pct", "finest mesh's error %", "{:.2f}"),
    Column("fitted_shift_pct", "limit with fitted p vs. p = 2 %", "{:.2f}"),
    Column("damping", "η for dynamic [1/s]", "{:.1f}"), Column("seconds", "seconds", "{:.1f}")]


def describe(scene_list, references, rows, picks, tolerances, quick: bool, minutes: float) -> str:
    """tradeoff.md: studies/templates/tradeoff.md filled with the references, the picks, each
    scene's frontier and the comparisons with the thesis."""
    template = PageTemplate("tradeoff")
    reference_rows = []
    for scene in scene_list:
        ref = references[scene.name]
        reference_rows.append({
            "scene": scene.name, "meshes": ", ".join(f"{c.label} ({n})" for c, n in zip(scene.reference_meshes,
                                                                                      ref["cells"])),
            "values": ", ".join(f"{v:.6g}" for v in ref["values"]), "limit": ref["limit"], "order": ref["order"],
            "finest_error_pct": 100 * abs(ref["values"][-1] / ref["limit"] - 1),
            "fitted_shift_pct": 100 * (ref["limit_fitted"] / ref["limit"] - 1), "damping": ref["damping"],
            "seconds": ref["seconds"]})
    sections = []
    for scene in scene_list:
        scene_rows = [row for row in rows if row["scene"] == scene.name]
        failed = [row for row in scene_rows if not row["converged"]]
        sections.append(template.snippet(
            "scene", name=scene.name, n_runs=len(scene_rows), meshes=", ".join(c.label for c in scene.meshes),
            solvers=", ".join(scene.solvers), tolerances=", ".join(f"{t:g}" for t in tolerances),
            failed="; ".join(f"{r['mesh']} {r['solver']} rtol {r['rtol']:g}: {r['reason']}" for r in failed)
            if failed else template.snippet("none"),
            frontier_table=markdown_table(sorted((row for row in scene_rows if row["pareto"]),
                                                 key=lambda r: r["seconds"]), RUN_COLUMNS),
            tightest=min(tolerances),
            tolerance_table=markdown_table(tolerance_effect(scene_rows, tolerances),
                                           [Column("rtol", "rtol", "{:g}")]
                                           + [Column(s, s, "{:.3g}") for s in scene.solvers])))
    cantilever_rows = [row for row in rows if row["scene"] == "cantilever"]
    cylinder_rows = [row for row in rows if row["scene"] == "cylinder"]
    linear_ratio = time_to_accuracy_ratio(cantilever_rows, "dynamic", "cg")
    nonlinear_ratio = time_to_accuracy_ratio(cylinder_rows, "dynamic", "ncg")
    newton_ratio = time_to_accuracy_ratio(cylinder_rows, "ncg", "newton")
    return template.page(
        quick_flag=" --quick" if quick else "",
        run=template.snippet("quick_run") if quick else template.snippet("full_run", minutes=minutes),
        settings="; ".join(template.snippet("reference_settings", scene=s.name, material=s.material,
                                            settings=s.reference_settings) for s in scene_list),
        reference_table=markdown_table(reference_rows, REFERENCE_COLUMNS), picks_table=markdown_table(picks, PICK_COLUMNS),
        scenes="\n\n".join(sections), linear_ratio=linear_ratio,
        linear_verdict=template.snippet("agrees" if 4 <= linear_ratio <= 12 else "differs"),
        equal_rtol_ratio=median_time_ratio(cantilever_rows, "dynamic", "cg"), nonlinear_ratio=nonlinear_ratio,
        nonlinear_verdict=template.snippet("roughly_agrees" if 0.5 <= nonlinear_ratio <= 2 else
                                           "ncg_faster" if nonlinear_ratio > 2 else "dynamic_faster"),
        newton_share=1 / newton_ratio, tolerance=tolerance_sentence(rows, tolerances, template),
        unreached=unreached_sentence(picks, template))


def main(argv=None) -> dict:
    start = time.perf_counter()
    arguments = parse_arguments(__doc__, argv)
    tolerances = (1e-1, 1e-3) if arguments.quick else (3e-1, 1e-1, 1e-2, 1e-3, 1e-4)
    scene_list = scenes(arguments.quick)
    references, rows, picks = {}, [], []
    for scene in scene_list:
        references[scene.name] = reference(scene)
        print(f"{scene.name} reference: {references[scene.name]}", flush=True)
        scene_rows = run_grid(scene, tolerances, references[scene.name])
        mark_pareto(scene_rows)
        rows += scene_rows
        picks += recommendations(scene_rows, scene.name)
    print(markdown_table(picks, PICK_COLUMNS))
    out = arguments.out
    write_csv(out / "tradeoff.csv", rows)
    plot(rows, [scene.name for scene in scene_list], out / "tradeoff.png")
    (out / "tradeoff.md").write_text(describe(scene_list, references, rows, picks, tolerances, arguments.quick,
                                              (time.perf_counter() - start) / 60))
    print(f"wrote {out / 'tradeoff.md'}, tradeoff.csv, tradeoff.png")
    return {"rows": rows, "references": references, "recommendations": picks,
            "reference_rtol": {scene.name: scene.reference_rtol for scene in scene_list},
            "reference_h": {scene.name: min(c.h for c in scene.reference_meshes) for scene in scene_list}}


if __name__ == "__main__":
    main()
