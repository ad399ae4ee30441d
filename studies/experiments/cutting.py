"""§3.3 cutting: the large diagonal cut in the generated cube (Figures 3.5, 3.14–3.16), the
same cut in small steps with relaxation in between (Figure 3.17), pie-like cuts in an
unstructured cylinder (Figure 3.13) and element quality before and after.

    .venv/bin/python -m studies.experiments.cutting [--quick] [--out DIR]

* Cube: snede.meshing.box((1, 1, 1), (8, 8, 8)), the thesis's 3072 tetrahedra and 729 nodes,
  linear elastic with ν = 1/4, the back face (z = 0) fixed and an outward traction on the four
  side faces (x = 0, 1 and y = 0, 1) lumped onto their nodes: the dilating load of Figures 3.12
  and 3.14. Linear CG until ‖r‖ < 1e-3‖f‖ (criterion (6.8)), before the cut from zero and after
  it from the carried state. The cut: a blade along the diagonal of the front face (z = 1)
  moved straight back from outside the body to 65 % of its depth in one move (two sweep
  triangles), in deformed coordinates; jagged (no snapping), snapped, and snapped with
  degeneracy removal at aspect ratio thresholds 0.01 (the thesis's), 0.05 and 0.1. A scan over
  18 other blade orientations shows how much the counts depend on the angle of the cut.
* Steps: the same cut in 1 to 32 moves, relaxing (solving) after every move or not; the
  incision's area and connectivity against the one-move cut.
* Cylinder: snede.meshing.cylinder (gmsh Delaunay, about 4000 tetrahedra), three pie-like cuts
  from the axis outward, 120° apart: edge collapses as a share of the faces dissected.
* Quality: histograms of aspect ratio and largest dihedral angle of the cube before and after
  the cut.

Writes cutting.md, cutting.csv (one row per cut, column ``part``), cutting_quality.png,
cutting_scan.png and cutting_incision.png into docs/results/.
"""
from __future__ import annotations

import math
import statistics
import time
from pathlib import Path

import numpy as np

import snede
from studies.experiments import organ_cuts
from studies.experiments.common import (Column, PageTemplate, markdown_table, options_prefix, parse_arguments, pyplot,
                                        save_figure, write_csv)

DIVISIONS = 8  # 8 × 8 × 8 cubes of 6 tetrahedra: 3072 tetrahedra, 729 nodes (§3.3)
YOUNG, POISSON = 1e4, 0.25  # Pa; ν = 1/4 as in §3.3 (E only scales the displacement)
TRACTION = 2e2  # Pa, outward on the side faces: about 1 % dilation before the cut, an opening of about an element after
RTOL = 1e-3  # ‖r‖ < 1e-3 ‖f‖, §3.3
FRONT, START, DEPTH = 1.0, 1.25, 0.65  # the blade starts at z = 1.25 and stops 0.65 deep (z = 0.35)
HALF_BLADE = 1.2  # half the blade's length: it spans the whole (dilated) front face
REPEATS = 5  # cuts timed per variant (the median is reported)
LARGE_ANGLE = 0.99 * math.pi

# Variants of the cube cut: label -> (snap, remove degeneracies, aspect threshold, large angle).
VARIANTS = {
    "jagged (no snapping)": (False, False, 0.01, LARGE_ANGLE),
    "snapped, no removal": (True, False, 0.01, LARGE_ANGLE),
    "removal at 0.01": (True, True, 0.01, LARGE_ANGLE),
    "removal at 0.05": (True, True, 0.05, LARGE_ANGLE),
    "removal at 0.1": (True, True, 0.1, LARGE_ANGLE),
    "removal at 0.1, large angle 0.9π": (True, True, 0.1, 0.9 * math.pi),
}
# The cuts of part (a): the diagonal one (the thesis's "large diagonal cut") and, for contrast,
# a blade at 15° to the x axis, which the orientation scan finds to leave the thinnest elements.
CUTS = {"diagonal": {"angle": 45.0}, "15° blade": {"angle": 15.0}}
REMOVAL_SETTINGS = {"none": None, "0.01": 0.01, "0.1": 0.1}  # for the orientation scan and the cylinder
THRESHOLDS = (0.01, 0.05, 0.1)

# §3.3 and Figures 3.14–3.16: the large diagonal cut in the 3072-element cube, and the cylinder.
THESIS = {"elements": 3072, "nodes": 729, "faces_dissected": 108, "degenerate": 143, "failed_repositionings": 2,
          "iterations_degenerate": 2439, "iterations_removed": 236, "collapses": 99, "incollapsible": 13,
          "elements_after": 3034, "nodes_after": 823, "removal_seconds": 0.7}
THESIS_CYLINDER = {"elements": 4020, "vertices": 891, "faces_dissected": 873, "collapse_share": 0.05}

# The cylinder of the pie-like cuts: gmsh target edge length and seed giving about 4000 tetrahedra.
CYLINDER = {"length": 0.1, "radius": 0.03, "h": 0.0072, "seed": 1}
PIE_MOVES = 15  # moves of the blade per pie cut, from the axis to 1.2 radii out (also 1 and 5: about an element per move)
PIE_OFFSETS = (0.1, 0.6)  # angle (rad) of the first of the three cuts


# --- the cube ---------------------------------------------------------------------------------
def apply_traction(body) -> None:
    """The dilating load: TRACTION (Pa) along the outward normal of every boundary face on the
    four side planes (x = 0, 1 and y = 0, 1; not incision faces parallel to them), a third of
    each face's force on each of its nodes (channel ``dilation``,
    set again after every cut so that vertex copies on the sides carry their share)."""
    mesh = body.mesh
    x = mesh.points
    forces = np.zeros_like(x)
    for face in mesh.boundary_faces():
        p = x[face]
        normal = np.cross(p[1] - p[0], p[2] - p[0])
        area = 0.5 * np.linalg.norm(normal)
        normal /= 2 * area
        axis = int(np.argmax(np.abs(normal)))
        side = 1.0 if normal[axis] > 0 else 0.0  # outward +x lies on x = 1, −x on x = 0
        if axis < 2 and abs(normal[axis]) > 1 - 1e-9 and np.allclose(p[:, axis], side, atol=1e-9):
            forces[face] += TRACTION * area / 3 * normal  # not on the incision's lips
    loaded = np.flatnonzero(np.abs(forces).sum(axis=1) > 0)
    body.set_nodal_forces(loaded, forces[loaded], channel="dilation")


def cube_body(divisions: int = DIVISIONS):
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (divisions,) * 3)
    body = snede.Body(mesh, snede.LinearElastic(YOUNG, POISSON))
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    apply_traction(body)
    return body


def cg(body, label: str):
    return snede.StaticSolver(body, "cg", preconditioner="none", rtol=RTOL, criterion="6.8", max_iterations=100000,
                              options_prefix=options_prefix(label))


def blade_path(moves: int, angle: float = 45.0, tilt: float = 0.0, offset: float = 0.0) -> np.ndarray:
    """(moves + 1, 2, 3) blade positions. The blade lies in the front face's plane at ``angle``
    degrees below the x axis (45: along the diagonal from (0, 1) to (1, 0)), through the face's
    centre shifted by ``offset`` along the blade's normal in that plane; it moves along −z tilted
    by ``tilt`` degrees towards that normal, from z = START to z = FRONT − DEPTH in equal moves."""
    a, t = math.radians(angle), math.radians(tilt)
    blade = np.array([math.cos(a), -math.sin(a), 0.0])
    normal = np.array([math.sin(a), math.cos(a), 0.0])
    sweep = -math.cos(t) * np.array([0.0, 0.0, 1.0]) + math.sin(t) * normal
    centre = np.array([0.5, 0.5, FRONT]) + offset * normal
    path = []
    for z in np.linspace(START, FRONT - DEPTH, moves + 1):
        middle = centre + sweep * (z - FRONT) / sweep[2]
        path.append([middle - HALF_BLADE * blade, middle + HALF_BLADE * blade])
    return np.array(path)


def incision_measures(mesh, faces) -> tuple[float, int, str]:
    """Area of the incision in the reference configuration (half the area of its faces: each
    cut face appears on both lips), its number of pieces (faces joined through edges) and their
    sizes in faces ("250/4"), largest first."""
    faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        return 0.0, 0, ""
    x = mesh.points
    area = 0.25 * np.linalg.norm(np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]]),
                                 axis=1).sum()
    parent = list(range(len(faces)))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    first = {}
    for i, face in enumerate(faces):
        for a, b in ((face[0], face[1]), (face[1], face[2]), (face[0], face[2])):
            key = (min(a, b), max(a, b))
            if key in first:
                parent[find(i)] = find(first[key])
            else:
                first[key] = i
    roots = [find(i) for i in range(len(faces))]
    sizes = sorted(np.unique(roots, return_counts=True)[1].tolist(), reverse=True)
    return float(area), len(sizes), "/".join(map(str, sizes))


def quality_counts(mesh) -> dict:
    q = mesh.quality()
    row = {f"below_{t:g}": int((q.aspect_ratio < t).sum()) for t in THRESHOLDS}
    row["min_aspect"] = float(q.aspect_ratio.min())
    row["max_dihedral_deg"] = float(np.degrees(q.max_dihedral.max()))
    flat = np.flatnonzero(q.aspect_ratio < THRESHOLDS[0])
    if len(flat):  # what makes them flat: a short edge (needle) or a large angle
        corners = mesh.points[mesh.cells[flat]]
        lengths = np.linalg.norm(corners[:, [0, 0, 0, 1, 1, 2]] - corners[:, [1, 2, 3, 2, 3, 3]], axis=2)
        row["flat_edge_ratio"] = float(np.median(lengths.min(axis=1) / lengths.max(axis=1)))
        row["flat_max_dihedral_deg"] = float(np.degrees(q.max_dihedral[flat].max()))
    return row


def flat_at_crease(mesh) -> int:
    """How many elements below aspect ratio 0.01 have their shortest edge at an edge or corner of
    the cube (an end with two coordinates 0 or 1, in the reference configuration)."""
    q = mesh.quality()
    flat = np.flatnonzero(q.aspect_ratio < THRESHOLDS[0])
    x = mesh.points
    on_crease = (np.isclose(x, 0.0, atol=1e-9) | np.isclose(x, 1.0, atol=1e-9)).sum(axis=1) >= 2
    count = 0
    for cell in mesh.cells[flat]:
        pairs = [(a, b) for i, a in enumerate(cell) for b in cell[i + 1:]]
        a, b = min(pairs, key=lambda ab: np.linalg.norm(x[ab[0]] - x[ab[1]]))
        count += bool(on_crease[a] or on_crease[b])
    return count


def report_columns(report) -> dict:
    return {"sweeps": report.sweeps, "faces_selected": report.faces_selected,
            "faces_dissected": report.faces_dissected, "vertices_split": report.vertices_split,
            "vertices_snapped": report.vertices_snapped, "snaps_refused": report.snaps_refused,
            "degenerate_found": report.degenerate_found, "needles": report.degenerate_shapes[0],
            "spindles": report.degenerate_shapes[1], "slivers": report.degenerate_shapes[2],
            "caps": report.degenerate_shapes[3], "edges_collapsed": report.edges_collapsed,
            "edges_split": report.edges_split, "faces_split": report.faces_split,
            "elements_cut_free": report.elements_cut_free, "components": report.components,
            "free_pieces": report.free_pieces, "pieces_fixed": report.pieces_fixed, "cut_seconds": report.seconds}


def cube_cut(snap: bool, remove: bool, threshold: float, large_angle: float, path, relax: bool = False,
             label: str = "cube"):
    """Solve the loaded cube, cut it along ``path`` (relaxing after every move if ``relax``),
    solve again. Returns (row, body)."""
    body = cube_body()
    solver = cg(body, label)
    before = solver.solve()
    cutter = snede.TetrahedralCutter(body, snap=snap, remove_degeneracies=remove, min_aspect_ratio=threshold,
                                     large_angle=large_angle)
    total = snede.CutResult()
    relax_iterations = 0
    for k, scalpel in enumerate(path):
        total = total + cutter.move(scalpel)
        if relax and 0 < k < len(path) - 1:
            apply_traction(body)
            relax_iterations += solver.solve().iterations
    apply_traction(body)
    after = solver.solve()
    area, pieces, piece_faces = incision_measures(body.mesh, cutter.incision_faces())
    columns = report_columns(total)
    columns["flat_at_crease"] = flat_at_crease(body.mesh)
    if not remove:  # the cutter looks for degeneracies only when it removes them
        columns.update(degenerate_found=None, needles=None, spindles=None, slivers=None, caps=None)
    row = {"snap": snap, "remove": remove, "threshold": threshold if remove else None,
           "large_angle_deg": math.degrees(large_angle) if remove else None, "moves": len(path) - 1,
           **columns, "elements": body.mesh.n_cells, "nodes": body.mesh.n_live_points,
           **quality_counts(body.mesh), "cg_before": before.iterations, "cg_after": after.iterations,
           "cg_between": relax_iterations, "cg_after_seconds": after.seconds, "converged": after.converged,
           "reason": after.reason, "incision_area": area, "incision_pieces": pieces,
           "incision_piece_faces": piece_faces}
    return row, body


def cube_rows(quick: bool):
    """Part (a): each cut of CUTS in one move, per variant; each cut timed REPEATS times.
    Returns the rows and the meshes after the cut by (cut, variant)."""
    rows, meshes = [], {}
    repeats = 1 if quick else REPEATS
    for cut, orientation in CUTS.items():
        for name, (snap, remove, threshold, large_angle) in VARIANTS.items():
            if quick and "0.9π" in name:
                continue
            seconds = []
            for _ in range(repeats):
                row, body = cube_cut(snap, remove, threshold, large_angle, blade_path(1, **orientation), label="cube")
                seconds.append(row["cut_seconds"])
            row["cut_seconds"] = statistics.median(seconds)
            row.update(part="cube", cut=cut, variant=name)
            rows.append(row)
            meshes[cut, name] = body.mesh
            print(f"cube {cut:<9} {name:<34} {row['faces_dissected']:>4} faces, {row['below_0.01']:>3} below 0.01 "
                  f"(min {row['min_aspect']:.4f}), {row['edges_collapsed']:>3} collapses, {row['elements_cut_free']:>3} "
                  f"cut free, CG {row['cg_after']:>5}, cut {row['cut_seconds'] * 1e3:.1f} ms", flush=True)
        unremoved = next(row for row in rows if row["cut"] == cut and row["variant"] == "snapped, no removal")
        for row in rows:
            if row["cut"] != cut:
                continue
            row["removal_seconds"] = row["cut_seconds"] - unremoved["cut_seconds"] if row["remove"] else None
            row["cut_ms"] = 1e3 * row["cut_seconds"]
            row["removal_ms"] = None if row["removal_seconds"] is None else 1e3 * row["removal_seconds"]
    return rows, meshes


def scan_orientations(quick: bool):
    """The cut at other blade angles, tilts and offsets (one move), without and with removal."""
    angles, tilts, offsets = ((45.0, 20.0), (0.0, 20.0), (0.0,)) if quick else \
        ((45.0, 30.0, 15.0), (0.0, 15.0, 30.0), (0.0, 0.3 / DIVISIONS))
    rows = []
    for angle in angles:
        for tilt in tilts:
            for offset in offsets:
                row = {"part": "scan", "angle_deg": angle, "tilt_deg": tilt, "offset": offset}
                for setting, threshold in REMOVAL_SETTINGS.items():
                    result, _ = cube_cut(True, threshold is not None, threshold or 0.01, LARGE_ANGLE,
                                         blade_path(1, angle, tilt, offset), label="scan")
                    if threshold is None:
                        row.update({key: result[key] for key in ("faces_dissected", "snaps_refused", "below_0.01",
                                                                 "below_0.05", "below_0.1", "min_aspect")})
                    else:
                        row[f"collapses_{setting}"] = result["edges_collapsed"]
                        row[f"cut_free_{setting}"] = result["elements_cut_free"]
                    row[f"cg_after_{setting}"] = result["cg_after"]
                    row["cg_before"] = result["cg_before"]
                rows.append(row)
                print(f"scan angle {angle:>4g}° tilt {tilt:>4g}° offset {offset:.4f}: {row['faces_dissected']:>4} "
                      f"faces, below 0.01/0.05/0.1: {row['below_0.01']}/{row['below_0.05']}/{row['below_0.1']}, "
                      f"min {row['min_aspect']:.4f}, CG {row['cg_after_none']}/{row['cg_after_0.01']}/"
                      f"{row['cg_after_0.1']}", flush=True)
    return rows


STEP_VARIANTS = {  # label -> (snap, remove, threshold, relax between moves)
    "snapped, removal at 0.01, relaxed": (True, True, 0.01, True),
    "snapped, removal at 0.01, not relaxed": (True, True, 0.01, False),
    "snapped, removal at 0.1, relaxed": (True, True, 0.1, True),
    "jagged (no snapping), relaxed": (False, False, 0.01, True),
}


def step_rows(quick: bool):
    """Part (b), Figure 3.17: the cut in several moves."""
    moves_list = (1, 4) if quick else (1, 2, 4, 8, 16, 32)
    rows = []
    for name, (snap, remove, threshold, relax) in STEP_VARIANTS.items():
        if quick and "0.1" in name:
            continue
        one_move = None
        for moves in moves_list:
            row, _ = cube_cut(snap, remove, threshold, LARGE_ANGLE, blade_path(moves), relax=relax, label="steps")
            row.update(part="steps", variant=name, relax=relax)
            if moves == 1:
                one_move = row
            row["area_ratio"] = row["incision_area"] / one_move["incision_area"] if one_move["incision_area"] else None
            rows.append(row)
            print(f"steps {name:<40} {moves:>3} moves: {row['faces_dissected']:>4} faces, area "
                  f"{row['incision_area']:.3f} ({row['area_ratio']:.2f} of one move), incision pieces "
                  f"{row['incision_pieces']}, body pieces {row['components']}, CG between {row['cg_between']}",
                  flush=True)
    return rows


# --- the cylinder -----------------------------------------------------------------------------
def pie_path(theta: float, moves: int) -> np.ndarray:
    """A blade parallel to the cylinder's axis (x), 1 % longer than the cylinder at each end,
    moved from the axis outward along the direction at angle ``theta`` to 1.2 radii."""
    length, radius = CYLINDER["length"], CYLINDER["radius"]
    direction = np.array([0.0, math.cos(theta), math.sin(theta)])
    ends = np.array([[-0.01 * length, 0.0, 0.0], [1.01 * length, 0.0, 0.0]])
    return np.array([ends + r * direction for r in np.linspace(0.0, 1.2 * radius, moves + 1)])


def incision_union(mesh, parts) -> np.ndarray:
    """The faces of several cutters' incisions that are still on the boundary of the mesh (a
    later cut's collapses can change an earlier incision's faces)."""
    boundary = {tuple(sorted(face)) for face in mesh.boundary_faces().tolist()}
    faces = {tuple(sorted(face)) for part in parts for face in np.asarray(part).reshape(-1, 3).tolist()}
    return np.array(sorted(faces & boundary), dtype=np.int64).reshape(-1, 3)


def cylinder_mesh(quick: bool):
    settings = dict(CYLINDER, h=0.012) if quick else CYLINDER
    return snede.meshing.cylinder(settings["length"], settings["radius"], settings["h"], seed=settings["seed"])


def cylinder_rows(quick: bool):
    """Part (c), Figure 3.13: three pie-like cuts, 120° apart, in the bare mesh."""
    rows = []
    moves_list = (5,) if quick else (1, 5, PIE_MOVES)
    for offset in (PIE_OFFSETS[:1] if quick else PIE_OFFSETS):
        for moves in moves_list:
            for setting, threshold in REMOVAL_SETTINGS.items():
                mesh = cylinder_mesh(quick)
                elements, vertices = mesh.n_cells, mesh.n_live_points
                per_cut, incision = [], []
                total = snede.CutResult()
                for k in range(3):
                    # A cutter per cut: the scalpel is lifted between cuts (one cutter would sweep from the
                    # end of one cut to the start of the next).
                    cutter = snede.TetrahedralCutter(mesh, remove_degeneracies=threshold is not None,
                                                     min_aspect_ratio=threshold or 0.01)
                    report = cutter.cut(pie_path(offset + 2 * math.pi * k / 3, moves))
                    incision.append(cutter.incision_faces())
                    del cutter
                    per_cut.append(report)
                    total = total + report
                sizes = np.bincount(mesh.connected_components()[1])
                area, pieces, piece_faces = incision_measures(mesh, incision_union(mesh, incision))
                row = {"part": "cylinder", "offset_rad": offset, "moves_per_cut": moves, "removal": setting,
                       "elements_before": elements, "vertices_before": vertices, **report_columns(total),
                       "elements": mesh.n_cells, "nodes": mesh.n_live_points, **quality_counts(mesh),
                       "collapse_share": total.edges_collapsed / total.faces_dissected
                       if total.faces_dissected >= 50 else None,  # a failed cut (see the text): no share
                       "faces_per_cut": "/".join(str(r.faces_dissected) for r in per_cut),
                       "collapses_per_cut": "/".join(str(r.edges_collapsed) for r in per_cut),
                       "largest_piece": int(sizes.max()), "small_pieces": int((sizes < 20).sum()),
                       "small_piece_elements": int(sizes[sizes < 20].sum()), "incision_area": area,
                       "incision_pieces": pieces, "incision_piece_faces": piece_faces}
                rows.append(row)
                print(f"cylinder offset {offset:.1f} {moves:>2} moves, removal {setting:<4}: {row['faces_dissected']:>4} "
                      f"faces ({row['faces_per_cut']}), {row['degenerate_found']} degenerate, {row['edges_collapsed']} "
                      f"collapses, {row['elements_cut_free']} cut free, {row['components']} pieces "
                      f"({row['small_pieces']} under 20 elements)", flush=True)
    return rows


# --- figures ----------------------------------------------------------------------------------
def plot_quality(meshes: dict, path: Path) -> None:
    """``meshes``: cut -> {label: mesh}; one row of panels per cut."""
    plt = pyplot()
    figure, panels = plt.subplots(len(meshes), 2, figsize=(11, 4.0 * len(meshes)), squeeze=False)
    bins = np.logspace(-4, 0, 41)
    angle_bins = np.linspace(60, 180, 41)
    for (cut, shown), (left, right) in zip(meshes.items(), panels):
        for k, (name, mesh) in enumerate(shown.items()):
            q = mesh.quality()
            # identical histograms (e.g. removal that removed nothing) stay visible: wide to narrow, dashed
            style = dict(histtype="step", lw=3.0 - 0.5 * k, color=f"C{k}", ls=("-", "--", "-.", ":", "-")[k % 5])
            left.hist(np.clip(q.aspect_ratio, 1e-4, None), bins=bins, label=f"{name} (min {q.aspect_ratio.min():.3g})",
                      **style)
            right.hist(np.degrees(q.max_dihedral), bins=angle_bins,
                       label=f"{name} (max {np.degrees(q.max_dihedral.max()):.0f}°)", **style)
        for threshold in THRESHOLDS:
            left.axvline(threshold, color="0.6", lw=0.8, ls=":")
        right.axvline(math.degrees(LARGE_ANGLE), color="0.6", lw=0.8, ls=":")
        left.set_xscale("log")
        for axes in (left, right):
            axes.set_yscale("log")
            axes.set_ylim(bottom=0.7)
            axes.set_ylabel("elements")
            axes.grid(True, which="both", alpha=0.3)
            axes.legend(fontsize=7, loc="upper left")
            axes.set_title(f"{cut} cut, one move", fontsize=10)
        left.set_xlabel("aspect ratio (min height / max edge); dotted: 0.01, 0.05, 0.1")
        right.set_xlabel("largest dihedral angle [°]; dotted: 0.99π")
    figure.suptitle("§3.3 cube (3072 tetrahedra): element quality before and after the cut")
    save_figure(figure, path, 110)


def plot_scan(rows, path: Path) -> None:
    plt = pyplot()
    figure, axes = plt.subplots(figsize=(6.4, 4.4))
    minimum = np.array([row["min_aspect"] for row in rows])
    for setting, marker in (("none", "o"), ("0.01", "s"), ("0.1", "^")):
        label = "no removal" if setting == "none" else f"removal at {setting}"
        axes.scatter(minimum, [row[f"cg_after_{setting}"] for row in rows], marker=marker, label=label,
                     facecolors="none" if setting != "none" else None, edgecolors=None if setting == "none" else "k")
    axes.axhline(rows[0]["cg_before"], color="0.6", lw=0.8, ls="--", label="uncut, from zero")
    axes.set_xscale("log")
    axes.set_xlabel("smallest aspect ratio after the cut, without removal")
    axes.set_ylabel("CG iterations after the cut (‖r‖ < 1e-3‖f‖)")
    axes.set_title("Cube, one-move cuts at 18 orientations")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    save_figure(figure, path, 120)


def plot_incisions(bodies: dict, path: Path) -> None:
    """The deformed incision (both lips) of each variant, seen from the front, with the outline
    of the deformed cube's front face."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    plt = pyplot()
    figure = plt.figure(figsize=(4.2 * len(bodies), 4.4))
    for k, (name, (body, faces)) in enumerate(bodies.items()):
        axes = figure.add_subplot(1, len(bodies), k + 1, projection="3d")
        x = body.mesh.points + body.displacement
        faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        triangles = x[faces]
        normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
        normals /= np.linalg.norm(normals, axis=1)[:, None]
        shade = 0.35 + 0.6 * np.abs(normals @ np.array([0.5, -0.6, 0.62]))
        colours = np.clip(np.outer(shade, [0.84, 0.25, 0.2]), 0, 1)
        axes.add_collection3d(Poly3DCollection(triangles, facecolors=colours, edgecolors="k", linewidths=0.15))
        boundary = body.mesh.boundary_faces()
        back = boundary[np.all(np.isclose(body.mesh.points[boundary][:, :, 2], 0.0), axis=1)]
        axes.add_collection3d(Poly3DCollection(x[back], facecolors=(0.6, 0.6, 0.6, 0.3), edgecolors="none"))
        corners = x[np.isclose(body.mesh.points[:, 2], FRONT)]
        axes.scatter(corners[:, 0], corners[:, 1], corners[:, 2], s=0.5, color="0.5")
        axes.set_xlim(-0.1, 1.1), axes.set_ylim(-0.1, 1.1), axes.set_zlim(0, 1.1)
        axes.view_init(elev=22, azim=50)  # looking at the diagonal plane x + y = 1 from its side
        axes.set_title(name, fontsize=9)
        axes.set_axis_off()
    save_figure(figure, path, 110)


# --- the report -------------------------------------------------------------------------------
CUBE_COLUMNS = [
    Column("cut", "cut"), Column("variant", "variant"), Column("faces_dissected", "faces dissected"),
    Column("vertices_snapped", "snapped"), Column("snaps_refused", "snaps refused"),
    Column("below_0.01", "aspect < 0.01 after"), Column("below_0.05", "< 0.05"), Column("below_0.1", "< 0.1"),
    Column("min_aspect", "min aspect", "{:.4f}"), Column("degenerate_found", "degenerate found"),
    Column("edges_collapsed", "collapses"), Column("edges_split", "edge splits"),
    Column("elements_cut_free", "cut free"), Column("elements", "elements"), Column("nodes", "nodes"),
    Column("cg_after", "CG after cut"), Column("cut_ms", "cut [ms]", "{:.1f}"),
    Column("removal_ms", "removal [ms]", "{:+.1f}")]
SCAN_COLUMNS = [
    Column("angle_deg", "blade angle [°]", "{:g}"), Column("tilt_deg", "tilt [°]", "{:g}"),
    Column("offset", "offset", "{:.4f}"), Column("faces_dissected", "faces"), Column("snaps_refused", "refused"),
    Column("below_0.01", "< 0.01"), Column("below_0.05", "< 0.05"), Column("below_0.1", "< 0.1"),
    Column("min_aspect", "min aspect", "{:.4f}"), Column("cg_after_none", "CG, no removal"),
    Column("collapses_0.01", "collapses at 0.01"), Column("cg_after_0.01", "CG, removal 0.01"),
    Column("collapses_0.1", "collapses at 0.1"), Column("cut_free_0.1", "cut free at 0.1"),
    Column("cg_after_0.1", "CG, removal 0.1")]
STEP_COLUMNS = [
    Column("variant", "variant"), Column("moves", "moves"), Column("sweeps", "sweep triangles"),
    Column("faces_selected", "faces selected"), Column("faces_dissected", "faces dissected"),
    Column("incision_area", "incision area", "{:.3f}"), Column("area_ratio", "of one move", "{:.2f}"),
    Column("incision_pieces", "incision pieces"), Column("incision_piece_faces", "their faces"),
    Column("components", "body pieces"),
    Column("edges_collapsed", "collapses"), Column("elements_cut_free", "cut free"),
    Column("below_0.01", "aspect < 0.01 after"), Column("cg_between", "CG between moves"),
    Column("cg_after", "CG final")]
CYLINDER_COLUMNS = [
    Column("offset_rad", "first angle [rad]", "{:.1f}"), Column("moves_per_cut", "moves per cut"),
    Column("removal", "removal threshold"), Column("faces_dissected", "faces dissected"),
    Column("faces_per_cut", "per cut"), Column("snaps_refused", "snaps refused"),
    Column("degenerate_found", "degenerate found"), Column("edges_collapsed", "collapses"),
    Column("collapses_per_cut", "per cut"), Column("collapse_share", "collapses / faces", "{:.1%}"),
    Column("edges_split", "edge splits"), Column("elements_cut_free", "cut free"),
    Column("below_0.01", "aspect < 0.01 after"), Column("elements", "elements"), Column("nodes", "nodes"),
    Column("components", "pieces"), Column("small_pieces", "pieces < 20 elements")]


def comparison_table(cube, template: PageTemplate) -> str:
    by = {row["variant"]: row for row in cube}
    thesis_like = by["removal at 0.01"]
    return template.snippet("comparison", thesis=THESIS, snapped=by["snapped, no removal"], at_001=thesis_like,
                            at_01=by["removal at 0.1"], nodes=cube_nodes(),
                            removal_001=_ms(thesis_like["removal_seconds"]),
                            removal_01=_ms(by["removal at 0.1"]["removal_seconds"]),
                            cut_ms=thesis_like["cut_seconds"] * 1e3)


def _ms(seconds) -> str:
    return "–" if seconds is None else f"{seconds * 1e3:+.1f} ms"


def cube_nodes() -> int:
    return (DIVISIONS + 1) ** 3


def engine_version() -> str:
    """The repository's commit (and whether engine/ differs from it), for results that depend on the cutter."""
    import subprocess

    root = Path(__file__).resolve().parents[2]
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True, text=True,
                                check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "engine", "bindings"], cwd=root, capture_output=True,
                               text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "an unknown commit"
    return f"commit {commit}" + (" with local changes to engine/ or bindings/" if dirty else "")


def describe(cube, scan, steps, cylinder, fresh, quick: bool, minutes: float) -> str:
    """cutting.md (without its organ section): studies/templates/cutting.md filled with the tables
    and the summaries of (a)–(d)."""
    template = PageTemplate("cutting")
    other = [row for row in cube if row["cut"] != "diagonal"]
    cube_all, cube = cube, [row for row in cube if row["cut"] == "diagonal"]
    snapped = {row["variant"]: row for row in cube}["snapped, no removal"]
    return template.page(
        quick_flag=" --quick" if quick else "",
        run=template.snippet("quick_run") if quick else template.snippet("full_run", minutes=minutes),
        engine=engine_version(), elements=snapped["elements"], nodes=cube_nodes(), young=YOUNG, poisson=POISSON,
        traction=TRACTION, cg_before=snapped["cg_before"], blade_length=2 * HALF_BLADE, start=START,
        stop=FRONT - DEPTH, faces=snapped["faces_dissected"], repeats=1 if quick else REPEATS,
        cube_table=markdown_table(cube_all, CUBE_COLUMNS), comparison=comparison_table(cube, template),
        cube_summary=cube_summary(cube, scan, template), other_summary=other_cut_summary(other, template),
        scan_table=markdown_table(scan, SCAN_COLUMNS), scan_summary=scan_summary(scan, template),
        fewest_moves=steps[0]["moves"] if steps else 1, most_moves=max((row["moves"] for row in steps), default=1),
        path=START - FRONT + DEPTH, path_edges=(START - FRONT + DEPTH) * DIVISIONS,
        steps_table=markdown_table(steps, STEP_COLUMNS), steps_summary=steps_summary(steps, template),
        length=CYLINDER["length"], radius=CYLINDER["radius"], h=0.012 if quick else CYLINDER["h"],
        seed=CYLINDER["seed"],
        cylinder_size=template.snippet("cylinder_size", elements=cylinder[0]["elements_before"],
                                       vertices=cylinder[0]["vertices_before"],
                                       thesis_elements=THESIS_CYLINDER["elements"],
                                       thesis_vertices=THESIS_CYLINDER["vertices"]) if cylinder else "",
        pie_moves=" or ".join(str(m) for m in dict.fromkeys(row["moves_per_cut"] for row in cylinder)),
        pie_moves_per_cut=PIE_MOVES, cylinder_table=markdown_table(cylinder, CYLINDER_COLUMNS),
        cylinder_summary=cylinder_summary(cylinder, template), quality_summary=quality_summary(cube, other, fresh, template))


def shapes(row, template: PageTemplate) -> str:
    names = ("needles", "spindles", "slivers", "caps")
    found = [f"{row[name]} {name}" for name in names if row[name]]
    return ", ".join(found) if found else template.snippet("none")


def large_angle(row, template: PageTemplate) -> str:
    return template.snippet("large_angle") if "0.9π" in row["variant"] else ""


def cube_summary(cube, scan, template: PageTemplate) -> str:
    snippet = template.snippet
    by = {row["variant"]: row for row in cube}
    snapped, jagged = by["snapped, no removal"], by["jagged (no snapping)"]
    at_001 = by["removal at 0.01"]
    larger = [row for row in cube if row["remove"] and row["threshold"] != 0.01]
    rows = dict(snapped=snapped, jagged=jagged, at_001=at_001)
    flat = ""
    if snapped.get("flat_edge_ratio") is not None and at_001["needles"] == at_001["degenerate_found"] > 0:
        flat = snippet("flat", edge_ratio=snapped["flat_edge_ratio"], dihedral=snapped["flat_max_dihedral_deg"],
                       crease=snippet("crease", n=snapped["flat_at_crease"]) if snapped["flat_at_crease"] else "")
    return snippet(
        "cube_summary", **rows, nodes=cube_nodes(),
        degenerate=snippet("degenerate" if snapped["below_0.01"] else "no_degenerate", **rows),
        attempted=snapped["vertices_snapped"] + snapped["snaps_refused"],
        scan_zero=snippet("scan_zero", zero=sum(row["below_0.01"] == 0 for row in scan), n_scan=len(scan))
        if scan else "",
        shapes=shapes(at_001, template), flat=flat,
        larger="; ".join(snippet("larger_threshold", row=row, large_angle=large_angle(row, template),
                                 shapes=shapes(row, template)) for row in larger),
        nothing_to_remove=snippet("nothing_to_remove") if all(row["degenerate_found"] == 0 for row in larger) else "",
        removal_001=_ms(at_001["removal_seconds"]), removal_01=_ms(by["removal at 0.1"]["removal_seconds"]),
        cut_ms=at_001["cut_seconds"] * 1e3)


def other_cut_summary(rows, template: PageTemplate) -> str:
    if not rows:
        return ""
    by = {row["variant"]: row for row in rows}
    return template.snippet(
        "other_cut", cut=rows[0]["cut"], snapped=by["snapped, no removal"],
        jagged_cg=by["jagged (no snapping)"]["cg_after"],
        removals="; ".join(template.snippet("other_removal", row=row, large_angle=large_angle(row, template),
                                            shapes=shapes(row, template), removal=_ms(row["removal_seconds"]))
                           for row in rows if row["remove"]))


def scan_summary(scan, template: PageTemplate) -> str:
    if not scan:
        return ""
    snippet = template.snippet
    faces = [row["faces_dissected"] for row in scan]
    minimum = np.array([row["min_aspect"] for row in scan])
    iterations = np.array([row["cg_after_none"] for row in scan])
    rho = float(np.corrcoef(np.argsort(np.argsort(minimum)), np.argsort(np.argsort(iterations)))[0, 1])
    helped = [row for row in scan if row["collapses_0.1"] > 0]
    relation = snippet("follows_worst") if rho < -0.5 else snippet("no_relation", by_tilt=", ".join(
        f"{tilt:g}°: {np.mean([row['cg_after_none'] for row in scan if row['tilt_deg'] == tilt]):.0f}"
        for tilt in dict.fromkeys(row["tilt_deg"] for row in scan)))
    removal = ""
    if helped:
        removal = snippet("removal_helped", n_helped=len(helped), n_scan=len(scan),
                          changes=", ".join(f"{row['cg_after_0.1'] - row['cg_after_none']:+d}" for row in helped),
                          best=max(helped, key=lambda row: row["cg_after_none"] - row["cg_after_0.1"]))
    return snippet(
        "scan_summary", faces_min=min(faces), faces_max=max(faces), most=max(scan, key=lambda row: row["below_0.1"]),
        below_01_min=min(row["below_0.1"] for row in scan),
        below_005_min=min(row["below_0.05"] for row in scan), below_005_max=max(row["below_0.05"] for row in scan),
        below_001_min=min(row["below_0.01"] for row in scan), below_001_max=max(row["below_0.01"] for row in scan),
        none_flat=snippet("none_flat") if minimum.min() > 0.01 else "", cg_min=iterations.min(),
        cg_max=iterations.max(), cg_before=scan[0]["cg_before"], rho=rho, relation=relation, helped=removal)


def joined_sentence(steps, template: PageTemplate) -> str:
    joined = sorted({row["moves"] for row in steps if row["faces_selected"] > 0 and row["area_ratio"] < 0.5})
    none = sorted({row["moves"] for row in steps if row["faces_selected"] == 0})
    text = template.snippet("joined", moves=", ".join(map(str, joined))) if joined else ""
    if none:
        moves = ", ".join(map(str, none))
        text += "; " + template.snippet("none_selected", moves=moves) if text else \
            template.snippet("none_selected_first", moves=moves)
    return text + ". " if text else ""


def steps_summary(steps, template: PageTemplate) -> str:
    if not steps:
        return ""
    snippet = template.snippet
    variants = list(dict.fromkeys(row["variant"] for row in steps))
    lines = []
    for name in variants:
        rows = [row for row in steps if row["variant"] == name]
        lines.append(snippet("step_variant", name=name, areas=", ".join(f"{row['area_ratio']:.2f}" for row in rows),
                             moves=", ".join(str(row["moves"]) for row in rows),
                             pieces=", ".join(str(row["incision_pieces"]) for row in rows)))
    edges = (START - FRONT + DEPTH) * DIVISIONS

    def failing(name):  # the first number of moves from which the incision is mostly lost
        rows = [row for row in steps if row["variant"] == name]
        lost = [row["moves"] for row in rows if row["area_ratio"] < 0.5]
        return min(lost) if lost else None

    fails = {name: failing(name) for name in variants}
    if any(fails.values()):
        first = next(iter(fails.values()))
        lost = snippet("every_variant_lost", moves=first, edges=edges / first) if len(set(fails.values())) == 1 else \
            "; ".join(snippet("variant_lost", name=name, moves=moves, edges=edges / moves)
                      for name, moves in fails.items() if moves)
        sentences = [snippet("incision_lost", lost=lost, joined=joined_sentence(steps, template))]
    else:
        sentences = [snippet("incision_kept")]
    relaxed, still = "snapped, removal at 0.01, relaxed", "snapped, removal at 0.01, not relaxed"
    pairs = []
    for row in steps:
        if row["variant"] != relaxed:
            continue
        twin = next((other for other in steps if other["variant"] == still and other["moves"] == row["moves"]), None)
        if twin is not None and twin["area_ratio"] >= 0.9:  # only where the cut works without relaxation
            pairs.append((row, twin))
    if pairs:
        split = [(row, twin) for row, twin in pairs if row["incision_pieces"] > twin["incision_pieces"]]
        sentences.append(snippet(
            "relaxed_moves", moves=", ".join(str(row["moves"]) for row, _ in pairs),
            area_change=max(abs(row["incision_area"] / twin["incision_area"] - 1) for row, twin in pairs),
            pieces=snippet("gains_pieces", pieces=", ".join(
                snippet("pieces_at", pieces=row["incision_pieces"], faces=row["incision_piece_faces"], moves=row["moves"])
                for row, _ in split)) if split else snippet("one_surface"),
            jagged_ratio=max(row["area_ratio"] for row in steps if row["variant"].startswith("jagged"))))
    return "\n".join(lines) + "\n\n" + " ".join(sentences)


def cylinder_summary(cylinder, template: PageTemplate) -> str:
    if not cylinder:
        return ""
    snippet = template.snippet
    working = [row for row in cylinder if row["faces_dissected"] >= 50]
    failed = list(dict.fromkeys((row["moves_per_cut"], row["offset_rad"], row["faces_per_cut"])
                                for row in cylinder if row["faces_dissected"] < 50))

    def moves(n):
        return snippet("moves" if n > 1 else "one_move", n=n)

    def shares(setting):
        return ", ".join(snippet("share", row=row, moves=moves(row["moves_per_cut"]))
                         for row in working if row["removal"] == setting)

    sentences = [snippet("cylinder_shares", shares_001=shares("0.01"), shares_01=shares("0.1"))]
    if working:
        sentences.append(snippet(
            "faces_per_cut", low=min(min(map(int, row["faces_per_cut"].split("/"))) for row in working),
            high=max(max(map(int, row["faces_per_cut"].split("/"))) for row in working)))
    if failed:
        sentences.append(snippet(
            "small_moves_fail", failed="; ".join(snippet("failed_cut", moves=m, offset=offset, faces=faces)
                                                 for m, offset, faces in failed),
            moves=failed[0][0], edges=1.2 * CYLINDER["radius"] / failed[0][0] / CYLINDER["h"]))
    small = [row for row in cylinder if row["small_pieces"] > 0]
    if small:
        worst = max(small, key=lambda row: row["small_pieces"])
        sentences.append(snippet("free_fragments", n_small=len(small), n_runs=len(cylinder), worst=worst,
                                 moves=moves(worst["moves_per_cut"])))
    return " ".join(sentences)


def quality_summary(cube, other, fresh, template: PageTemplate) -> str:
    snippet = template.snippet
    q = fresh.quality()
    spread = q.aspect_ratio.max() - q.aspect_ratio.min() > 1e-9
    sentences = [snippet("quality_before", low=q.aspect_ratio.min(),
                         spread=snippet("quality_range", high=q.aspect_ratio.max()) if spread else snippet("congruent"),
                         dihedral=np.degrees(q.max_dihedral.max()))]
    for rows in (cube, other):
        if not rows:
            continue
        by = {row["variant"]: row for row in rows}
        sentences.append(snippet(
            "quality_after", cut=rows[0]["cut"].capitalize(), jagged_min=by["jagged (no snapping)"]["min_aspect"],
            snapped_min=by["snapped, no removal"]["min_aspect"],
            snapped_dihedral=by["snapped, no removal"]["max_dihedral_deg"],
            after=", ".join(snippet("aspect_at", min_aspect=row["min_aspect"], threshold=row["threshold"])
                            for row in rows if row["remove"] and "0.9π" not in row["variant"])))
    return " ".join(sentences)


def main(argv=None) -> dict:
    start = time.perf_counter()
    arguments = parse_arguments(__doc__, argv)
    quick, out = arguments.quick, arguments.out
    cube, meshes = cube_rows(quick)
    scan = scan_orientations(quick)
    steps = step_rows(quick)
    cylinder = cylinder_rows(quick)

    fresh = cube_body().mesh
    shown = ("jagged (no snapping)", "snapped, no removal", "removal at 0.01", "removal at 0.1")
    plot_quality({cut: {"before the cut": fresh, **{name: meshes[cut, name] for name in shown}} for cut in CUTS},
                 out / "cutting_quality.png")
    plot_scan(scan, out / "cutting_scan.png")
    pictures = {}
    for name in ("jagged (no snapping)", "snapped, no removal", "removal at 0.1"):
        snap, remove, threshold, large_angle = VARIANTS[name]
        body = cube_body()
        cg(body, "picture").solve()
        cutter = snede.TetrahedralCutter(body, snap=snap, remove_degeneracies=remove, min_aspect_ratio=threshold,
                                         large_angle=large_angle)
        cutter.cut(blade_path(1))
        apply_traction(body)
        cg(body, "picture").solve()
        pictures[name] = (body, cutter.incision_faces())
    plot_incisions(pictures, out / "cutting_incision.png")

    write_csv(out / "cutting.csv", cube + scan + steps + cylinder)
    text = describe(cube, scan, steps, cylinder, fresh, quick, (time.perf_counter() - start) / 60)
    (out / "cutting.md").write_text(text + "\n" + organ_cuts.section_for_cutting(out))
    print(f"wrote {out / 'cutting.md'}, cutting.csv, cutting_quality.png, cutting_scan.png, cutting_incision.png "
          f"in {time.perf_counter() - start:.0f} s")
    return {"cube": cube, "scan": scan, "steps": steps, "cylinder": cylinder}


if __name__ == "__main__":
    main()
