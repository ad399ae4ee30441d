"""§6.8 needle insertion: Tables 6.1–6.6 and Figures 6.10 and 6.12 of the thesis.

    .venv/bin/python -m studies.experiments.needle [--quick] [--out DIR]

The §6.8.1 slab (snede.app.scenes.needle_slab: 0.1 × 0.1 × 0.01 m, E = 34 kPa, ν = 0.34, fixed at
x = 0.1 m) under the Figure 6.4 stand-in friction profile (snede.FrictionProfile.figure_6_4).

* Static line load (Tables 6.1–6.3, Figure 6.10): the profile's force distribution applied
  along y = 0.05 m, 0 ≤ x ≤ 70 mm, as nodal forces along +x on the mesh nodes of that line
  (each node gets the profile integrated over its share of the line, half-way to its
  neighbours, with the tip at x = 70 mm: as the needle distributes friction); the mesh is
  refined around the line so that the line is made of mesh edges.
* Insertion (Tables 6.4, 6.5): snede.NeedleInsertion to a depth of 70 mm at several speeds (Table 6.5:
  the thesis's haptic loop, one solve per update, at ε = 1e-3 and at the ε of the thesis's CG counts).
* Conformance (Table 6.6): the static load along a tilted line, loaded nodes left where they
  are or projected onto the line (``mesh.snap_vertex``).
* Nonlinearity (Figure 6.12): sideways insertion into a slab fixed at the bottom, ν = 0,
  linear against neo-Hookean.

Writes needle.md, needle.csv (one row per solve or insertion, column ``part``),
needle_errors.png (Figure 6.10), needle_rates.png (Table 6.5's update rates) and
needle_nonlinear*.png (Figure 6.12) into docs/results/.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import snede
from studies.experiments.common import PageTemplate, options_prefix, parse_arguments, pyplot, save_figure, write_csv
from snede.app.scenes.needle_slab import DEPTH, ENTRY, SIZE, YOUNG, h, needle_for, slab_body

ROUND_TOLERANCE = 1e-8  # ε_round of (6.9), §6.8.1
REFERENCE_TOLERANCE = 1e-8  # Table 6.1's reference solve, and the "exact" solves of Tables 6.3 and 6.6
# ε of the solves whose cost is measured (Table 6.2 and the insertions of Table 6.4 and
# Figure 6.12; Table 6.5 has its own, TIMING_TOLERANCES). The thesis does not say which ε it used there; 0.01 gives CG counts close to
# its Table 6.2 (see needle.md) and an error of ~0.01 mm in Table 6.1.
WORKING_TOLERANCE = 0.01
TOLERANCES = (0.3, 0.1, 0.03, 0.01, 0.003, 0.001)
SPEEDS = (3.0, 1.0, 0.3, 0.1, 0.03, 0.01)
TILT_DEGREES = 15.0  # Table 6.6's line: from the entry point (0, 0.05), 15° above the x axis
MM = 1e3

# --- the thesis's numbers -------------------------------------------------------------------
THESIS_TABLE_6_1 = {0.3: (0.74, 2.98), 0.1: (0.061, 0.18), 0.03: (0.034, 0.083), 0.01: (0.011, 0.022),
                    0.003: (0.0038, 0.0096), 0.001: (0.0008, 0.0021)}
# (h_start, h_ref) -> CG iterations (Table 6.2), mean and maximum error in mm (Table 6.3)
THESIS_TABLE_6_2 = {
    (1, 3): 22, (1, 4): 34, (1, 5): 45, (1, 6): 62, (1, 7): 84,
    (2, 3): 27, (2, 4): 36, (2, 5): 46, (2, 6): 64, (2, 7): 84,
    (3, 3): 46, (3, 4): 49, (3, 5): 58, (3, 6): 73, (3, 7): 93,
    (4, 4): 81, (4, 5): 86, (4, 6): 96, (4, 7): 115,
    (5, 5): 204, (5, 6): 208, (5, 7): 194,
    (6, 6): 278, (6, 7): 285}
THESIS_TABLE_6_3_MEAN = {
    (1, 3): 0.34, (1, 4): 0.33, (1, 5): 0.33, (1, 6): 0.30, (1, 7): 0.28,
    (2, 3): 0.26, (2, 4): 0.24, (2, 5): 0.24, (2, 6): 0.21, (2, 7): 0.20,
    (3, 3): 0.15, (3, 4): 0.13, (3, 5): 0.13, (3, 6): 0.10, (3, 7): 0.08,
    (4, 4): 0.09, (4, 5): 0.08, (4, 6): 0.04, (4, 7): 0.03,
    (5, 5): 0.07, (5, 6): 0.03, (5, 7): 0.00,
    (6, 6): 0.02, (6, 7): 0.00}
THESIS_TABLE_6_3_MAX = {
    (1, 3): 1.01, (1, 4): 0.88, (1, 5): 0.88, (1, 6): 0.87, (1, 7): 0.87,
    (2, 3): 0.91, (2, 4): 0.68, (2, 5): 0.61, (2, 6): 0.54, (2, 7): 0.53,
    (3, 3): 0.66, (3, 4): 0.54, (3, 5): 0.51, (3, 6): 0.29, (3, 7): 0.27,
    (4, 4): 0.45, (4, 5): 0.43, (4, 6): 0.19, (4, 7): 0.14,
    (5, 5): 0.41, (5, 6): 0.17, (5, 7): 0.06,
    (6, 6): 0.16, (6, 7): 0.03}
THESIS_TABLE_6_4 = {3.0: (0.62, 1.60), 1.0: (0.68, 1.96), 0.3: (0.15, 0.34), 0.1: (0.18, 0.68),
                    0.03: (0.36, 1.08), 0.01: (0.07, 0.27)}
THESIS_TABLE_6_4_REFERENCE_SPEED = 0.005
THESIS_TABLE_6_4_DISCRETISATION = (0.11, 0.29)
# h_ref -> speed -> (CPU s, rearrangements, update rate Hz, mean CG, max CG); h_start = h3
THESIS_TABLE_6_5 = {
    6: {3.0: (0.80, 157, 196.25, 11.81, 41), 1.0: (0.90, 232, 257.78, 11.52, 62),
        0.3: (0.94, 308, 327.66, 10.87, 70), 0.1: (1.07, 504, 471.03, 8.14, 61),
        0.03: (2.24, 1478, 659.82, 5.31, 57), 0.01: (5.77, 4187, 725.65, 3.87, 51)},
    7: {3.0: (2.46, 243, 98.78, 12.67, 57), 1.0: (2.80, 401, 143.21, 10.88, 82),
        0.3: (3.15, 561, 178.10, 10.03, 66), 0.1: (3.48, 1000, 287.36, 6.63, 67),
        0.03: (6.34, 2966, 467.82, 4.18, 53), 0.01: (15.68, 8505, 542.41, 3.15, 48)}}
UPDATE_RATE_GOAL = 50.0  # issue 33's goal: update rates ≥ 50 × the thesis's in every row at ε = 1e-3
H7_RATE_GOAL_HZ = 1000.0  # and ≥ 1 kHz at h_ref = h7
# Table 6.5 is timed in the thesis's haptic loop (§6.7: one solve per update) at the issue's ε
# and at the ε whose CG counts are the thesis's: the geometric mean over Table 6.5's 12 rows of
# (our mean CG / the thesis's) is 1 there (studies/benchmarks/needle_rates.py --scan: 2.40 at 0.01, 1.53
# at 0.02, 1.06 at 0.03, 0.68 at 0.05). The thesis states neither ε.
ISSUE_TOLERANCE = 1e-3
THESIS_CG_TOLERANCE = 0.03
TIMING_TOLERANCES = (ISSUE_TOLERANCE, THESIS_CG_TOLERANCE)
THESIS_TABLE_6_6 = {"relocation_vs_none": (0.019, 0.23), "with_relocation": (0.094, 0.43),
                    "without_relocation": (0.095, 0.37)}
THESIS_TIP_DISTANCE_MM = 8.0  # Figure 6.12


@dataclass(frozen=True)
class Settings:
    fine: int                    # reference: uniform mesh with longest edge h_fine
    tolerance_level: int         # Table 6.1's mesh: h_start = h_ref = this
    starts: tuple                # Tables 6.2/6.3 rows (h_start)
    refs: tuple                  # Tables 6.2/6.3 columns (h_ref)
    figure_pairs: tuple          # Figure 6.10's (h_start, h_ref)
    h_start: int                 # Tables 6.4–6.6 and Figure 6.12
    h_ref: int                   # Tables 6.4, 6.6 and Figure 6.12
    speeds: tuple                # h_ref per update
    reference_speed: float       # Table 6.4's slow insertion
    timing_refs: tuple           # Table 6.5's h_ref
    nonlinear_speed: float
    nonlinear_scales: tuple      # Figure 6.12: multiples of the stand-in friction profile


FULL = Settings(fine=7, tolerance_level=7, starts=(1, 2, 3, 4, 5, 6), refs=(3, 4, 5, 6, 7),
                figure_pairs=((6, 6), (3, 6)), h_start=3, h_ref=6, speeds=SPEEDS, reference_speed=0.005,
                timing_refs=(6, 7), nonlinear_speed=0.01, nonlinear_scales=(1.0, 5.0, 10.0))
QUICK = Settings(fine=5, tolerance_level=5, starts=(1, 2, 3, 4), refs=(3, 4, 5), figure_pairs=((4, 4), (3, 4)),
                 h_start=3, h_ref=4, speeds=(3.0, 1.0, 0.3, 0.1), reference_speed=0.03, timing_refs=(4,),
                 nonlinear_speed=0.3, nonlinear_scales=(1.0,))


# --- geometry of the loaded line ------------------------------------------------------------
def unit(degrees: float) -> np.ndarray:
    return np.array([math.cos(math.radians(degrees)), math.sin(math.radians(degrees))])


def refine_along(mesh, degrees: float, h_ref: int, length: float = DEPTH) -> None:
    """§6.5 refine-around at points every h_ref/4 along the line from the entry point: every
    cell containing one of them gets edges no longer than h_ref (as the needle refines)."""
    start, direction = np.asarray(ENTRY, dtype=np.float64), unit(degrees)
    for s in np.arange(0.0, length + 1e-12, h(h_ref) / 4):
        mesh.refine_around(start + s * direction, h(h_ref))


def mesh_edges(cells: np.ndarray) -> np.ndarray:
    edges = np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]])
    return np.unique(np.sort(edges, axis=1), axis=0)


def line_nodes(mesh, degrees: float, length: float = DEPTH) -> np.ndarray:
    """The nodes a needle along the line would take (§6.4): of every edge the segment crosses,
    the end closest to the line; and every node on the segment. Sorted along the line."""
    points = mesh.points
    start, direction = np.asarray(ENTRY, dtype=np.float64), unit(degrees)
    normal = np.array([-direction[1], direction[0]])
    along, across = (points - start) @ direction, (points - start) @ normal
    tolerance = 1e-12
    on = np.abs(across) <= tolerance
    nodes = set(np.flatnonzero(on & (along >= -tolerance) & (along <= length + tolerance)).tolist())
    edges = mesh_edges(mesh.cells)
    a, b = edges[:, 0], edges[:, 1]
    crossing = (across[a] * across[b] < 0) & ~on[a] & ~on[b]
    a, b = a[crossing], b[crossing]
    t = across[a] / (across[a] - across[b])
    s = along[a] + t * (along[b] - along[a])
    inside = (s >= 0) & (s <= length)
    nearest = np.where(np.abs(across[a]) <= np.abs(across[b]), a, b)
    nodes.update(nearest[inside].tolist())
    nodes = np.fromiter(nodes, dtype=np.int64)
    return nodes[np.argsort(along[nodes], kind="stable")]


def line_forces(mesh, nodes: np.ndarray, degrees: float, profile, length: float = DEPTH) -> np.ndarray:
    """Nodal forces along the line: the profile (distance from the tip at ``length``)
    integrated over each node's share, half-way to its neighbours along the line."""
    start, direction = np.asarray(ENTRY, dtype=np.float64), unit(degrees)
    s = np.clip((mesh.points[nodes] - start) @ direction, 0.0, length)
    middle = 0.5 * (s[1:] + s[:-1])
    begin, end = np.r_[0.0, middle], np.r_[middle, length]
    magnitude = np.array([profile.integral(length - e, length - b) for b, e in zip(begin, end)])
    return magnitude[:, None] * direction[None, :]


def relocate(mesh, nodes: np.ndarray, degrees: float) -> dict:
    """Project the nodes orthogonally onto the line, one after another along it, with
    ``mesh.snap_vertex`` (target written as an affine combination of a cell of the node's
    star), which refuses a move that would make a cell of the star flat or inverted."""
    start, direction = np.asarray(ENTRY, dtype=np.float64), unit(degrees)
    distances = []
    pending = [int(v) for v in nodes]
    for _ in range(2):  # a second pass: a move refused at first may be allowed once its neighbours moved
        refused = []
        for v in pending:
            x = mesh.points[v]
            target = start + ((x - start) @ direction) * direction
            distance = float(np.linalg.norm(target - x))
            if distance <= 1e-14:
                continue
            corners = mesh.element_vertices(int(mesh.star(v)[0]))
            weights = np.linalg.solve(np.vstack([mesh.points[corners].T, np.ones(3)]), np.r_[target, 1.0])
            if mesh.snap_vertex(v, corners, weights):
                distances.append(distance)
            else:
                refused.append(v)
        pending = refused
    return {"moved": len(distances), "refused": len(pending), "max_move": max(distances, default=0.0)}


def line_load_body(h_start: int, h_ref: int | None, degrees: float = 0.0, *, relocated: bool = False,
                   uniform_refinements: int = 0, profile=None):
    """The slab (``slab_body(h_start)``), optionally bisected uniformly, refined to h_ref
    around the line, nodes optionally projected onto it, and loaded. Returns (body, nodes, info)."""
    profile = profile or snede.FrictionProfile.figure_6_4()
    body = slab_body(h_start)
    mesh = body.mesh
    if uniform_refinements:  # new vertices on the fixed side inherit the support (both parents fixed)
        mesh.refine_uniform(uniform_refinements)
    if h_ref is not None:
        refine_along(mesh, degrees, h_ref)
    nodes = line_nodes(mesh, degrees)
    info = {"moved": 0, "refused": 0, "max_move": 0.0}
    if relocated:
        info = relocate(mesh, nodes, degrees)
    body.add_nodal_force(nodes, line_forces(mesh, nodes, degrees, profile))
    return body, nodes, info


def reference_body(fine: int, degrees: float = 0.0, relocated: bool = False):
    """The reference: uniform mesh whose every cell has longest edge h_fine (slab_body(fine)
    bisected once uniformly: legs h_fine/√2), the finest mesh of the family (every mesh here
    with longest edges ≥ h_fine is nested in it)."""
    return line_load_body(fine, None, degrees, relocated=relocated, uniform_refinements=1)


def solve(body, rtol: float, label: str):
    result = snede.StaticSolver(body, "cg", preconditioner="none",
                                rtol=rtol, round_tolerance=ROUND_TOLERANCE, max_iterations=100000,
                                options_prefix=options_prefix(label)).solve()
    if not result.converged:
        raise RuntimeError(f"{label}: static solve did not converge: {result}")
    return result


# --- comparing fields on different meshes ---------------------------------------------------
class Field:
    """A P1 displacement field on a triangle mesh (reference coordinates), evaluated anywhere
    in the slab by barycentric (linear) interpolation in the cell containing the point
    (matplotlib.tri's trapezoid-map point location + LinearTriInterpolator)."""

    def __init__(self, points: np.ndarray, cells: np.ndarray, u: np.ndarray):
        import matplotlib.tri as mtri

        self.points, self.cells, self.u = points.copy(), cells.copy(), u.copy()
        self.triangulation = mtri.Triangulation(points[:, 0], points[:, 1], cells)
        finder = self.triangulation.get_trifinder()
        self.interpolators = [mtri.LinearTriInterpolator(self.triangulation, u[:, k], trifinder=finder)
                              for k in range(2)]

    @classmethod
    def of(cls, body) -> "Field":
        return cls(body.mesh.points, body.mesh.cells, body.displacement)

    def at(self, points: np.ndarray) -> np.ndarray:
        values = [interpolator(points[:, 0], points[:, 1]) for interpolator in self.interpolators]
        if any(np.ma.count_masked(v) for v in values):
            raise ValueError("a sample point lies outside the mesh")
        return np.column_stack([np.ma.getdata(v) for v in values])


def errors_mm(u: np.ndarray, reference: np.ndarray) -> tuple[float, float]:
    """Mean and maximum of |u − u_ref| over the sample points, in mm."""
    e = np.linalg.norm(u - reference, axis=1) * MM
    return float(e.mean()), float(e.max())


# --- Table 6.1 ------------------------------------------------------------------------------
def table_6_1(level: int) -> list[dict]:
    body, _, _ = line_load_body(level, level)
    reference = solve(body, REFERENCE_TOLERANCE, "t61_reference")
    u_reference = body.displacement
    rows = []
    for eps in TOLERANCES:
        body, _, _ = line_load_body(level, level)
        result = solve(body, eps, f"t61_{eps}")
        mean, largest = errors_mm(body.displacement, u_reference)
        thesis = THESIS_TABLE_6_1[eps]
        rows.append({"part": "table_6_1", "h_start": level, "h_ref": level, "nodes": body.mesh.n_points,
                     "cells": body.mesh.n_cells, "rtol": eps, "iterations": result.iterations,
                     "reference_iterations": reference.iterations, "seconds": result.seconds,
                     "mean_error_mm": mean, "max_error_mm": largest,
                     "thesis_mean_error_mm": thesis[0] if level == 7 else None,
                     "thesis_max_error_mm": thesis[1] if level == 7 else None,
                     "max_displacement_mm": float(np.linalg.norm(u_reference, axis=1).max() * MM)})
        print(f"Table 6.1 ε={eps:<6g} {result.iterations:>5} CG  mean {mean:.2e} max {largest:.2e} mm", flush=True)
    return rows


# --- Tables 6.2, 6.3, Figure 6.10 -----------------------------------------------------------
def mesh_tables(settings: Settings, reference_points, reference_u) -> tuple[list[dict], dict]:
    rows, fields = [], {}
    fine = settings.fine
    for h_start in settings.starts:
        for h_ref in settings.refs:
            if h_ref < h_start:
                continue
            body, nodes, _ = line_load_body(h_start, h_ref)
            working = solve(body, WORKING_TOLERANCE, f"t62_{h_start}_{h_ref}")
            working_errors = errors_mm(Field.of(body).at(reference_points), reference_u)
            exact = solve(body, REFERENCE_TOLERANCE, f"t63_{h_start}_{h_ref}")  # continues from the 0.01 solution
            field = Field.of(body)
            mean, largest = errors_mm(field.at(reference_points), reference_u)
            if (h_start, h_ref) in settings.figure_pairs:
                fields[(h_start, h_ref)] = field
            thesis = fine == 7
            rows.append({"part": "tables_6_2_6_3", "h_start": h_start, "h_ref": h_ref, "nodes": body.mesh.n_points,
                         "cells": body.mesh.n_cells, "loaded_nodes": len(nodes), "rtol": WORKING_TOLERANCE,
                         "iterations": working.iterations, "seconds": working.seconds,
                         "thesis_iterations": THESIS_TABLE_6_2.get((h_start, h_ref)) if thesis else None,
                         "mean_error_mm": mean, "max_error_mm": largest,
                         "mean_error_at_working_rtol_mm": working_errors[0],
                         "max_error_at_working_rtol_mm": working_errors[1],
                         "reference_iterations_1e-8": exact.iterations,
                         "thesis_mean_error_mm": THESIS_TABLE_6_3_MEAN.get((h_start, h_ref)) if thesis else None,
                         "thesis_max_error_mm": THESIS_TABLE_6_3_MAX.get((h_start, h_ref)) if thesis else None})
            print(f"Tables 6.2/6.3 h{h_start}/h{h_ref}: {body.mesh.n_points:>6} nodes {working.iterations:>4} CG  "
                  f"error mean {mean:.4f} max {largest:.4f} mm", flush=True)
    return rows, fields


# --- Tables 6.4, 6.5 ------------------------------------------------------------------------
def insert(h_start: int, h_ref: int, speed: float, *, material=None, method: str = "cg", fixed: str = "right",
           friction=None, label: str = "needle"):
    """One automated insertion to 70 mm at ``speed`` h_ref per update. Returns (body, needle,
    report, CPU seconds of the whole insertion)."""
    body = slab_body(h_start, material, fixed=fixed)
    needle = needle_for(body, h_ref, friction=friction, method=method, rtol=WORKING_TOLERANCE,
                        round_tolerance=ROUND_TOLERANCE, options_prefix=options_prefix(label))
    cpu = time.process_time()
    report = needle.insert(DEPTH, speed * h(h_ref))
    return body, needle, report, time.process_time() - cpu


def insertion_rows(settings: Settings, reference_points) -> tuple[list[dict], dict]:
    rows = []
    reference_u = None
    final = {}
    for h_ref in settings.timing_refs:
        speeds = list(settings.speeds)
        with_errors = h_ref == settings.h_ref
        if with_errors:
            speeds = [settings.reference_speed] + speeds
        for speed in speeds:
            body, needle, report, cpu = insert(settings.h_start, h_ref, speed, label=f"insert_{h_ref}_{speed}")
            row = {"part": "tables_6_4_6_5", "h_start": settings.h_start, "h_ref": h_ref, "speed": speed,
                   "reference": speed == settings.reference_speed and with_errors, "rtol": WORKING_TOLERANCE,
                   "nodes": body.mesh.n_points, "cells": body.mesh.n_cells, "needle_nodes": len(needle.needle_nodes),
                   "slipping": int((~needle.sticking).sum()), "updates": report.updates,
                   "rearrangements": report.rearrangements, "cpu_seconds": cpu, "engine_seconds": report.seconds,
                   "update_rate_hz": report.rearrangements / cpu if cpu > 0 else float("nan"),
                   "engine_update_rate_hz": report.update_rate, "mean_iterations": report.mean_iterations,
                   "max_iterations": report.max_iterations, "converged": report.converged, "reason": report.reason,
                   "max_displacement_mm": float(np.linalg.norm(body.displacement, axis=1).max() * MM)}
            thesis = THESIS_TABLE_6_5.get(h_ref, {}).get(speed) if settings.h_start == 3 else None
            if thesis:
                row.update({"thesis_cpu_seconds": thesis[0], "thesis_rearrangements": thesis[1],
                            "thesis_update_rate_hz": thesis[2], "thesis_mean_iterations": thesis[3],
                            "thesis_max_iterations": thesis[4], "rate_ratio": row["update_rate_hz"] / thesis[2]})
            if with_errors:
                u = Field.of(body).at(reference_points)
                if row["reference"]:
                    reference_u = u
                else:
                    row["mean_error_mm"], row["max_error_mm"] = errors_mm(u, reference_u)
                    if h_ref == 6 and settings.h_start == 3:
                        row["thesis_mean_error_mm"], row["thesis_max_error_mm"] = THESIS_TABLE_6_4.get(speed, (None, None))
                final[speed] = Field.of(body)
            rows.append(row)
            print(f"insertion h{settings.h_start}/h{h_ref} speed {speed:<6g}: {report}; CPU {cpu:.2f} s"
                  + (f"; error mean {row['mean_error_mm']:.3f} max {row['max_error_mm']:.3f} mm"
                     if "mean_error_mm" in row else ""), flush=True)
    return rows, final


# --- Table 6.6 ------------------------------------------------------------------------------
def haptic_row(h_ref: int, speed: float, rtol: float, h_start: int = 3, *, method: str = "cg",
               solves_per_update: int | None = 1) -> dict:
    """Table 6.5's insertion to 70 mm in the thesis's haptic loop (§6.7, §6.8.5): one solve and
    one rearrangement per update, pending rearrangements carried into the next update, and at
    70 mm updates in place until no node changes state (solves_per_update=None: every update
    relaxes until settled). CPU seconds of this process over the insertion; the update rate is
    rearrangements (solves) per CPU second, as the thesis's."""
    body = slab_body(h_start)
    needle = needle_for(body, h_ref, method=method, rtol=rtol, round_tolerance=ROUND_TOLERANCE,
                        solves_per_update=solves_per_update)
    cpu = time.process_time()
    report = needle.insert(DEPTH, speed * h(h_ref))
    cpu = time.process_time() - cpu
    row = {"part": "table_6_5", "h_start": h_start, "h_ref": h_ref, "speed": speed, "rtol": rtol,
           "cells": body.mesh.n_cells, "updates": report.updates, "rearrangements": report.rearrangements,
           "cpu_seconds": cpu, "engine_seconds": report.seconds,
           "update_rate_hz": report.rearrangements / cpu if cpu > 0 else float("nan"),
           "mean_iterations": report.mean_iterations, "max_iterations": report.max_iterations,
           "converged": report.converged, "reason": report.reason}
    thesis = THESIS_TABLE_6_5.get(h_ref, {}).get(speed) if h_start == 3 else None
    if thesis:
        row.update({"thesis_cpu_seconds": thesis[0], "thesis_rearrangements": thesis[1],
                    "thesis_update_rate_hz": thesis[2], "thesis_mean_iterations": thesis[3],
                    "thesis_max_iterations": thesis[4], "rate_ratio": row["update_rate_hz"] / thesis[2]})
    return row


def table_6_5_rows(h_refs=(6, 7), speeds=SPEEDS, tolerances=TIMING_TOLERANCES, echo=print) -> list[dict]:
    rows = []
    for rtol in tolerances:
        for h_ref in h_refs:
            for speed in speeds:
                rows.append(haptic_row(h_ref, speed, rtol))
                echo(table_6_5_line(rows[-1]))
    return rows


def cg_ratio(rows: list[dict]) -> float | None:
    """Geometric mean of our mean CG iterations over the thesis's, over the rows it has."""
    return geometric_mean([r["mean_iterations"] / r["thesis_mean_iterations"] for r in rows
                           if r.get("thesis_mean_iterations")])


def table_6_5_line(row: dict) -> str:
    return (f"| {row['rtol']:g} | h{row['h_ref']} | {row['speed']:g} | {row['updates']} | {row['cells']} | "
            f"{cell(row['cpu_seconds'], row.get('thesis_cpu_seconds'), '{:.3f}')} | "
            f"{cell(row['rearrangements'], row.get('thesis_rearrangements'), '{:.0f}')} | "
            f"{cell(row['update_rate_hz'], row.get('thesis_update_rate_hz'), '{:.0f}')} | "
            f"{cell(row.get('rate_ratio'), None, '{:.1f}×') if row.get('rate_ratio') else '–'} | "
            f"{cell(row['mean_iterations'], row.get('thesis_mean_iterations'))} | "
            f"{cell(row['max_iterations'], row.get('thesis_max_iterations'), '{:.0f}')} | "
            f"{'yes' if row['converged'] else row['reason']} |")


def table_6_5_section(rows: list[dict], command: str) -> list[str]:
    """The results page's Table 6.5 section, as lines (written by this module and by
    studies/benchmarks/needle_rates.py --markdown)."""
    template = PageTemplate("needle")
    text = template.snippet("table_6_5", rate_goal=UPDATE_RATE_GOAL, issue_rtol=ISSUE_TOLERANCE,
                            h7_goal=H7_RATE_GOAL_HZ, thesis_cg_rtol=THESIS_CG_TOLERANCE, command=command,
                            t65_table="\n".join([template.snippet("t65_header")] + [table_6_5_line(row) for row in rows]),
                            rate_note=rate_note(rows, template))
    return text.split("\n") + [""]


def replace_table_6_5(page: str, section: list[str]) -> str:
    """The page with its Table 6.5 section (up to the next '## ') replaced."""
    start = page.index("## Table 6.5")
    end = page.index("\n## ", start) + 1
    return page[:start] + "\n".join(section) + "\n" + page[end:]


def table_6_6(settings: Settings) -> list[dict]:
    degrees = TILT_DEGREES
    results = {}
    for relocated in (False, True):
        body, nodes, info = reference_body(settings.fine, degrees, relocated)
        solve(body, REFERENCE_TOLERANCE, f"t66_reference_{relocated}")
        results[("reference", relocated)] = (body, nodes, info)
        body, nodes, info = line_load_body(settings.h_start, settings.h_ref, degrees, relocated=relocated)
        solve(body, REFERENCE_TOLERANCE, f"t66_{relocated}")
        results[("coarse", relocated)] = (body, nodes, info)
    reference, _, _ = results[("reference", True)]
    points = reference.mesh.points
    reference_max = float(np.linalg.norm(reference.displacement, axis=1).max() * MM)
    u = {key: Field.of(value[0]).at(points) for key, value in results.items()}
    direction = unit(degrees)
    normal = np.array([-direction[1], direction[0]])

    def off_line(key):
        body, nodes, _ = results[key]
        return float(np.abs((body.mesh.points[nodes] - np.asarray(ENTRY)) @ normal).max())

    comparisons = [
        ("relocation_vs_none", "with relocation vs. without", ("coarse", True), ("coarse", False)),
        ("with_relocation", "discretisation error with relocation", ("coarse", True), ("reference", True)),
        ("without_relocation", "discretisation error without relocation", ("coarse", False), ("reference", True)),
        ("reference_relocation_vs_none", f"reference (h{settings.fine}) with relocation vs. without",
         ("reference", False), ("reference", True)),
    ]
    rows = []
    thesis = settings.h_start == 3 and settings.h_ref == 6 and settings.fine == 7
    for key, label, a, b in comparisons:
        mean, largest = errors_mm(u[a], u[b])
        body, nodes, info = results[a]
        rows.append({"part": "table_6_6", "comparison": key, "label": label, "degrees": degrees,
                     "h_start": settings.h_start, "h_ref": settings.h_ref, "fine": settings.fine,
                     "mean_error_mm": mean, "max_error_mm": largest,
                     "thesis_mean_error_mm": THESIS_TABLE_6_6[key][0] if thesis and key in THESIS_TABLE_6_6 else None,
                     "thesis_max_error_mm": THESIS_TABLE_6_6[key][1] if thesis and key in THESIS_TABLE_6_6 else None,
                     "reference_max_displacement_mm": reference_max,
                     "loaded_nodes": len(nodes), "relocated": info["moved"], "refused": info["refused"],
                     "max_move_mm": info["max_move"] * MM, "max_offset_from_line_mm": off_line(a) * MM})
        print(f"Table 6.6 {label}: mean {mean:.4f} max {largest:.4f} mm", flush=True)
    for key, (body, nodes, info) in results.items():
        rows[0].setdefault("details", "")
        rows[0]["details"] += (f"{key[0]} {'relocated' if key[1] else 'as meshed'}: {len(nodes)} loaded nodes, "
                               f"{info['moved']} moved (≤ {info['max_move'] * MM:.3f} mm), {info['refused']} refused, "
                               f"max off line {off_line(key) * MM:.3f} mm; ")
    return rows


# --- Figure 6.12 ----------------------------------------------------------------------------
def reference_locations(body, deformed_points: np.ndarray) -> np.ndarray:
    """The reference positions of the material points at the given deformed positions: find a
    deformed cell containing each (barycentric coordinates all ≥ −1e-9; of several, the one it
    is deepest inside) and map the barycentric coordinates back to the reference cell. NaN
    where a point is outside the deformed body. A brute-force search (a few hundred points),
    which unlike a trapezoid map also works on a deformed mesh that overlaps itself."""
    points, cells = body.mesh.points, body.mesh.cells
    deformed = points + body.displacement
    queries = np.atleast_2d(np.asarray(deformed_points, dtype=np.float64))
    origin = deformed[cells[:, 0]]
    edges = np.stack([deformed[cells[:, 1]] - origin, deformed[cells[:, 2]] - origin], axis=2)  # (n, 2, 2)
    determinant = edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0]
    usable = np.abs(determinant) > 0
    inverse = np.zeros_like(edges)
    inverse[usable] = np.linalg.inv(edges[usable])
    result = np.full(queries.shape, np.nan)
    for k, query in enumerate(queries):
        local = np.einsum("nij,nj->ni", inverse, query - origin)
        weights = np.column_stack([1.0 - local.sum(axis=1), local])
        depth = np.where(usable, weights.min(axis=1), -np.inf)
        best = int(np.argmax(depth))
        if depth[best] >= -1e-9:
            result[k] = weights[best] @ points[cells[best]]
    return result


def tip_reference_location(body, tip: np.ndarray) -> np.ndarray | None:
    """The reference position of the material point under the deformed tip."""
    location = reference_locations(body, tip)[0]
    return None if np.isnan(location).any() else location


def nonlinear_rows(settings: Settings) -> tuple[list[dict], dict]:
    rows, states = [], {}
    materials = {"LinearElastic": (lambda: snede.LinearElastic(YOUNG, 0.0), "cg"),
                 "NeoHookean": (lambda: snede.NeoHookean(YOUNG, 0.0), "newton")}
    for scale in settings.nonlinear_scales:
        profile = snede.FrictionProfile.figure_6_4(scale)
        for name, (make, method) in materials.items():
            body, needle, report, cpu = insert(settings.h_start, settings.h_ref, settings.nonlinear_speed,
                                               material=make(), method=method, fixed="bottom", friction=profile,
                                               label=f"fig612_{name}_{scale}")
            nodes = needle.needle_nodes
            points, u = body.mesh.points, body.displacement
            last = nodes[np.argmax(needle.d_needle)]
            exact = tip_reference_location(body, needle.tip)
            shaft = needle.entry + np.linspace(0.0, needle.depth, 200)[:, None] * needle.direction
            shaft = reference_locations(body, shaft)
            shaft = shaft[~np.isnan(shaft).any(axis=1)]  # the part of the shaft inside the body
            rows.append({"part": "figure_6_12", "scale": scale, "material": name, "method": method,
                         "h_start": settings.h_start, "h_ref": settings.h_ref, "speed": settings.nonlinear_speed,
                         "rtol": WORKING_TOLERANCE, "nodes": body.mesh.n_points, "updates": report.updates,
                         "rearrangements": report.rearrangements, "cpu_seconds": cpu,
                         "mean_iterations": report.mean_iterations, "max_iterations": report.max_iterations,
                         "converged": report.converged, "reason": report.reason,
                         "max_displacement_mm": float(np.linalg.norm(u, axis=1).max() * MM),
                         "inverted_elements": len(body.inverted_elements(u)),
                         "tip_x": needle.tip[0], "tip_y": needle.tip[1],
                         "tip_reference_x": None if exact is None else exact[0],
                         "tip_reference_y": None if exact is None else exact[1],
                         "tip_node_reference_x": points[last, 0], "tip_node_reference_y": points[last, 1],
                         "shaft_reference_y_min_mm": float(shaft[:, 1].min() * MM),
                         "shaft_reference_y_max_mm": float(shaft[:, 1].max() * MM)})
            states[(scale, name)] = {"points": points, "cells": body.mesh.cells, "u": u, "nodes": nodes,
                                     "sticking": needle.sticking, "tip": needle.tip, "entry": needle.entry,
                                     "tip_reference": exact, "tip_node": points[last], "shaft": shaft}
            print(f"Figure 6.12 ×{scale:g} {name}: {report}; CPU {cpu:.1f} s; tip reference "
                  f"{exact}, tip node {points[last]}", flush=True)
        linear, neo = rows[-2], rows[-1]
        for row in (linear, neo):
            row["tip_reference_distance_mm"] = (math.hypot(neo["tip_reference_x"] - linear["tip_reference_x"],
                                                           neo["tip_reference_y"] - linear["tip_reference_y"]) * MM
                                                if neo["tip_reference_x"] is not None
                                                and linear["tip_reference_x"] is not None else None)
            row["tip_node_distance_mm"] = math.hypot(neo["tip_node_reference_x"] - linear["tip_node_reference_x"],
                                                     neo["tip_node_reference_y"] - linear["tip_node_reference_y"]) * MM
            row["thesis_tip_distance_mm"] = THESIS_TIP_DISTANCE_MM
    return rows, states


# --- pictures -------------------------------------------------------------------------------
def plot_errors(fields: dict, reference: Field, path: Path) -> None:
    """Figure 6.10: |u − u_ref| at the reference vertices, with the coarser mesh drawn over it."""
    plt = pyplot()
    pairs = sorted(fields, key=lambda pair: -pair[0])
    errors = {pair: np.linalg.norm(fields[pair].at(reference.points) - reference.u, axis=1) * MM for pair in pairs}
    top = max(e.max() for e in errors.values())
    figure, axes = plt.subplots(1, len(pairs), figsize=(5.6 * len(pairs), 5.0), squeeze=False)
    for ax, pair in zip(axes[0], pairs):
        field = fields[pair]
        shaded = ax.tripcolor(reference.triangulation, errors[pair], shading="gouraud", cmap="magma_r", vmin=0, vmax=top)
        ax.triplot(field.triangulation, color="0.35", linewidth=0.25)
        ax.plot([ENTRY[0], ENTRY[0] + DEPTH], [ENTRY[1]] * 2, color="C0", linewidth=1.5, label="load line")
        ax.plot([SIZE, SIZE], [0, SIZE], color="k", linewidth=4, label="fixed")
        ax.set_title(f"h_start = h{pair[0]}, h_ref = h{pair[1]}: mean {errors[pair].mean():.3f}, "
                     f"max {errors[pair].max():.3f} mm", fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.legend(loc="lower left", fontsize=7)
    figure.colorbar(shaded, ax=axes[0].tolist(), label="displacement error |u − u_ref| [mm]", shrink=0.85)
    figure.suptitle("Figure 6.10: displacement error against the uniform reference (static line load)", fontsize=10)
    figure.savefig(path, dpi=100)
    plt.close(figure)


def plot_rates(rows: list[dict], path: Path) -> None:
    plt = pyplot()
    figure, axes = plt.subplots(figsize=(6.4, 4.4))
    for k, h_ref in enumerate(sorted({row["h_ref"] for row in rows})):
        for rtol, marker in zip(sorted({row["rtol"] for row in rows}), ("o-", "^-.")):
            runs = sorted((row for row in rows if row["h_ref"] == h_ref and row["rtol"] == rtol),
                          key=lambda r: r["speed"])
            axes.loglog([r["speed"] for r in runs], [r["update_rate_hz"] for r in runs], marker, color=f"C{k}",
                        label=f"snede, h_ref = h{h_ref}, ε = {rtol:g}")
        thesis = THESIS_TABLE_6_5.get(h_ref)
        if thesis:
            speeds = sorted(thesis)
            axes.loglog(speeds, [thesis[s][2] for s in speeds], "s--", color=f"C{k}", mfc="none",
                        label=f"thesis Table 6.5, h_ref = h{h_ref}")
            axes.loglog(speeds, [UPDATE_RATE_GOAL * thesis[s][2] for s in speeds], ":", color=f"C{k}", linewidth=1,
                        label=f"goal: {UPDATE_RATE_GOAL:g} × thesis, h_ref = h{h_ref}")
    axes.set_xlabel("insertion speed [h_ref per update]")
    axes.set_ylabel("update rate [rearrangements per CPU second]")
    axes.grid(True, which="both", color="0.9")
    axes.legend(fontsize=8)
    axes.set_title("Table 6.5: update rates (h_start = h3)", fontsize=10)
    save_figure(figure, path, 130)


def plot_nonlinear(states: dict, scale: float, path: Path) -> None:
    """Figure 6.12: deformed (left) and reference (right) configurations, needle nodes marked."""
    plt = pyplot()
    names = [name for (s, name) in states if s == scale]
    figure, axes = plt.subplots(len(names), 2, figsize=(10, 5 * len(names)), squeeze=False)
    tips = {name: states[(scale, name)]["tip_reference"] for name in names}
    for row, name in zip(axes, names):
        state = states[(scale, name)]
        points, cells, u, nodes = state["points"], state["cells"], state["u"], state["nodes"]
        deformed = points + u
        stick = state["sticking"]
        ax = row[0]
        ax.triplot(deformed[:, 0], deformed[:, 1], cells, color="0.6", linewidth=0.3)
        ax.plot([state["entry"][0] - 0.01, state["tip"][0]], [state["entry"][1] - 0.0, state["tip"][1]], color="k",
                linewidth=1.2, label="needle")
        ax.plot(deformed[nodes[stick], 0], deformed[nodes[stick], 1], "o", ms=3, color="C3", label="sticking node")
        ax.plot(deformed[nodes[~stick], 0], deformed[nodes[~stick], 1], "o", ms=3, color="C0", label="slipping node")
        ax.set_title(f"{name}: deformed", fontsize=10)
        ax = row[1]
        ax.triplot(points[:, 0], points[:, 1], cells, color="0.6", linewidth=0.3)
        ax.plot(state["shaft"][:, 0], state["shaft"][:, 1], color="k", linewidth=1.2,
                label="material points on the shaft")
        ax.plot(points[nodes, 0], points[nodes, 1], "o", ms=3, color="C2", label="needle nodes (reference)")
        for k, (other, location) in enumerate(tips.items()):
            if location is not None:
                ax.plot(*location, "*", ms=11, color=("C1", "C4")[k % 2], mec="k" if other == name else "none",
                        label=f"tip's reference location ({other}{', this run' if other == name else ''})")
        ax.set_title(f"{name}: reference", fontsize=10)
        low = np.minimum(deformed.min(axis=0), points.min(axis=0))
        high = np.maximum(deformed.max(axis=0), points.max(axis=0))
        for ax in row:
            ax.plot([low[0] - 0.01, high[0] + 0.01], [0, 0], color="k", linewidth=4)
            ax.set_aspect("equal")
            ax.set_xlim(min(low[0], state["entry"][0] - 0.01) - 0.005, high[0] + 0.005)
            ax.set_ylim(-0.005, high[1] + 0.025)
            ax.legend(loc="upper right", fontsize=7)
    figure.suptitle(f"Figure 6.12: sideways insertion into a slab fixed at the bottom, ν = 0 "
                    f"(friction profile ×{scale:g})", fontsize=11)
    save_figure(figure, path, 110)


# --- the results page -----------------------------------------------------------------------
def cell(ours, thesis, spec="{:.2f}") -> str:
    text = spec.format(ours) if ours is not None else "–"
    return text + (f" ({spec.format(thesis)})" if thesis is not None else "")


def ratio(a, b):
    return a / b if a is not None and b not in (None, 0) else None


def grid_table(rows: list[dict], settings: Settings, key: str, thesis_key: str, spec: str) -> str:
    header = "| ↓ h_start / h_ref → | " + " | ".join(f"h{r}" for r in settings.refs) + " |"
    lines = [header, "|" + "---|" * (len(settings.refs) + 1)]
    for h_start in settings.starts:
        cells = []
        for h_ref in settings.refs:
            row = next((r for r in rows if r["h_start"] == h_start and r["h_ref"] == h_ref), None)
            cells.append(cell(row[key], row[thesis_key], spec) if row else "")
        lines.append(f"| h{h_start} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def geometric_mean(values) -> float | None:
    values = [v for v in values if v is not None and v > 0 and np.isfinite(v)]
    return float(np.exp(np.mean(np.log(values)))) if values else None


def describe(settings: Settings, quick: bool, minutes: float, results: dict) -> str:
    """needle.md: studies/templates/needle.md filled with the tables and notes of §6.8."""
    template = PageTemplate("needle")
    snippet = template.snippet
    t61, mesh_rows, insertion, t66, nonlinear = (results[k] for k in ("table_6_1", "tables_6_2_6_3", "insertion",
                                                                      "table_6_6", "figure_6_12"))
    reference = results["reference"]
    values = dict(
        quick_flag=" --quick" if quick else "", minutes=minutes, load_start=results["load_average"][0],
        load_end=results["load_average"][1], quick_note=snippet("quick_note") if quick else "",
        profile_force=snede.FrictionProfile.figure_6_4().integral(0, DEPTH),
        max_displacement=reference["max_displacement_mm"], fine=settings.fine, reference_nodes=reference["nodes"],
        reference_cells=reference["cells"], reference_rtol=REFERENCE_TOLERANCE, round_tolerance=ROUND_TOLERANCE,
        working_rtol=WORKING_TOLERANCE, issue_rtol=ISSUE_TOLERANCE, thesis_cg_rtol=THESIS_CG_TOLERANCE,
        h_start=settings.h_start, h_ref=settings.h_ref)

    # Table 6.1
    thesis61 = settings.tolerance_level == 7
    rows61 = [f"| {row['rtol']:g} | {row['iterations']} | {row['mean_error_mm']:.2g} | "
              f"{cell(row['thesis_mean_error_mm'], None, '{:g}') if thesis61 else '–'} | "
              f"{cell(ratio(row['mean_error_mm'], row['thesis_mean_error_mm']), None) if thesis61 else '–'} | "
              f"{row['max_error_mm']:.2g} | "
              f"{cell(row['thesis_max_error_mm'], None, '{:g}') if thesis61 else '–'} | "
              f"{cell(ratio(row['max_error_mm'], row['thesis_max_error_mm']), None) if thesis61 else '–'} |"
              for row in t61]
    means = [row["mean_error_mm"] for row in t61]
    values.update(
        tolerance_level=settings.tolerance_level, t61_nodes=t61[0]["nodes"],
        t61_reference_iterations=t61[0]["reference_iterations"],
        t61_not_shown="" if thesis61 else snippet("t61_not_shown"), t61_table="\n".join([snippet("t61_header")] + rows61),
        t61_falls=snippet("falls_every_step" if all(b < a for a, b in zip(means, means[1:])) else "falls_overall"),
        mean_first=means[0], rtol_first=t61[0]["rtol"], mean_last=means[-1], rtol_last=t61[-1]["rtol"],
        slope=slope(t61), proportion=snippet("in_proportion" if 0.8 <= slope(t61) <= 1.25 else
                                             "slower_than_proportion" if slope(t61) < 0.8 else
                                             "faster_than_proportion"),
        mean_at_001=t61[3]["mean_error_mm"])

    # Tables 6.2 and 6.3
    thesis = settings.fine == 7
    t62_ratio = t63_ratio = ""
    if thesis:
        r62 = [ratio(r["iterations"], r["thesis_iterations"]) for r in mesh_rows]
        t62_ratio = snippet("t62_ratio", mean=geometric_mean(r62), low=min(x for x in r62 if x),
                            high=max(x for x in r62 if x))
        rm = [ratio(r["mean_error_mm"], r["thesis_mean_error_mm"]) for r in mesh_rows if r["thesis_mean_error_mm"]]
        rx = [ratio(r["max_error_mm"], r["thesis_max_error_mm"]) for r in mesh_rows if r["thesis_max_error_mm"]]
        t63_ratio = snippet("t63_ratio", mean=geometric_mean(rm), max=geometric_mean(rx))
    pair = next((r for r in mesh_rows if (r["h_start"], r["h_ref"]) == (settings.h_start, settings.h_ref)), None)
    values.update(
        t62_not_shown="" if thesis else snippet("t62_not_shown"),
        t62_table=grid_table(mesh_rows, settings, "iterations", "thesis_iterations", "{:.0f}"), t62_ratio=t62_ratio,
        t62_exceptions="" if monotone_iterations(mesh_rows) else snippet("t62_exceptions"),
        change_mean=max(abs(r["mean_error_at_working_rtol_mm"] - r["mean_error_mm"]) for r in mesh_rows),
        change_max=max(abs(r["max_error_at_working_rtol_mm"] - r["max_error_mm"]) for r in mesh_rows),
        t63_mean=grid_table(mesh_rows, settings, "mean_error_mm", "thesis_mean_error_mm", "{:.3f}"),
        t63_max=grid_table(mesh_rows, settings, "max_error_mm", "thesis_max_error_mm", "{:.3f}"), t63_ratio=t63_ratio,
        t63_pair=snippet("t63_pair", pair=pair) if pair else "", monotone=monotone_notes(mesh_rows, settings, template),
        figure_pairs=" and ".join(f"(h{a}, h{b})" for a, b in settings.figure_pairs))

    # Tables 6.4 and 6.5
    errors = [r for r in insertion if "mean_error_mm" in r]
    reference_run = next(r for r in insertion if r["reference"])
    rows64 = []
    for row in errors:
        tm, tx = row.get("thesis_mean_error_mm"), row.get("thesis_max_error_mm")
        rows64.append(f"| {row['speed']:g} | {row['mean_error_mm']:.3f} | {cell(tm, None, '{:g}') if tm else '–'} | "
                      f"{cell(ratio(row['mean_error_mm'], tm), None) if tm else '–'} | {row['max_error_mm']:.3f} | "
                      f"{cell(tx, None, '{:g}') if tx else '–'} | "
                      f"{cell(ratio(row['max_error_mm'], tx), None) if tx else '–'} |")
    values.update(
        reference_speed=settings.reference_speed, reference_updates=reference_run["updates"],
        reference_rearrangements=reference_run["rearrangements"], reference_cpu=reference_run["cpu_seconds"],
        thesis_reference_speed=snippet("thesis_reference_speed")
        if settings.reference_speed == THESIS_TABLE_6_4_REFERENCE_SPEED else "",
        t64_table="\n".join([snippet("t64_header")] + rows64),
        t64_discretisation=snippet("t64_discretisation", pair=pair, thesis_mean=THESIS_TABLE_6_4_DISCRETISATION[0],
                                   thesis_max=THESIS_TABLE_6_4_DISCRETISATION[1]) if pair else "",
        speed_note=speed_note(errors, pair, template),
        table_6_5="\n".join(table_6_5_section(results["table_6_5"], "python -m studies.experiments.needle"
                                              + (" --quick" if quick else ""))))

    # Table 6.6
    values.update(
        tilt=TILT_DEGREES,
        t66_table="\n".join([snippet("t66_header")] + [
            f"| {row['label']} | {row['mean_error_mm']:.3f} | "
            f"{cell(row['thesis_mean_error_mm'], None, '{:g}') if row['thesis_mean_error_mm'] else '–'} | "
            f"{row['max_error_mm']:.3f} | "
            f"{cell(row['thesis_max_error_mm'], None, '{:g}') if row['thesis_max_error_mm'] else '–'} |" for row in t66]),
        t66_nodes=t66[0]["details"].rstrip("; "),
        conformance=conformance_note(t66, reference["max_displacement_mm"], template))

    # Figure 6.12
    rows612 = []
    for row in nonlinear:
        exact = ("–" if row["tip_reference_x"] is None
                 else f"({row['tip_reference_x'] * MM:.2f}, {row['tip_reference_y'] * MM:.2f})")
        rows612.append(f"| {row['scale']:g} | {row['material']} | {row['updates']} | {row['rearrangements']} | "
                       f"{row['cpu_seconds']:.1f} | {row['mean_iterations']:.1f} / {row['max_iterations']} | "
                       f"{row['max_displacement_mm']:.1f} | {exact} | ({row['tip_node_reference_x'] * MM:.2f}, "
                       f"{row['tip_node_reference_y'] * MM:.2f}) | {'yes' if row['converged'] else row['reason']} |")
    failed = ([snippet("failed_insertion", row=r) for r in insertion + results["table_6_5"] if not r["converged"]]
              + [snippet("failed_nonlinear", row=r) for r in nonlinear if not r["converged"]])
    values.update(
        nonlinear_speed=settings.nonlinear_speed,
        nonlinear_speed_note=snippet("thesis_speed" if settings.nonlinear_speed == 0.01 else "coarser_speed"),
        nonlinear_table="\n".join([snippet("nonlinear_header")] + rows612), nonlinear_note=nonlinear_note(nonlinear, template),
        nonlinear_images="\n\n".join(snippet("nonlinear_image", scale=scale, file=nonlinear_png(scale))
                                      for scale in settings.nonlinear_scales),
        failed="; ".join(failed) if failed else snippet("none"))
    return template.page(**values)


def slope(rows) -> float:
    """Least-squares slope of log(mean error) against log ε."""
    return float(np.polyfit(np.log([r["rtol"] for r in rows]), np.log([r["mean_error_mm"] for r in rows]), 1)[0])


def monotone_iterations(rows) -> bool:
    by = {(r["h_start"], r["h_ref"]): r["iterations"] for r in rows}
    return all(by[(a, b)] <= by[(a, b2)] for (a, b) in by for (a2, b2) in by if a2 == a and b2 > b) and \
        all(by[(a, b)] <= by[(a2, b)] for (a, b) in by for (a2, b2) in by if b2 == b and a2 > a)


def monotone_notes(rows, settings, template: PageTemplate) -> str:
    by = {(r["h_start"], r["h_ref"]): r["mean_error_mm"] for r in rows}
    rises = [(f"h{a}/h{b} → h{a}/h{b + 1}", by[(a, b + 1)] - by[(a, b)]) for (a, b) in by
             if (a, b + 1) in by and by[(a, b + 1)] > by[(a, b)]]
    rises += [(f"h{a}/h{b} → h{a + 1}/h{b}", by[(a + 1, b)] - by[(a, b)]) for (a, b) in by
              if (a + 1, b) in by and by[(a + 1, b)] > by[(a, b)]]
    paragraphs = [template.snippet("not_monotone", largest=max(d for _, d in rises),
                                   steps=", ".join(name for name, _ in rises)) if rises else
                  template.snippet("monotone")]
    first, last = settings.refs[0], settings.refs[-1]
    gains = [(a, by[(a, b)], by[(a, last)]) for a in settings.starts for b in (max(first, a + 1),)
             if (a, b) in by and (a, last) in by and b < last]
    if gains:
        paragraphs.append(template.snippet("mean_flat", last=last,
                                           gains="; ".join(f"h{a}: {x:.3f} → {y:.3f} mm" for a, x, y in gains)))
    return "\n\n".join(paragraphs)


def speed_note(errors, pair, template: PageTemplate) -> str:
    if not errors:
        return ""
    monotone = all(b["mean_error_mm"] <= a["mean_error_mm"] for a, b in zip(errors, errors[1:]))
    sentences = [template.snippet("trend", fastest=errors[0], slowest=errors[-1],
                                  worst=max(errors, key=lambda r: r["mean_error_mm"])),
                 template.snippet("falls_with_speed" if monotone else "no_clear_trend")]
    if pair:
        below = [r for r in errors if r["speed"] < 1.0]
        if below:
            sentences.append(template.snippet("below_one",
                                              ratio=max(r["mean_error_mm"] for r in below) / pair["mean_error_mm"]))
    return " ".join(sentences)


def rate_note(rows, template: PageTemplate) -> str:
    snippet = template.snippet
    texts = []
    for rtol in sorted({r["rtol"] for r in rows}):
        timed = [r for r in rows if r["rtol"] == rtol and r.get("rate_ratio")]
        if not timed:
            continue
        ratios = [r["rate_ratio"] for r in timed]
        h7 = [r["update_rate_hz"] for r in rows if r["rtol"] == rtol and r["h_ref"] == 7]
        per_solve = [1e6 * r["cpu_seconds"] / r["rearrangements"] for r in timed]
        texts.append(snippet(
            "rate", rtol=rtol, low=min(ratios), high=max(ratios), mean=geometric_mean(ratios),
            goal=snippet("rate_goal", goal=UPDATE_RATE_GOAL,
                         met=snippet("met" if min(ratios) >= UPDATE_RATE_GOAL else "not_met"))
            if rtol == ISSUE_TOLERANCE else "",
            h7=snippet("h7_rates", low=min(h7), high=max(h7), goal=H7_RATE_GOAL_HZ,
                       met=snippet("h7_met" if min(h7) >= H7_RATE_GOAL_HZ else "h7_not_met")) if h7 else "",
            worst=min(timed, key=lambda r: r["rate_ratio"]), best=max(timed, key=lambda r: r["rate_ratio"]),
            cg=cg_ratio(timed), cpu_low=min(per_solve), cpu_high=max(per_solve)))
    if not texts:
        return snippet("no_thesis_rates")
    texts.append(snippet("time_goes"))
    return " ".join(texts)


def conformance_note(rows, straight_max_mm: float, template: PageTemplate) -> str:
    by = {r["comparison"]: r for r in rows}
    a, w, wo = by["relocation_vs_none"], by["with_relocation"], by["without_relocation"]
    smaller = a["mean_error_mm"] < min(w["mean_error_mm"], wo["mean_error_mm"])
    return template.snippet(
        "conformance", verdict=template.snippet("relocation_smaller" if smaller else "relocation_not_smaller",
                                                a=a, w=w, wo=wo),
        reference=by["reference_relocation_vs_none"]["mean_error_mm"], tilted=a["reference_max_displacement_mm"],
        straight=straight_max_mm)


def nonlinear_note(rows, template: PageTemplate) -> str:
    snippet = template.snippet
    distances = []
    for scale in sorted({r["scale"] for r in rows}):
        pair = [r for r in rows if r["scale"] == scale]
        distance = pair[0]["tip_reference_distance_mm"]
        distances.append(snippet("scale_distance", scale=scale, largest=max(r["max_displacement_mm"] for r in pair),
                                 distance=f"{distance:.1f} mm" if distance is not None else snippet("not_found"),
                                 node=pair[0]["tip_node_distance_mm"]))
    largest = max((r["tip_reference_distance_mm"] for r in rows if r["tip_reference_distance_mm"] is not None),
                  default=float("nan"))
    if largest < 0.5 * THESIS_TIP_DISTANCE_MM:
        verdict = snippet("distance_short", largest=largest, why=snippet("why"),
                          scaled=snippet("even_scaled") if len({r["scale"] for r in rows}) > 1 else ".")
    else:
        verdict = snippet("distance_close", largest=largest, why=snippet("why"))
    shafts = " ".join(snippet("shaft_row", material=r["material"], scale=r["scale"],
                              y_min=r["shaft_reference_y_min_mm"], y_max=r["shaft_reference_y_max_mm"],
                              x=f"{r['tip_reference_x'] * MM:.1f} mm" if r["tip_reference_x"] is not None else "–")
                      for r in rows)
    return "\n\n".join([snippet("distances", thesis=THESIS_TIP_DISTANCE_MM, distances="; ".join(distances)), verdict,
                         snippet("shaft_summary", rows=shafts)])


def nonlinear_png(scale: float) -> str:
    return "needle_nonlinear.png" if scale == 1.0 else f"needle_nonlinear_x{scale:g}.png"


def main(argv=None) -> dict:
    start = time.perf_counter()
    arguments = parse_arguments(__doc__, argv)
    settings = QUICK if arguments.quick else FULL
    load_before = os.getloadavg()[0]
    out = arguments.out

    reference, _, _ = reference_body(settings.fine)
    reference_result = solve(reference, REFERENCE_TOLERANCE, "reference")
    reference_field = Field.of(reference)
    reference_points = reference.mesh.points
    reference_row = {"part": "reference", "h_start": settings.fine, "uniform_refinements": 1,
                     "nodes": reference.mesh.n_points, "cells": reference.mesh.n_cells,
                     "rtol": REFERENCE_TOLERANCE, "iterations": reference_result.iterations,
                     "seconds": reference_result.seconds,
                     "max_displacement_mm": float(np.linalg.norm(reference.displacement, axis=1).max() * MM)}
    print(f"reference uniform h{settings.fine}: {reference.mesh.n_points} nodes, {reference_result}", flush=True)

    t61 = table_6_1(settings.tolerance_level)
    mesh_rows, fields = mesh_tables(settings, reference_points, reference_field.u)
    plot_errors(fields, reference_field, out / "needle_errors.png")
    insertion, _ = insertion_rows(settings, reference_points)
    timing = table_6_5_rows(settings.timing_refs, settings.speeds)
    plot_rates(timing, out / "needle_rates.png")
    t66 = table_6_6(settings)
    nonlinear, states = nonlinear_rows(settings)
    for scale in settings.nonlinear_scales:
        plot_nonlinear(states, scale, out / nonlinear_png(scale))

    results = {"settings": settings, "reference": reference_row, "table_6_1": t61, "tables_6_2_6_3": mesh_rows,
               "insertion": insertion, "table_6_5": timing, "table_6_6": t66, "figure_6_12": nonlinear}
    write_csv(out / "needle.csv", [reference_row] + t61 + mesh_rows + insertion + timing + t66 + nonlinear)
    minutes = (time.perf_counter() - start) / 60
    results["load_average"] = (load_before, os.getloadavg()[0])
    (out / "needle.md").write_text(describe(settings, arguments.quick, minutes, results))
    print(f"wrote {out / 'needle.md'}, needle.csv and the PNGs ({minutes:.1f} min)")
    return results


if __name__ == "__main__":
    main()
