"""§6.8 needle insertion: Tables 6.1–6.6 and Figures 6.10 and 6.12 of the thesis.

    .venv/bin/python -m studies.experiments.needle [--quick] [--out DIR]

The §6.8.1 slab (snede.scenes.needle_slab: 0.1 × 0.1 × 0.01 m, E = 34 kPa, ν = 0.34, fixed at
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
from studies.experiments.common import options_prefix, parse_arguments, pyplot, write_csv
from snede.scenes.needle_slab import DEPTH, ENTRY, SIZE, YOUNG, h, needle_for, slab_body

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


TABLE_6_5_HEADER = ["| ε | h_ref | speed [h_ref/update] | updates | cells | CPU [s] | rearrangements | rate [Hz] | "
                    "rate ratio | CG mean | CG max | converged |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]


def table_6_5_section(rows: list[dict], command: str) -> list[str]:
    """The results page's Table 6.5 section (written by this module and by
    studies/benchmarks/needle_rates.py --markdown)."""
    lines = ["## Table 6.5: timings (h_start = h3)", "",
             f"The thesis's haptic loop (§6.7: `needle_for(slab_body(3), h_ref, rtol=ε, solves_per_update=1)`, one solve "
             "and one rearrangement per update, pending rearrangements carried into the next update, at 70 mm updates "
             "in place until no node changes state), linear CG without a preconditioner (the default below 1000 "
             "cells). CPU time: `time.process_time()` around `NeedleInsertion.insert`; rate = rearrangements (solves) "
             "per CPU second, as the thesis's 'updates [Hz]'. Thesis (Pentium III 1 GHz) in parentheses; 'rate "
             f"ratio' = our rate / the thesis's. Goals (issue 33): ≥ {UPDATE_RATE_GOAL:g}× in every row at ε = "
             f"{ISSUE_TOLERANCE:g}, ≥ {H7_RATE_GOAL_HZ:g} Hz at h7. ε = {THESIS_CG_TOLERANCE:g} is the ε whose CG "
             "counts are the thesis's: over the 12 rows the geometric mean of our mean CG iterations over the "
             "thesis's is 1.06 there (2.40 at 0.01, 1.53 at 0.02, 0.68 at 0.05; `studies/benchmarks/needle_rates.py --scan`). "
             "No single ε matches every row: our counts fall faster with the speed than the thesis's (at 0.03 "
             "from 2.4–2.5× the thesis's at 3 h_ref/update to 0.26–0.38× at 0.01). The thesis does not state its ε. "
             f"This section: `{command}`.", ""]
    lines += TABLE_6_5_HEADER + [table_6_5_line(row) for row in rows]
    lines += ["", rate_note(rows), "", "![update rates](needle_rates.png)", ""]
    return lines


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
    figure.tight_layout()
    figure.savefig(path, dpi=130)
    plt.close(figure)


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
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


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
    t61, mesh_rows, insertion, t66, nonlinear = (results[k] for k in ("table_6_1", "tables_6_2_6_3", "insertion",
                                                                      "table_6_6", "figure_6_12"))
    profile = snede.FrictionProfile.figure_6_4()
    reference = results["reference"]
    lines = [
        "# §6.8 needle insertion: Tables 6.1–6.6, Figures 6.10 and 6.12", "",
        "Regenerate with `.venv/bin/python -m studies.experiments.needle`" + (" --quick" if quick else "")
        + f" (this file, `needle.csv`, `needle_errors.png`, `needle_rates.png`, `needle_nonlinear*.png`; "
        f"this run: {minutes:.1f} min on the shared 2-core machine, 1-minute load average "
        f"{results['load_average'][0]:.1f} at the start and {results['load_average'][1]:.1f} at the end)."
        + (" **Quick run: smaller meshes than the thesis; thesis numbers are shown only where the set-up matches.**"
           if quick else ""), "",
        "## Set-up", "",
        f"The §6.8.1 slab of `snede.scenes.needle_slab`: 0.1 × 0.1 m, 0.01 m thick, plane stress, E = 34 kPa, "
        f"ν = 0.34, fixed at x = 0.1 m; meshes `slab_body(k)`: right triangles with legs h_k = 0.1·2^-k m.",
        "",
        "* **Friction profile: a stand-in.** The thesis's Figure 6.4 gives the shape of DiMaio and Salcudean's "
        "measured distribution but no numbers; we use `FrictionProfile.figure_6_4()` (40 N/m at the tip, a bulge of "
        f"60 N/m at 2 mm, 20 N/m of shaft friction from 10 mm on; {profile.integral(0, DEPTH):.2f} N over 70 mm). "
        "Displacements, and so absolute errors in mm, therefore differ from the thesis's: compare trends and "
        "orders of magnitude, not digits. Our static line load gives at most "
        f"{reference['max_displacement_mm']:.2f} mm of displacement.",
        "* **Element sizes.** `slab_body(h_start)` has legs h_start (longest edge √2·h_start). Refining to h_ref "
        "follows §6.5's refine-around and the needle engine: bisect until the cells containing the point have "
        "longest edge ≤ h_ref (legs h_ref/√2), at points every h_ref/4 along the line. So a refined region is half a "
        "bisection level finer than a start mesh of the same index.",
        f"* **Reference (\"uniform h{settings.fine}\")**: `slab_body({settings.fine})` bisected once uniformly, "
        f"every cell with longest edge h{settings.fine} ({reference['nodes']} nodes, {reference['cells']} cells), "
        f"solved with ε = {REFERENCE_TOLERANCE:g}. Every other mesh here (longest edges ≥ h{settings.fine}) is nested in "
        "it.",
        "* **Comparing meshes.** Displacements are compared at the vertices of the reference mesh: a coarser solution "
        "is evaluated there by barycentric interpolation in the coarse cell containing the vertex "
        "(matplotlib.tri trapezoid-map point location + `LinearTriInterpolator`, i.e. the coarse P1 field itself). "
        "'mean' and 'max' are the mean and maximum of |u − u_ref| over those vertices (area-uniform sampling), in mm.",
        f"* **Solves.** Linear CG (`snede.StaticSolver(body, \"cg\", preconditioner=\"none\", rtol=ε, round_tolerance={ROUND_TOLERANCE:g})`, "
        f"stopping criterion (6.9)). Insertions: `needle_for(slab_body(h_start), h_ref, rtol={WORKING_TOLERANCE:g}, "
        f"round_tolerance={ROUND_TOLERANCE:g})` (static friction threshold 2 × dynamic).",
        f"* **Working tolerance ε = {WORKING_TOLERANCE:g}** for Table 6.2 and the insertions of Table 6.4 and "
        "Figure 6.12: the thesis does not say which ε its Tables 6.2 and 6.5 used; ε = 0.01 reproduces its Table 6.2 "
        "CG counts best (ε = 0.001 needs about twice as many iterations on h3/h6) and costs about 0.01 mm of error "
        f"(Table 6.1). Table 6.5 is timed at ε = {ISSUE_TOLERANCE:g} and at ε = {THESIS_CG_TOLERANCE:g}, where the "
        "insertions' CG counts are the thesis's (see there).", "",
    ]

    # Table 6.1
    thesis61 = settings.tolerance_level == 7
    lines += [f"## Table 6.1: error against relaxation tolerance (h_start = h_ref = h{settings.tolerance_level})", "",
              f"Same mesh ({t61[0]['nodes']} nodes), solved from zero at each ε, compared with ε = "
              f"{REFERENCE_TOLERANCE:g} ({t61[0]['reference_iterations']} CG iterations). Thesis values in "
              "parentheses" + ("" if thesis61 else " are for h7 and not shown in a quick run") + ".", "",
              "| ε | CG iterations | mean error [mm] | thesis mean | ratio | max error [mm] | thesis max | ratio |",
              "|---|---|---|---|---|---|---|---|"]
    for row in t61:
        lines.append(f"| {row['rtol']:g} | {row['iterations']} | {row['mean_error_mm']:.2g} | "
                     f"{cell(row['thesis_mean_error_mm'], None, '{:g}') if thesis61 else '–'} | "
                     f"{cell(ratio(row['mean_error_mm'], row['thesis_mean_error_mm']), None) if thesis61 else '–'} | "
                     f"{row['max_error_mm']:.2g} | "
                     f"{cell(row['thesis_max_error_mm'], None, '{:g}') if thesis61 else '–'} | "
                     f"{cell(ratio(row['max_error_mm'], row['thesis_max_error_mm']), None) if thesis61 else '–'} |")
    means = [row["mean_error_mm"] for row in t61]
    falls = all(b < a for a, b in zip(means, means[1:]))
    lines += ["", f"**Agrees:** modest tolerances already give small errors; the error "
              + ("falls at every step" if falls else "falls overall (not at every step)")
              + f" as ε tightens, from {means[0]:.2g} mm at ε = {t61[0]['rtol']:g} to {means[-1]:.2g} mm at ε = "
              f"{t61[-1]['rtol']:g} (least-squares slope {slope(t61):.2f} on log-log axes: "
              + ("about in proportion to ε" if 0.8 <= slope(t61) <= 1.25 else
                 "slower than in proportion to ε" if slope(t61) < 0.8 else "faster than in proportion to ε")
              + "). Our errors are smaller than the thesis's by the ratios shown; our load, and so our displacements, "
              "differ from its (see the set-up), and the thesis does not give its displacements. At ε = 0.01 it is "
              f"{t61[3]['mean_error_mm']:.2g} mm mean, far below the 1 mm accuracy goal of §6.8.", ""]

    # Tables 6.2 and 6.3
    thesis = settings.fine == 7
    diagonal = [r for r in mesh_rows if r["h_start"] == r["h_ref"]]
    lines += [f"## Table 6.2: CG iterations (ε = {WORKING_TOLERANCE:g}), h_start × h_ref", "",
              "Ours, thesis in parentheses" + ("" if thesis else " (not shown: quick run)") + ".", "",
              grid_table(mesh_rows, settings, "iterations", "thesis_iterations", "{:.0f}")]
    if thesis:
        r62 = [ratio(r["iterations"], r["thesis_iterations"]) for r in mesh_rows]
        lines += [f"Ratio ours/thesis: geometric mean {geometric_mean(r62):.2f}, range "
                  f"{min(x for x in r62 if x):.2f}–{max(x for x in r62 if x):.2f}. ", ""]
    lines += ["**Agrees:** fewer iterations on coarser meshes: iterations grow with h_ref along every row and with "
              "h_start down every column" + (" (with the exceptions visible above)" if not monotone_iterations(mesh_rows)
                                             else "") + ".", ""]
    lines += [f"## Table 6.3: displacement error [mm] against uniform h{settings.fine}", "",
              f"Solutions with ε = {REFERENCE_TOLERANCE:g} (pure discretisation error; at ε = {WORKING_TOLERANCE:g} "
              "the numbers change by at most "
              f"{max(abs(r['mean_error_at_working_rtol_mm'] - r['mean_error_mm']) for r in mesh_rows):.3f} mm "
              "(mean) and "
              f"{max(abs(r['max_error_at_working_rtol_mm'] - r['max_error_mm']) for r in mesh_rows):.3f} mm (max), "
              "see needle.csv). Thesis in parentheses.", "",
              "Mean error [mm]:", "", grid_table(mesh_rows, settings, "mean_error_mm", "thesis_mean_error_mm", "{:.3f}"),
              "Maximum error [mm]:", "", grid_table(mesh_rows, settings, "max_error_mm", "thesis_max_error_mm", "{:.3f}")]
    if thesis:
        rm = [ratio(r["mean_error_mm"], r["thesis_mean_error_mm"]) for r in mesh_rows if r["thesis_mean_error_mm"]]
        rx = [ratio(r["max_error_mm"], r["thesis_max_error_mm"]) for r in mesh_rows if r["thesis_max_error_mm"]]
        lines += [f"Ratio ours/thesis (entries where the thesis is non-zero): mean errors geometric mean "
                  f"{geometric_mean(rm):.2f}, max errors {geometric_mean(rx):.2f}.", ""]
    pair = next((r for r in mesh_rows if (r["h_start"], r["h_ref"]) == (settings.h_start, settings.h_ref)), None)
    lines += ["**Agrees:** refining either h_start or h_ref lowers the error; a fine h_ref on a coarse start mesh "
              "buys most of the accuracy of a uniformly fine mesh for a fraction of its nodes"
              + (f" (h{pair['h_start']}/h{pair['h_ref']}: {pair['nodes']} nodes, mean {pair['mean_error_mm']:.3f} / "
                 f"max {pair['max_error_mm']:.3f} mm; thesis 0.10 / 0.29 mm)" if pair else "") + ". "
              "Errors are largest where the load varies (the entry point and the tip bulge) and at the corners of "
              "the fixed side (Figure 6.10).", ""]
    lines += monotone_notes(mesh_rows, settings)
    lines += ["## Figure 6.10: displacement-error fields", "",
              f"|u − u_ref| at the reference vertices for (h_start, h_ref) = "
              + " and ".join(f"(h{a}, h{b})" for a, b in settings.figure_pairs)
              + ", same colour scale, the coarse mesh drawn over it.", "", "![Figure 6.10](needle_errors.png)", ""]

    # Tables 6.4 and 6.5
    errors = [r for r in insertion if "mean_error_mm" in r]
    reference_run = next(r for r in insertion if r["reference"])
    lines += [f"## Table 6.4: error against insertion speed (h_start = h{settings.h_start}, h_ref = h{settings.h_ref})",
              "",
              f"Automated insertion to 70 mm, advancing speed × h_ref per update (each update relaxes and rearranges "
              f"until no needle node changes state), compared with the slow insertion at {settings.reference_speed:g} "
              f"h_ref per update ({reference_run['updates']} updates, {reference_run['rearrangements']} "
              f"rearrangements, {reference_run['cpu_seconds']:.1f} s)"
              + (" — the thesis's reference speed" if settings.reference_speed == THESIS_TABLE_6_4_REFERENCE_SPEED
                 else "") + f", on the uniform h{settings.fine} vertices.", "",
              "| speed [h_ref/update] | mean error [mm] | thesis mean | ratio | max error [mm] | thesis max | ratio |",
              "|---|---|---|---|---|---|---|"]
    for row in errors:
        tm, tx = row.get("thesis_mean_error_mm"), row.get("thesis_max_error_mm")
        lines.append(f"| {row['speed']:g} | {row['mean_error_mm']:.3f} | {cell(tm, None, '{:g}') if tm else '–'} | "
                     f"{cell(ratio(row['mean_error_mm'], tm), None) if tm else '–'} | {row['max_error_mm']:.3f} | "
                     f"{cell(tx, None, '{:g}') if tx else '–'} | "
                     f"{cell(ratio(row['max_error_mm'], tx), None) if tx else '–'} |")
    if pair:
        lines += ["", f"Discretisation error at this resolution (Table 6.3, static load): mean {pair['mean_error_mm']:.3f}, "
                  f"max {pair['max_error_mm']:.3f} mm (thesis: {THESIS_TABLE_6_4_DISCRETISATION[0]} / "
                  f"{THESIS_TABLE_6_4_DISCRETISATION[1]} mm)."]
    lines += ["", speed_note(errors, pair), ""]

    lines += table_6_5_section(results["table_6_5"], "python -m studies.experiments.needle"
                               + (" --quick" if quick else ""))

    # Table 6.6
    lines += [f"## Table 6.6: conformance error (h_start = h{settings.h_start}, h_ref = h{settings.h_ref})", "",
              f"The static load along a line tilted {TILT_DEGREES:g}° from the entry point (0, 0.05) over 70 mm, so the "
              "'needle' does not follow mesh edges. Loaded nodes: of every edge the line crosses, the end closest to "
              "the line (the needle's rule, §6.4), plus nodes on it; forces as for the straight line, along the line, "
              "from the nodes' positions projected onto it. 'With relocation': the loaded nodes are first projected "
              "orthogonally onto the line with `mesh.snap_vertex` (which refuses a move that would flatten or invert a "
              f"cell; such nodes stay). Reference: uniform h{settings.fine} with relocation, ε = {REFERENCE_TOLERANCE:g}; "
              f"errors at its vertices.", "",
              "| comparison | mean error [mm] | thesis mean | max error [mm] | thesis max |", "|---|---|---|---|---|"]
    for row in t66:
        lines.append(f"| {row['label']} | {row['mean_error_mm']:.3f} | "
                     f"{cell(row['thesis_mean_error_mm'], None, '{:g}') if row['thesis_mean_error_mm'] else '–'} | "
                     f"{row['max_error_mm']:.3f} | "
                     f"{cell(row['thesis_max_error_mm'], None, '{:g}') if row['thesis_max_error_mm'] else '–'} |")
    lines += ["", "Nodes: " + t66[0]["details"].rstrip("; ") + ".", "",
              conformance_note(t66, reference["max_displacement_mm"]), ""]

    # Figure 6.12
    lines += [f"## Figure 6.12: nonlinearity (sideways insertion, slab fixed at the bottom, ν = 0)", "",
              f"`slab_body({settings.h_start}, material, fixed=\"bottom\")`, needle from (0, 0.05) along +x to 70 mm, "
              f"h_ref = h{settings.h_ref}, {settings.nonlinear_speed:g} h_ref per update"
              + (" (the thesis's speed)" if settings.nonlinear_speed == 0.01 else " (coarser than the thesis's 0.01)")
              + "; linear CG for `LinearElastic(34e3, 0)`, truncated Newton for `NeoHookean(34e3, 0)`. "
              "**Tip's reference location**: the reference position of the material point under the deformed tip, "
              "found by locating the tip in the deformed mesh and mapping its barycentric coordinates back to the "
              "reference cell; as a check, the reference position of the needle node furthest along the shaft.", "",
              "| friction ×| material | updates | rearrangements | CPU [s] | CG mean / max | max |u| [mm] | "
              "tip's reference location [mm] | furthest needle node, reference [mm] | converged |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for row in nonlinear:
        exact = ("–" if row["tip_reference_x"] is None
                 else f"({row['tip_reference_x'] * MM:.2f}, {row['tip_reference_y'] * MM:.2f})")
        lines.append(f"| {row['scale']:g} | {row['material']} | {row['updates']} | {row['rearrangements']} | "
                     f"{row['cpu_seconds']:.1f} | {row['mean_iterations']:.1f} / {row['max_iterations']} | "
                     f"{row['max_displacement_mm']:.1f} | {exact} | ({row['tip_node_reference_x'] * MM:.2f}, "
                     f"{row['tip_node_reference_y'] * MM:.2f}) | {'yes' if row['converged'] else row['reason']} |")
    lines += ["", nonlinear_note(nonlinear), ""]
    for scale in settings.nonlinear_scales:
        lines += [f"![Figure 6.12, friction ×{scale:g}]({nonlinear_png(scale)})", ""]
    failed = ([f"insertion h{r['h_ref']} at {r['speed']:g} (ε = {r['rtol']:g}): {r['reason']}"
               for r in insertion + results["table_6_5"] if not r["converged"]]
              + [f"Figure 6.12 {r['material']} ×{r['scale']:g}: {r['reason']}" for r in nonlinear if not r["converged"]])
    lines += ["**Did not converge:** " + ("; ".join(failed) if failed else "none") + "."]
    return "\n".join(lines) + "\n"


def slope(rows) -> float:
    """Least-squares slope of log(mean error) against log ε."""
    return float(np.polyfit(np.log([r["rtol"] for r in rows]), np.log([r["mean_error_mm"] for r in rows]), 1)[0])


def monotone_iterations(rows) -> bool:
    by = {(r["h_start"], r["h_ref"]): r["iterations"] for r in rows}
    return all(by[(a, b)] <= by[(a, b2)] for (a, b) in by for (a2, b2) in by if a2 == a and b2 > b) and \
        all(by[(a, b)] <= by[(a2, b)] for (a, b) in by for (a2, b2) in by if b2 == b and a2 > a)


def monotone_notes(rows, settings) -> list[str]:
    by = {(r["h_start"], r["h_ref"]): r["mean_error_mm"] for r in rows}
    rises = [(f"h{a}/h{b} → h{a}/h{b + 1}", by[(a, b + 1)] - by[(a, b)]) for (a, b) in by
             if (a, b + 1) in by and by[(a, b + 1)] > by[(a, b)]]
    rises += [(f"h{a}/h{b} → h{a + 1}/h{b}", by[(a + 1, b)] - by[(a, b)]) for (a, b) in by
              if (a + 1, b) in by and by[(a + 1, b)] > by[(a, b)]]
    lines = []
    if rises:
        lines += ["**Not monotone everywhere:** the mean error rises, by at most "
                  f"{max(d for _, d in rises):.4f} mm, for " + ", ".join(name for name, _ in rises)
                  + ": refining only along the line cannot remove the error of the coarse far field, and moves "
                  "the load's discretisation slightly.", ""]
    else:
        lines += ["The mean error falls with every refinement step of either h (no exceptions).", ""]
    first, last = settings.refs[0], settings.refs[-1]
    gains = [(a, by[(a, b)], by[(a, last)]) for a in settings.starts for b in (max(first, a + 1),)
             if (a, b) in by and (a, last) in by and b < last]
    if gains:
        lines += ["**Differs:** past h_ref = h_start + 1 the *mean* error hardly moves in our runs ("
                  + "; ".join(f"h{a}: {x:.3f} → {y:.3f} mm" for a, x, y in gains)
                  + f", from the first tabulated h_ref finer than h_start to h{last}), while the thesis's keeps falling with "
                  "h_ref (e.g. h3: "
                  "0.13 → 0.08 mm); the far field of the coarse start mesh dominates ours. The *maximum* error, "
                  "which sits near the line, does fall with h_ref in both.", ""]
    return lines


def speed_note(errors, pair) -> str:
    if not errors:
        return ""
    fastest, slowest = errors[0], errors[-1]
    worst = max(errors, key=lambda r: r["mean_error_mm"])
    text = (f"**Trend:** the error of the fastest insertion ({fastest['speed']:g} h_ref/update) is "
            f"{fastest['mean_error_mm']:.3f} mm mean / {fastest['max_error_mm']:.3f} mm max; the slowest "
            f"({slowest['speed']:g}) {slowest['mean_error_mm']:.3f} / {slowest['max_error_mm']:.3f} mm; the largest "
            f"mean error is at {worst['speed']:g}. ")
    monotone = all(b["mean_error_mm"] <= a["mean_error_mm"] for a, b in zip(errors, errors[1:]))
    text += ("The error falls monotonically with speed here. " if monotone else
             "As in the thesis (\"no clear trend\"), the error does not fall monotonically with speed (our "
             "reading: stick-slip is path dependent, and where each node last stuck depends on the step). ")
    if pair:
        below = [r for r in errors if r["speed"] < 1.0]
        if below:
            ratio_to_disc = max(r["mean_error_mm"] for r in below) / pair["mean_error_mm"]
            text += (f"Below 1 h_ref per update the mean error is at most {ratio_to_disc:.1f}× the static "
                     "discretisation error at this resolution (thesis: \"the same order of magnitude\").")
    return text


def rate_note(rows) -> str:
    texts = []
    for rtol in sorted({r["rtol"] for r in rows}):
        timed = [r for r in rows if r["rtol"] == rtol and r.get("rate_ratio")]
        if not timed:
            continue
        ratios = [r["rate_ratio"] for r in timed]
        worst = min(timed, key=lambda r: r["rate_ratio"])
        best = max(timed, key=lambda r: r["rate_ratio"])
        h7 = [r["update_rate_hz"] for r in rows if r["rtol"] == rtol and r["h_ref"] == 7]
        per_solve = [1e6 * r["cpu_seconds"] / r["rearrangements"] for r in timed]
        text = (f"**ε = {rtol:g}: {min(ratios):.1f}× to {max(ratios):.1f}× the thesis's rate (geometric mean "
                f"{geometric_mean(ratios):.1f}×)"
                + (f"; the ≥ {UPDATE_RATE_GOAL:g}× goal is " + ("met" if min(ratios) >= UPDATE_RATE_GOAL else "not met")
                   if rtol == ISSUE_TOLERANCE else "")
                + (f"; h7 at {min(h7):.0f}–{max(h7):.0f} Hz (goal ≥ {H7_RATE_GOAL_HZ:g} Hz"
                   + (", met)" if min(h7) >= H7_RATE_GOAL_HZ else ", not met everywhere)") if h7 else "")
                + f".** Smallest ratio: h{worst['h_ref']} at {worst['speed']:g} h_ref/update, largest: "
                f"h{best['h_ref']} at {best['speed']:g}. CG iterations per solve: {cg_ratio(timed):.2f}× the "
                f"thesis's (geometric mean); CPU per solve {min(per_solve):.0f}–{max(per_solve):.0f} µs.")
        texts.append(text)
    if not texts:
        return "No thesis numbers for this set-up (quick run)."
    texts.append("Where the time goes (`studies/benchmarks/needle_rates.py` prints it from PETSc's event log; `perf` on the "
                 "C++ build): at ε = 1e-3 the solver, 20–40 unpreconditioned CG iterations per solve of about 3 µs "
                 "each on 750–1300 triangles, the matrix-free tangent product half of that and the rest PETSc's "
                 "vector operations (the reference BLAS's ddot), the constraint projections around each product and "
                 "the convergence test; at ε = 0.03, below 4 iterations per solve at the slow speeds, the 25–35 µs "
                 "per update outside the solver: point location for the refinement at the tip (in the deformed "
                 "mesh, then in the bisection hierarchy), the residual at the start of each solve and again at its "
                 "end (the check of (6.9) on the final state, which the rearrangement now reuses), the interception "
                 "scan and the rearrangement. 50× at ε = 1e-3 leaves 28–43 µs per solve in the slowest rows (0.03 and "
                 "0.01 h_ref/update), less than their 22–35 tangent products alone take: it needs fewer iterations, "
                 "not cheaper ones. "
                 "Measured and not taken: ICC (`-needle_pc_type icc`, 11–15 iterations) and a Cholesky "
                 "factorisation (`cholesky`, 1 iteration) cost more per solve than they save (h6, ε = 1e-3: 145–260 "
                 "and 175–520 µs per solve against 125–175 without a preconditioner; Jacobi 165–330), because the "
                 "system changes at 45–100 % of the updates (refinement at the tip changes the mesh, stick-slip the "
                 "constraints) and each change is a new factorisation; the linear predictor (`extrapolate=True`) "
                 "saves iterations in the slow rows but adds rearrangements in the fast ones. As in the thesis, "
                 "slower insertion needs fewer CG iterations per solve (more coherence between solutions) and "
                 "reaches higher update rates.")
    return " ".join(texts)


def conformance_note(rows, straight_max_mm: float) -> str:
    by = {r["comparison"]: r for r in rows}
    a, w, wo = by["relocation_vs_none"], by["with_relocation"], by["without_relocation"]
    smaller = a["mean_error_mm"] < min(w["mean_error_mm"], wo["mean_error_mm"])
    return ((f"**{'Agrees' if smaller else 'Differs'}:** the difference relocation makes ({a['mean_error_mm']:.3f} mm "
             f"mean, {a['max_error_mm']:.3f} max) is {'smaller' if smaller else 'not smaller'} than the discretisation "
             f"error ({w['mean_error_mm']:.3f} with, {wo['mean_error_mm']:.3f} without relocation)")
            + (", as in the thesis: not relocating nodes costs little accuracy." if smaller else ".")
            + f" The reference's own conformance error (h-fine with vs. without relocation) is "
              f"{by['reference_relocation_vs_none']['mean_error_mm']:.3f} mm mean: the reference is good to about that. "
              f"The tilted load bends the slab (up to {a['reference_max_displacement_mm']:.1f} mm of displacement, "
              f"against {straight_max_mm:.1f} mm for the straight line), so its discretisation error on the coarse "
              "start mesh is larger than the straight line's in Table 6.3; the thesis found the two about equal.")


# Why snede's Figure 6.12 distance is smaller than the thesis's (issue 33; docs/results/needle.md).
FIGURE_6_12_EXPLANATION = (
    "**Why, and not a snede mistake.** (1) The units hold: the profile is a force per length across the slab's "
    "10 mm (§6.3.1: t = t̃/d) and the slab's stiffness has that thickness (`Body(thickness=0.01)`); the static line "
    "load's 4.6 mm (Tables 6.1–6.3) is of the size a hand estimate gives (1.6 N on a 0.1 × 0.01 m section of "
    "E = 34 kPa: a strain of 5 % over the 30–100 mm to the fixed side, 1.5–5 mm). (2) The materials are the thesis's: linear elasticity (2.22) and, at ν = 0, neo-Hookean "
    "S = μ(I − C⁻¹) (6.4), which the engine's plane-stress closed form gives at λ = 0 (C₃₃ = 1). (3) The "
    "deformation is a shear parallel to the fixed bottom, and in simple shear neo-Hookean's shear stress is μγ, "
    "the linear one's: the two differ only in second order (normal stresses and rotation, γ²·h). The friction "
    "thresholds prescribe forces, equal for both materials, so the tip's material point moves alike along x; the "
    "distance grows with the load and levels off near 2 mm once the slab's left part is dragged off the shaft. "
    "(4) The load is what the thesis does not give: Figure 6.4 has no numbers, so `figure_6_4()` is a stand-in. "
    "Its refined mesh gives a hint: 625 triangles at the end, between snede's ×1 (about 760) and ×5 (about 600) "
    "meshes, where snede's distance is 0.2–2 mm. A load, or a measure (the text says 'the final location of "
    "needle tip', the caption 'the tip reference locations'), that gives 8 mm cannot be read from the thesis; "
    "nothing to fix in snede.")


def nonlinear_note(rows) -> str:
    text = []
    for scale in sorted({r["scale"] for r in rows}):
        pair = [r for r in rows if r["scale"] == scale]
        distance = pair[0]["tip_reference_distance_mm"]
        node = pair[0]["tip_node_distance_mm"]
        largest = max(r["max_displacement_mm"] for r in pair)
        text.append(f"friction ×{scale:g} (max |u| {largest:.0f} mm): "
                    + (f"{distance:.1f} mm" if distance is not None else "not found")
                    + f" (furthest needle nodes: {node:.1f} mm)")
    distances = [r["tip_reference_distance_mm"] for r in rows if r["tip_reference_distance_mm"] is not None]
    largest = max(distances, default=float("nan"))
    lines = ["**Distance between the tips' reference locations, linear vs. neo-Hookean (thesis ≈ "
             f"{THESIS_TIP_DISTANCE_MM:g} mm):** " + "; ".join(text) + "."]
    lines.append(("**Differs:** " if largest < 0.5 * THESIS_TIP_DISTANCE_MM else "")
                 + f"at most {largest:.1f} mm here"
                 + ((", well short of the thesis's ≈ 8 mm"
                     + (", even when the profile is scaled up until the slab's top is dragged several centimetres. "
                        if len({r["scale"] for r in rows}) > 1 else ". "))
                    if largest < 0.5 * THESIS_TIP_DISTANCE_MM else ". ")
                 + FIGURE_6_12_EXPLANATION)
    lines.append(" ".join(f"{r['material']} ×{r['scale']:g}: the shaft's material points lie at reference y = "
                          f"{r['shaft_reference_y_min_mm']:.1f}–{r['shaft_reference_y_max_mm']:.1f} mm, the tip's "
                          "material point at x = " + (f"{r['tip_reference_x'] * MM:.1f} mm"
                                                      if r["tip_reference_x"] is not None else "–") + "."
                          for r in rows)
                 + " The tip's material point lies short of x = 70 mm because friction dragged the material along +x "
                 "before the tip reached it (at large scales the slab's left side is dragged so far that only the end "
                 "of the shaft is inside it); the spread in y is how far the shaft's material trajectory bends away "
                 "from the straight line y = 50 mm in the reference configuration.")
    return "\n\n".join(lines)


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
