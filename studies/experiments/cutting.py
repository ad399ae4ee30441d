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
from studies.experiments.common import Column, markdown_table, options_prefix, parse_arguments, pyplot, write_csv

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
    total = snede.CutReport()
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
                total = snede.CutReport()
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
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


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
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


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
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


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


def comparison_table(cube) -> str:
    by = {row["variant"]: row for row in cube}
    snapped, thesis_like = by["snapped, no removal"], by["removal at 0.01"]
    strongest = by["removal at 0.1"]
    lines = ["| quantity | thesis (§3.3, Figures 3.14–3.16) | snede |", "|---|---|---|"]
    entries = [
        ("mesh", f"{THESIS['elements']} elements, {THESIS['nodes']} nodes",
         f"{snapped['elements']} elements, {cube_nodes()} nodes"),
        ("faces dissected", THESIS["faces_dissected"], snapped["faces_dissected"]),
        ("repositionings that failed", f"{THESIS['failed_repositionings']} (spikes in Figure 3.14)",
         f"{snapped['snaps_refused']} snaps refused"),
        ("degenerate elements (aspect < 0.01) after the cut", THESIS["degenerate"],
         f"{snapped['below_0.01']} (min aspect {snapped['min_aspect']:.4f}); {snapped['below_0.05']} below 0.05, "
         f"{snapped['below_0.1']} below 0.1"),
        ("CG iterations after the cut, no removal", THESIS["iterations_degenerate"], snapped["cg_after"]),
        ("edge collapses at 0.01 / 0.99π", THESIS["collapses"],
         f"{thesis_like['edges_collapsed']} (at 0.1: {strongest['edges_collapsed']})"),
        ("incollapsible elements cut free", THESIS["incollapsible"],
         f"{thesis_like['elements_cut_free']} (at 0.1: {strongest['elements_cut_free']})"),
        ("elements / nodes after removal", f"{THESIS['elements_after']} / {THESIS['nodes_after']}",
         f"{thesis_like['elements']} / {thesis_like['nodes']} (at 0.1: {strongest['elements']} / "
         f"{strongest['nodes']})"),
        ("CG iterations after the cut, with removal", THESIS["iterations_removed"],
         f"{thesis_like['cg_after']} (at 0.1: {strongest['cg_after']})"),
        ("time of the removal", f"{THESIS['removal_seconds']} s (Pentium III, 1 GHz)",
         f"{_ms(thesis_like['removal_seconds'])} (at 0.1: {_ms(strongest['removal_seconds'])}); whole cut "
         f"{thesis_like['cut_seconds'] * 1e3:.1f} ms"),
    ]
    lines += [f"| {a} | {b} | {c} |" for a, b, c in entries]
    return "\n".join(lines) + "\n"


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
    other = [row for row in cube if row["cut"] != "diagonal"]
    cube_all, cube = cube, [row for row in cube if row["cut"] == "diagonal"]
    by = {row["variant"]: row for row in cube}
    snapped, jagged = by["snapped, no removal"], by["jagged (no snapping)"]
    removal = [row for row in cube if row["remove"]]
    zero_scan = sum(row["below_0.01"] == 0 for row in scan)
    lines = [
        "# §3.3 cutting: the diagonal cut in the cube, steps, pie-like cuts, element quality", "",
        "Regenerate with `.venv/bin/python -m studies.experiments.cutting" + (" --quick`" if quick else "`")
        + " (this file, `cutting.csv`, `cutting_quality.png`, `cutting_scan.png`, `cutting_incision.png`)"
        + (". **Quick run: reduced variants and sizes.**" if quick else f"; this run took {minutes:.1f} min on the "
           "2-core development machine") + f", with snede at {engine_version()}. The numbers depend on the "
        "cutter's details (face selection, snapping rules), which were still changing when this was written.", "",
        "The cutter is `snede.TetrahedralCutter` (§3.2: face selection by closest nodes, node snapping in the "
        "deformed body, dissection §7.3, degeneracy removal by shape, free pieces fixed). Unlike the thesis's "
        "prototype, snede's node snapping refuses any move that would make an element of the vertex's star flat or "
        "inverted (exact predicates, in the reference and the deformed configuration); this is the main reason "
        "the numbers below differ from the thesis's.", "",
        "## (a) The large diagonal cut in the cube (Figures 3.5, 3.14–3.16)", "",
        f"`snede.meshing.box((1, 1, 1), (8, 8, 8))`: {snapped['elements']} tetrahedra and {cube_nodes()} nodes as in the "
        f"thesis (6 tetrahedra per cube, Kuhn split). Linear elastic, E = {YOUNG:g} Pa, ν = {POISSON}; back face "
        f"z = 0 fixed; an outward traction of {TRACTION:g} Pa on the four side faces (x = 0, 1 and y = 0, 1), "
        "lumped onto their nodes (a third of each boundary face's force per corner) and lumped again after the cut "
        "so that the vertex copies on the sides carry their share. Linear CG with ‖r‖ < 1e-3‖f‖ (criterion (6.8)): "
        f"{snapped['cg_before']} iterations from zero before the cut; 'CG after cut' continues from the state before "
        "the cut, as the thesis's counts do.", "",
        f"The cut: a straight blade along the front face's diagonal (from (0, 1, 1) to (1, 0, 1), {2 * HALF_BLADE} "
        f"long so that it spans the dilated face) moved straight back along −z from z = {START} (outside) to "
        f"z = {FRONT - DEPTH:g} (65 % of the depth) in **one move**, i.e. one swept quadrilateral processed as two "
        "sweep triangles, in deformed coordinates: the vertical diagonal plane x + y = 1 (where the deformed body "
        f"is). It dissects {snapped['faces_dissected']} faces, against the thesis's 108. The thesis does not give "
        "its cut's plane; its Figure 3.14 shows a large diagonal cut, and the scan below shows how strongly the "
        "counts depend on the orientation. Cut times are medians of "
        f"{1 if quick else REPEATS} cuts; 'removal' is the difference from the snapped cut without removal.", "",
        markdown_table(cube_all, CUBE_COLUMNS),
        "Next to the thesis (the diagonal cut):", "", comparison_table(cube),
        "![incisions](cutting_incision.png)", "",
        cube_summary(cube, scan), "", other_cut_summary(other), "",
        "### The angle of the cut", "",
        "The thesis notes that in generated cubes the frequency of degeneracies correlates strongly with the angle "
        "of the cut (the mesh has six orientations of tetrahedra). One-move cuts, each dissecting about a hundred "
        "faces: the blade at 45° (the diagonal), 30° and 15° to the x axis in the front face, its sweep tilted by 0°, "
        "15° or 30° from −z, through the face's centre or shifted by 0.3 element; each cut without removal and with "
        "removal at 0.01 and at 0.1 (three separate runs). CG iterations after the cut against the smallest aspect "
        "ratio the cut left:", "",
        markdown_table(scan, SCAN_COLUMNS),
        "![CG iterations against the worst element](cutting_scan.png)", "",
        scan_summary(scan), "",
        "## (b) The same cut in steps, relaxed in between (Figure 3.17)", "",
        f"The blade path of (a) divided into {steps[0]['moves'] if steps else 1}–"
        f"{max((row['moves'] for row in steps), default=1)} "
        f"equal moves (each move two sweep triangles; one move advances the blade {START - FRONT + DEPTH:g}/moves, i.e. "
        f"{(START - FRONT + DEPTH) * DIVISIONS:.1f}/moves element edges). 'Relaxed': after every "
        "move the traction is lumped again and CG relaxes the body before the next move (the thesis's interactive "
        "loop), so the opening incision moves the material relative to the blade. 'Incision pieces' counts the "
        "pieces of the incision surface (its faces joined through edges; one connected incision is 1); 'incision "
        "area' is measured in the reference configuration (half the area of the incision's faces, one lip); "
        "'of one move' divides it by the one-move cut of the same variant.", "",
        markdown_table(steps, STEP_COLUMNS),
        steps_summary(steps), "",
        "## (c) Pie-like cuts in an unstructured cylinder (Figure 3.13)", "",
        f"`snede.meshing.cylinder({CYLINDER['length']}, {CYLINDER['radius']}, h={0.012 if quick else CYLINDER['h']}, "
        f"seed={CYLINDER['seed']})` "
        "(gmsh Delaunay, optimised): "
        + (f"{cylinder[0]['elements_before']} tetrahedra and {cylinder[0]['vertices_before']} vertices (the thesis's "
           f"Delaunay tetrahedralization of a cylindrical point cloud: {THESIS_CYLINDER['elements']} and "
           f"{THESIS_CYLINDER['vertices']}). " if cylinder else "")
        + "Three pie-like cuts: a blade parallel to the axis, slightly longer than the cylinder, moved from the axis "
        f"outward to 1.2 radii in {' or '.join(str(m) for m in dict.fromkeys(row['moves_per_cut'] for row in cylinder))} "
        "moves, at angles θ, θ + 120° and θ + 240°, on the bare "
        "mesh (no body), each cut with a new cutter (the scalpel lifted in between). The thesis's 'three large "
        f"pie-like cuts (45 faces)' dissect 873 faces in all; we read the 45 as sweep steps, 3 × {PIE_MOVES} moves. "
        "Its finding: edge collapses are about 5 % of the faces "
        "dissected, with a handful of incollapsible elements, whatever the orientation.", "",
        markdown_table(cylinder, CYLINDER_COLUMNS),
        cylinder_summary(cylinder), "",
        "## (d) Element quality before and after", "",
        "![aspect ratio and dihedral angle histograms](cutting_quality.png)", "",
        quality_summary(cube, other, fresh), "",
        "## Cost per sweep triangle", "",
        "The time of a sweep triangle against the mesh size (boxes of 10³–10⁶ tetrahedra, the same cut in units of "
        "the mesh spacing) is measured by `.venv/bin/python studies/benchmarks/cutting_rates.py`; see the README's "
        "benchmark section.", "",
    ]
    return "\n".join(lines) + "\n"


def shapes(row) -> str:
    names = ("needles", "spindles", "slivers", "caps")
    found = [f"{row[name]} {name}" for name in names if row[name]]
    return ", ".join(found) if found else "none"


def cube_summary(cube, scan) -> str:
    by = {row["variant"]: row for row in cube}
    snapped, jagged = by["snapped, no removal"], by["jagged (no snapping)"]
    at_001 = by["removal at 0.01"]
    removal = [row for row in cube if row["remove"]]
    larger = [row for row in removal if row["threshold"] != 0.01]
    zero_scan = sum(row["below_0.01"] == 0 for row in scan)
    text = [
        f"**What agrees.** The cut is of the thesis's size ({snapped['faces_dissected']} faces dissected against "
        f"108, on the same mesh) and dissection keeps the number of elements ({jagged['elements']}; the nodes grow "
        f"from {cube_nodes()} to {snapped['nodes']} by the vertex copies). Without snapping the incision is jagged "
        "(Figure 3.5) and every element keeps its shape (min aspect ratio "
        f"{jagged['min_aspect']:.3f}, the mesh's own); snapping makes the incision smooth (Figure 3.14) and thins the "
        f"elements next to it (min aspect {snapped['min_aspect']:.4f})"
        + (f", {snapped['below_0.01']} of them below the thesis's threshold 0.01, and CG then needs "
           f"{snapped['cg_after']} iterations after the cut against {jagged['cg_after']} after the jagged one. "
           f"Removal at 0.01 brings that back to {at_001['cg_after']} iterations (thesis: from 2439 to 236) and "
           f"barely changes the mesh size ({at_001['elements']} elements, {at_001['nodes']} nodes; thesis: 3034 "
           "and 823)." if snapped["below_0.01"] else
           f"; CG needs {snapped['cg_after']} iterations after the cut against {jagged['cg_after']} after the jagged "
           "one."),
        "",
        f"**What differs.** The number of degenerate elements: {snapped['below_0.01']} below 0.01 here against the "
        f"thesis's 143, and CG {snapped['cg_after']} iterations without removal against 2439. snede's snapping never "
        "makes an element exactly flat or inverted (it refuses such a move, in both configurations) and moves a vertex "
        "on an edge of the body only along that edge (a corner not at all); it refused "
        f"{snapped['snaps_refused']} of {snapped['vertices_snapped'] + snapped['snaps_refused']} snaps here (the "
        "thesis reports 2 failed repositionings, the spikes of Figure 3.14)"
        + (f". In the orientation scan below {zero_scan} of {len(scan)} one-move cuts leave no element below 0.01"
           if scan else "") + ". "
        f"The removal at 0.01 finds {at_001['degenerate_found']} degenerate elements ({shapes(at_001)}) and makes "
        f"{at_001['edges_collapsed']} collapses, {at_001['edges_split']} edge splits and cuts "
        f"{at_001['elements_cut_free']} elements free (thesis: 99 collapses, 13 cut free)"
        + (f". Without removal these elements have a very short edge (median shortest/longest edge "
           f"{snapped['flat_edge_ratio']:.3f}) and no large dihedral angle (at most "
           f"{snapped['flat_max_dihedral_deg']:.0f}°)"
           + (f"; in {snapped['flat_at_crease']} of them that edge ends at a vertex on an edge of the cube (where "
              "the diagonal meets the vertical edges x = 1, y = 0 and x = 0, y = 1): snapping moved a vertex of the "
              "side face next to it" if snapped["flat_at_crease"] else "")
           + ". Collapsing the short edge removes the elements around it"
           if snapped.get("flat_edge_ratio") is not None and at_001["needles"] == at_001["degenerate_found"] > 0
           else "")
        + ". At larger thresholds: "
        + "; ".join(f"{row['threshold']:g}{' with large angle 0.9π' if '0.9π' in row['variant'] else ''}: "
                    f"{row['degenerate_found']} found ({shapes(row)}), {row['edges_collapsed']} collapses, "
                    f"{row['edges_split']} edge splits, {row['elements_cut_free']} cut free, min aspect "
                    f"{row['min_aspect']:.3f} after, CG {row['cg_after']}" for row in larger) + "."]
    if all(row["degenerate_found"] == 0 for row in larger):
        text[-1] += " Even at 0.1 this cut leaves nothing to remove; some orientations of the scan below do."
    text += ["", f"Removal time: {_ms(at_001['removal_seconds'])} at 0.01 and "
             f"{_ms(by['removal at 0.1']['removal_seconds'])} at 0.1 (medians of whole cuts minus the cut without "
             f"removal; whole cut {at_001['cut_seconds'] * 1e3:.1f} ms; differences of a few ms are within the noise of "
             "the shared machine), against the thesis's 0.7 s on a 1 GHz Pentium III for 99 collapses. The removal "
             "only visits the elements around the dissected faces."]
    return "\n".join(text)


def other_cut_summary(rows) -> str:
    if not rows:
        return ""
    by = {row["variant"]: row for row in rows}
    snapped = by["snapped, no removal"]
    removal = [row for row in rows if row["remove"]]
    cut = rows[0]["cut"]
    return (f"**The {cut} cut** (same path, the blade at 15° to the x axis instead of 45°) leaves many thin elements "
            f"but none flat: {snapped['faces_dissected']} faces dissected, "
            f"{snapped['below_0.01']} elements below 0.01, {snapped['below_0.05']} below 0.05 and "
            f"{snapped['below_0.1']} below 0.1 (min {snapped['min_aspect']:.4f}), CG {snapped['cg_after']} after the "
            f"cut without removal (jagged: {by['jagged (no snapping)']['cg_after']}). With the large angle at 0.99π "
            "(178.2°) "
            "its thin elements have no dihedral angle that large and count as needles; at 0.9π the other shapes of "
            "§3.2.3 appear. Removal: "
            + "; ".join(f"at {row['threshold']:g}{' with large angle 0.9π' if '0.9π' in row['variant'] else ''}: "
                        f"{row['degenerate_found']} found ({shapes(row)}), {row['edges_collapsed']} collapses, "
                        f"{row['edges_split']} edge splits, {row['elements_cut_free']} cut free, {row['elements']} "
                        f"elements and {row['nodes']} nodes after, min aspect {row['min_aspect']:.3f}, CG "
                        f"{row['cg_after']}, removal {_ms(row['removal_seconds'])}" for row in removal) + ".")


def scan_summary(scan) -> str:
    if not scan:
        return ""
    faces = [row["faces_dissected"] for row in scan]
    most = max(scan, key=lambda row: row["below_0.1"])
    minimum = np.array([row["min_aspect"] for row in scan])
    iterations = np.array([row["cg_after_none"] for row in scan])
    rho = float(np.corrcoef(np.argsort(np.argsort(minimum)), np.argsort(np.argsort(iterations)))[0, 1])
    helped = [row for row in scan if row["collapses_0.1"] > 0]
    text = (f"Faces dissected range over {min(faces)}–{max(faces)}; elements below 0.1 after the cut from "
            f"{min(row['below_0.1'] for row in scan)} to {most['below_0.1']} (blade {most['angle_deg']:g}°, tilt "
            f"{most['tilt_deg']:g}°), below 0.05 from {min(row['below_0.05'] for row in scan)} to "
            f"{max(row['below_0.05'] for row in scan)}, below 0.01 from {min(row['below_0.01'] for row in scan)} to "
            f"{max(row['below_0.01'] for row in scan)}: the thin elements do depend strongly on the orientation, as "
            f"the thesis says{', but none of these cuts comes near flat' if minimum.min() > 0.01 else ''}. "
            f"CG after the cut takes {iterations.min()}–"
            f"{iterations.max()} iterations without removal (the uncut body {scan[0]['cg_before']} from zero); the "
            f"rank correlation between the smallest aspect ratio and the CG count is {rho:+.2f}: ")
    text += ("the count follows the worst element (a negative correlation: thinner, more iterations). " if rho < -0.5
             else "no clear relation; the count follows the cut's orientation and extent, i.e. how far the solution "
             "has to move after the cut (mean CG by tilt: " + ", ".join(
                 f"{tilt:g}°: {np.mean([row['cg_after_none'] for row in scan if row['tilt_deg'] == tilt]):.0f}"
                 for tilt in dict.fromkeys(row["tilt_deg"] for row in scan)) + "). ")
    if helped:
        best = max(helped, key=lambda row: row["cg_after_none"] - row["cg_after_0.1"])
        text += (f"Removal at 0.1 collapses edges after {len(helped)} of the {len(scan)} cuts and changes their CG "
                 "counts by " + ", ".join(f"{row['cg_after_0.1'] - row['cg_after_none']:+d}" for row in helped)
                 + f"; the largest saving is on the cut with the blade at {best['angle_deg']:g}°, tilt "
                 f"{best['tilt_deg']:g}° (min aspect {best['min_aspect']:.4f}): {best['cg_after_none']} to "
                 f"{best['cg_after_0.1']} iterations, as in the thesis (2439 to 236), where the cut's elements were "
                 "flatter still.")
    return text


def joined_sentence(steps) -> str:
    joined = sorted({row["moves"] for row in steps if row["faces_selected"] > 0 and row["area_ratio"] < 0.5})
    none = sorted({row["moves"] for row in steps if row["faces_selected"] == 0})
    text = ""
    if joined:
        text += (f"At {', '.join(map(str, joined))} moves faces are still selected but stay joined (the dissection "
                 "opens a face only where the selected faces around its vertices close into a surface)")
    if none:
        text += ("; at " if text else "At ") + f"{', '.join(map(str, none))} moves none is selected"
    return text + ". " if text else ""


def steps_summary(steps) -> str:
    if not steps:
        return ""
    variants = list(dict.fromkeys(row["variant"] for row in steps))
    lines = []
    for name in variants:
        rows = [row for row in steps if row["variant"] == name]
        lines.append(f"* *{name}*: area " + ", ".join(f"{row['area_ratio']:.2f}" for row in rows)
                     + " of the one-move cut for " + ", ".join(str(row["moves"]) for row in rows)
                     + " moves; incision pieces " + ", ".join(str(row["incision_pieces"]) for row in rows) + ".")
    text = "\n".join(lines) + "\n\n"
    edges = (START - FRONT + DEPTH) * DIVISIONS

    def failing(name):  # the first number of moves from which the incision is mostly lost
        rows = [row for row in steps if row["variant"] == name]
        lost = [row["moves"] for row in rows if row["area_ratio"] < 0.5]
        return min(lost) if lost else None

    fails = {name: failing(name) for name in variants}
    if any(fails.values()):
        text += ("**The incision depends on the step size, whether or not the body moves between moves.** "
                 + ("Every variant loses it from " + f"{next(iter(fails.values()))} moves on "
                    f"({edges / next(iter(fails.values())):.2f} element edges per move)"
                    if len(set(fails.values())) == 1 else
                    "; ".join(f"{name}: lost from {moves} moves on ({edges / moves:.2f} element edges per move)"
                              for name, moves in fails.items() if moves))
                 + ". " + joined_sentence(steps) + "The likely cause (from reading the code, not verified by changing it): a "
                 "tetrahedron selects a face only when the crossings of the current and a few recent "
                 "sweep triangles (the last four in engine/cutting/face_selection.hpp) mark three of its corners, so "
                 "when the blade needs more moves than that to cross an element, its crossings are forgotten before "
                 "it is complete. The thesis keeps the crossings of an incomplete tetrahedron for as long as the "
                 "scalpel is in it (§3.2.1, Figure 3.4). ")
    else:
        text += "No variant loses its incision as the moves get smaller. "
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
        text += ("Where the cut works without relaxation (" + ", ".join(str(row["moves"]) for row, _ in pairs)
                 + " moves), relaxing between moves (the Figure 3.17 setting: the incision opens and the material "
                 "moves relative to the blade) keeps the area within "
                 f"{max(abs(row['incision_area'] / twin['incision_area'] - 1) for row, twin in pairs):.0%} of the "
                 "unrelaxed cut's; the incision "
                 + ("stays one connected surface" if not split else
                    "gains pieces: " + ", ".join(f"{row['incision_pieces']} pieces ({row['incision_piece_faces']} "
                                                 f"faces) at {row['moves']} moves" for row, _ in split)
                    + ", the disconnection of Figure 3.17 on a small scale")
                 + ". snede's scalpel is given in deformed coordinates and each sweep re-reads the deformed mesh, so "
                 "the body's motion between moves is followed; the thesis's stored crossings were not. The jagged cut "
                 "with relaxation dissects more faces than in one move (area ratio up to "
                 f"{max(row['area_ratio'] for row in steps if row['variant'].startswith('jagged')):.2f}): the "
                 "opening lips move into the blade's later sweeps.")
    return text


def cylinder_summary(cylinder) -> str:
    if not cylinder:
        return ""
    working = [row for row in cylinder if row["faces_dissected"] >= 50]
    failed = list(dict.fromkeys((row["moves_per_cut"], row["offset_rad"], row["faces_per_cut"])
                                for row in cylinder if row["faces_dissected"] < 50))

    def shares(setting):
        rows = [row for row in working if row["removal"] == setting]
        return ", ".join(f"{row['collapse_share']:.1%} ({row['edges_collapsed']}/{row['faces_dissected']}, "
                         f"{row['elements_cut_free']} cut free; θ = {row['offset_rad']:.1f}, {row['moves_per_cut']} "
                         f"move{'s' if row['moves_per_cut'] > 1 else ''})" for row in rows)

    text = (f"Edge collapses as a share of the faces dissected, at the thesis's threshold 0.01: {shares('0.01')}; at "
            f"0.1: {shares('0.1')}. The thesis finds about 5 % at 0.01 with a handful of incollapsible elements; "
            "with snede's guarded snapping that share is reached only at a ten times larger threshold. The three "
            "directions give counts of the same size (columns 'per cut'), as the thesis says for the unstructured "
            "mesh. ")
    if working:
        text += (f"Faces dissected per cut: {min(min(map(int, row['faces_per_cut'].split('/'))) for row in working)}–"
                 f"{max(max(map(int, row['faces_per_cut'].split('/'))) for row in working)} "
                 f"(thesis: 873 for three cuts in a mesh of 4020 elements, about 290 per cut; its cuts were larger "
                 "than ours or counted both lips, it does not say). ")
    if failed:
        text += ("**With small moves the cuts fail:** "
                 + "; ".join(f"{moves} moves per cut (θ = {offset:.1f}): {faces} faces dissected"
                             for moves, offset, faces in failed)
                 + f". {failed[0][0]} moves of 1.2 radii are {1.2 * CYLINDER['radius'] / failed[0][0] / CYLINDER['h']:.2f} "
                 "target edge lengths per move, too short for the face selection (see (b)); the vertices are "
                 "snapped all the same, which is why removal still finds and collapses elements there. ")
    small = [row for row in cylinder if row["small_pieces"] > 0]
    if small:
        worst = max(small, key=lambda row: row["small_pieces"])
        text += (f"**Free fragments:** {len(small)} of {len(cylinder)} runs leave small free pieces besides the body "
                 f"(up to {worst['small_pieces']} pieces of fewer than 20 elements, {worst['small_piece_elements']} "
                 f"elements in all, with {worst['moves_per_cut']} move{'s' if worst['moves_per_cut'] > 1 else ''} per "
                 "cut): tetrahedra all of whose faces were dissected. A single pie cut on this mesh shows them when it "
                 "is made as two sweep triangles (one move) with snapping, not as one large sweep triangle and not "
                 "without snapping; its fragments lie within about an element of the diagonal the two triangles "
                 "share and are bounded partly by faces off the cut plane, so the second triangle seems to select "
                 "faces around vertices the first one had snapped onto the plane. With a body attached the cutter "
                 "fixes each such piece on one face (§3.3).")
    return text


def quality_summary(cube, other, fresh) -> str:
    q = fresh.quality()
    text = (f"Before the cut every element of the Kuhn cube has aspect ratio {q.aspect_ratio.min():.3f}"
            + (f"–{q.aspect_ratio.max():.3f}" if q.aspect_ratio.max() - q.aspect_ratio.min() > 1e-9 else
               " (the six tetrahedra of a cube are congruent)")
            + f" and largest dihedral angle {np.degrees(q.max_dihedral.max()):.0f}°. ")
    for rows in (cube, other):
        if not rows:
            continue
        by = {row["variant"]: row for row in rows}
        text += (f"{rows[0]['cut'].capitalize()} cut: the jagged cut leaves the elements as they were (min aspect "
                 f"{by['jagged (no snapping)']['min_aspect']:.3f}); snapping spreads those around the cut towards "
                 f"small aspect ratios (min {by['snapped, no removal']['min_aspect']:.4f}, largest dihedral angle "
                 f"{by['snapped, no removal']['max_dihedral_deg']:.1f}°); after removal the smallest aspect ratio is "
                 + ", ".join(f"{row['min_aspect']:.3f} at {row['threshold']:g}" for row in rows
                             if row["remove"] and "0.9π" not in row["variant"]) + ". ")
    return text


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
