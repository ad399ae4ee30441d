"""Random scalpel cuts through real and organ-like shapes (issue 32): does a cut separate
exactly what it spans, with and without the body relaxing between the scalpel's moves?

    .venv/bin/python -m studies.experiments.organ_cuts [--quick] [--out DIR] [--cuts N]

The shapes, the blades and the independent count of the pieces a cut should leave are described
on the page (studies/templates/organ_cuts.md).

Writes organ_cuts.md and organ_cuts.csv (one row per cut).
"""
from __future__ import annotations

import csv
import importlib.util
import math
import sys
import time
import warnings
from dataclasses import dataclass, replace

import numpy as np

import snede
from studies.experiments.common import _REPOSITORY, Column, PageTemplate, markdown_table, parse_arguments, write_csv

E, NU, DENSITY, GRAVITY = 5e3, 0.45, 1000.0, 9.81
MOVES = 12
RESOLVED_CELLS = 50       # blades whose expected pieces are all at least this big; a smaller
                          # piece of the cut body is a fragment (the cutter removes up to 10)
RELAXATION_RTOL = 1e-4


def _organ_meshes_module():
    path = _REPOSITORY / "studies" / "benchmarks" / "organ_meshes.py"
    spec = importlib.util.spec_from_file_location("organ_meshes", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["organ_meshes"] = module
    spec.loader.exec_module(module)
    return module


def shapes(quick: bool) -> dict:
    """name → factory of a fresh mesh (cut meshes are not reused)."""
    h = 0.012 if quick else 0.009
    made = {
        "ellipsoid": lambda: snede.meshing.ellipsoid((0.06, 0.04, 0.03), h=h, seed=1),
        "torus": lambda: snede.meshing.torus(0.05, 0.02, h=h, seed=1),
        "lumpy-0": lambda: snede.meshing.lumpy(0.04, lumps=6, h=h, seed=0),
        "lumpy-1": lambda: snede.meshing.lumpy(0.04, lumps=8, h=h, seed=1),
    }
    organs = _organ_meshes_module()
    for name in ("liver",) if quick else ("liver", "liver2"):
        made[name] = lambda name=name: organs.organ_mesh(name, 1500 if quick else 3000)
    return made


@dataclass(frozen=True)
class Blade:
    """The scalpel: centre + s·direction for |s| ≤ half_length, moved from travel_from to
    travel_to along ``travel`` (offsets of the centre), in MOVES steps."""

    centre: np.ndarray
    direction: np.ndarray
    travel: np.ndarray
    half_length: float
    travel_from: float
    travel_to: float

    @property
    def normal(self) -> np.ndarray:
        return np.cross(self.direction, self.travel)

    def positions(self) -> np.ndarray:
        offsets = np.linspace(self.travel_from, self.travel_to, MOVES + 1)
        ends = np.array([-self.half_length, self.half_length])
        return (self.centre + offsets[:, None, None] * self.travel + ends[None, :, None] * self.direction)


def random_blade(rng, points: np.ndarray, full: bool) -> Blade:
    lo, hi = points.min(0), points.max(0)
    diameter = float(np.linalg.norm(hi - lo))
    centre = lo + rng.uniform(0.3, 0.7, size=3) * (hi - lo)
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    travel = rng.normal(size=3)
    travel -= travel.dot(direction) * direction
    travel /= np.linalg.norm(travel)
    # From outside the body to outside on the far side, or to a point inside it.
    reach = diameter if full else rng.uniform(-0.15, 0.15) * diameter
    return Blade(centre, direction, travel, diameter, -diameter, reach)


def face_neighbours(cells: np.ndarray) -> np.ndarray:
    """(m, 2) pairs of cells sharing a triangle."""
    faces = np.sort(np.concatenate([cells[:, [1, 2, 3]], cells[:, [0, 2, 3]], cells[:, [0, 1, 3]], cells[:, [0, 1, 2]]]), axis=1)
    owner = np.tile(np.arange(len(cells)), 4)
    order = np.lexsort(faces.T[::-1])
    faces, owner = faces[order], owner[order]
    same = np.all(faces[1:] == faces[:-1], axis=1)
    return np.column_stack([owner[:-1][same], owner[1:][same]])


def components(n: int, pairs: np.ndarray) -> np.ndarray:
    """Labels 0.. of the connected components of n nodes joined by ``pairs`` (union-find)."""
    parent = np.arange(n)

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    for a, b in pairs:
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    roots = np.array([root(i) for i in range(n)])
    return np.unique(roots, return_inverse=True)[1]


def expected_pieces(positions: np.ndarray, cells: np.ndarray, blade: Blade) -> np.ndarray:
    """Per cell, the piece the cut should leave it in: the flood fill across faces whose
    centroid-to-centroid segment does not cross the swept region."""
    centroids = positions[cells].mean(axis=1)
    pairs = face_neighbours(cells)
    side = (centroids - blade.centre) @ blade.normal
    a, b = side[pairs[:, 0]], side[pairs[:, 1]]
    crosses = a * b < 0
    t = np.where(crosses, a / np.where(crosses, a - b, 1.0), 0.0)
    hit = centroids[pairs[:, 0]] + t[:, None] * (centroids[pairs[:, 1]] - centroids[pairs[:, 0]]) - blade.centre
    along, travelled = hit @ blade.direction, hit @ blade.travel
    inside = (np.abs(along) <= blade.half_length) & (travelled >= blade.travel_from) & (travelled <= blade.travel_to)
    return components(len(cells), pairs[~(crosses & inside)])


def held_body(mesh: snede.Mesh) -> snede.Body:
    """Neo-Hookean under gravity, held on a patch of its top (within a quarter of the smaller
    horizontal extent of the top's highest point)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ν = 0.45 warns of locking, known and accepted here
        body = snede.Body(mesh, snede.NeoHookean(E, NU), density=DENSITY)
    p = mesh.points
    lo, hi = p.min(0), p.max(0)
    top = p[np.argmax(p[:, 2])]
    near = np.linalg.norm(p[:, :2] - top[:2], axis=1) < 0.25 * (hi - lo)[:2].min()
    held = near & (p[:, 2] > hi[2] - 0.25 * (hi - lo)[2])
    body.fix(held)
    body.add_gravity((0.0, 0.0, -GRAVITY))
    return body


def piece_volumes(mesh: snede.Mesh) -> np.ndarray:
    _, labels = mesh.connected_components()
    return np.bincount(labels, weights=mesh.quality().volume)


def one_cut(name: str, mesh: snede.Mesh, blade: Blade, relaxed: bool, expected: np.ndarray,
            mean_cell: float, max_fragment_elements: int = 10) -> dict:
    volume_before = float(mesh.quality().volume.sum())
    body = held_body(mesh)
    solver = snede.StaticSolver(body, "newton", rtol=RELAXATION_RTOL)
    first = solver.solve()
    cutter = snede.TetrahedralCutter(body, max_fragment_elements=max_fragment_elements)
    cut_ms, solves_failed, invalid, removed = [], 0, None, 0
    for k, scalpel in enumerate(blade.positions()):
        report = cutter.move(scalpel)
        cut_ms.append(report.seconds * 1e3)
        removed += report.fragments_removed
        try:
            mesh.validate()
        except Exception as error:  # counted, not raised: the table shows every failure
            invalid = invalid or f"move {k}: {error}"
        if relaxed and k > 0:
            solves_failed += not solver.solve().converged
    volumes = piece_volumes(mesh)
    big = int(np.sum(volumes >= RESOLVED_CELLS * mean_cell))
    return {"shape": name, "cells": expected.size, "relaxed": relaxed,
            "full": blade.travel_to > 0.5 * blade.half_length, "expected": int(expected.max() + 1),
            "pieces": int(volumes.size), "big pieces": big, "fragments": int(volumes.size - big),
            "wrong": int(big != expected.max() + 1), "smallest piece (cells)": float(volumes.min() / mean_cell),
            "fragments removed": removed, "volume change %": 100 * (volumes.sum() / volume_before - 1),
            "invalid": invalid or "", "first solve": first.reason, "solves failed": solves_failed,
            "cut ms median": float(np.median(cut_ms[1:])), "cut ms max": float(np.max(cut_ms[1:]))}


def draw_blade(rng, reference: snede.Mesh, positions: np.ndarray, full: bool) -> tuple[Blade, np.ndarray, int]:
    """A random blade (random_blade) whose pieces, by the independent flood fill of the mesh at
    ``positions``, are each at least RESOLVED_CELLS mean cells and do not change when the sweep
    ends two edge lengths earlier or later (where a partial cut ends, the cut surface is only
    placed to within an element or two: the tetrahedra the scalpel is still in are cut with the
    next move, Figure 3.4). Returns the blade, its expected piece labels and the blades drawn
    and dropped before it."""
    volumes = reference.quality().volume
    mean_cell = float(volumes.mean())
    edge = (6 * math.sqrt(2) * mean_cell) ** (1 / 3)
    redrawn = 0
    while True:
        blade = random_blade(rng, positions, full=full)
        expected = expected_pieces(positions, reference.cells, blade)
        shorter, longer = (expected_pieces(positions, reference.cells, replace(blade, travel_to=blade.travel_to + shift))
                           for shift in (-2 * edge, 2 * edge))
        resolved = np.bincount(expected, weights=volumes).min() >= RESOLVED_CELLS * mean_cell
        if resolved and shorter.max() == expected.max() == longer.max():
            return blade, expected, redrawn
        redrawn += 1


def run(quick: bool, cuts_per_shape: int, seed: int = 0, progress=print, max_fragment_elements: int = 10) -> list[dict]:
    rng = np.random.default_rng(seed)
    rows = []
    for name, make in shapes(quick).items():
        reference = make()
        mean_cell = float(reference.quality().volume.mean())
        # The configuration the scalpel is placed in: the body relaxed under gravity.
        settled = held_body(reference)
        snede.StaticSolver(settled, "newton", rtol=RELAXATION_RTOL).solve()
        positions = reference.points + settled.displacement
        redrawn = 0
        for k in range(cuts_per_shape):
            blade, expected, redraws = draw_blade(rng, reference, positions, full=bool(k % 2 == 0))
            redrawn += redraws
            row = one_cut(name, make(), blade, relaxed=bool((k // 2) % 2 == 0), expected=expected, mean_cell=mean_cell,
                          max_fragment_elements=max_fragment_elements)
            row["redrawn"] = redrawn
            rows.append(row)
            if progress:
                progress(f"{name} cut {k + 1}/{cuts_per_shape}: expected {row['expected']}, got {row['big pieces']}"
                         f" + {row['fragments']} fragments ({'relaxed' if row['relaxed'] else 'no solves'})")
    return rows


COLUMNS = [Column("shape", "shape"), Column("cells", "cells"), Column("cuts", "cuts"), Column("relaxed", "relaxed"),
           Column("wrong", "wrong piece counts"), Column("fragments", "fragments"), Column("invalid", "invalid meshes"),
           Column("smallest", "smallest piece (mean cells)", "{:.0f}"), Column("median", "cut ms median", "{:.2f}"),
           Column("max", "cut ms max", "{:.1f}"), Column("removed", "fragments removed"),
           Column("volume", "largest volume change %", "{:.3f}"), Column("solves failed", "solves failed"),
           Column("redrawn", "blades drawn again (shape)")]


def summary(rows: list[dict]) -> list[dict]:
    out = []
    for shape in dict.fromkeys(r["shape"] for r in rows):
        for relaxed in (True, False):
            group = [r for r in rows if r["shape"] == shape and r["relaxed"] == relaxed]
            if group:
                out.append({"shape": shape, "cells": group[0]["cells"], "cuts": len(group), "relaxed": relaxed,
                            "wrong": sum(r["wrong"] for r in group), "fragments": sum(r["fragments"] for r in group),
                            "invalid": sum(bool(r["invalid"]) for r in group),
                            "smallest": min(r["smallest piece (cells)"] for r in group),
                            "median": float(np.median([r["cut ms median"] for r in group])),
                            "max": max(r["cut ms max"] for r in group),
                            "removed": sum(r["fragments removed"] for r in group),
                            "volume": max((r["volume change %"] for r in group), key=abs),
                            "solves failed": sum(r["solves failed"] for r in group),
                            "redrawn": max(r["redrawn"] for r in group)})
    return out


def describe(rows: list[dict], quick: bool, minutes: float) -> str:
    """organ_cuts.md: studies/templates/organ_cuts.md filled with this run's rows."""
    template = PageTemplate("organ_cuts")
    total = summary(rows)
    failures = [r for r in rows if r["wrong"] or r["fragments"] or r["invalid"]]
    columns = [Column(k, k) for k in ("shape", "relaxed", "full", "expected", "big pieces", "fragments", "invalid")]
    return template.page(
        quick_flag=" --quick" if quick else "", minutes=minutes, moves=MOVES, resolved_cells=RESOLVED_CELLS,
        n_cuts=len(rows), n_shapes=len(total) // 2, wrong=sum(r["wrong"] for r in rows),
        fragments=sum(r["fragments"] for r in rows), table=markdown_table(total, COLUMNS),
        failures=template.snippet("failures", table=markdown_table(failures[:20], columns)) if failures else "")


def section_for_cutting(folder) -> str:
    """The section of cutting.md on real organ meshes: the summary of ``organ_cuts.csv`` in
    ``folder`` (written by this experiment), or how to make it."""
    template = PageTemplate("organ_cuts")
    path = folder / "organ_cuts.csv"
    if not path.exists():
        return template.snippet("cutting_section_missing") + "\n"
    with open(path, newline="") as stream:
        rows = [{key: _parsed(value) for key, value in row.items()} for row in csv.DictReader(stream)]
    return template.snippet("cutting_section", n_cuts=len(rows), moves=MOVES, wrong=sum(r["wrong"] for r in rows),
                            fragments=sum(r["fragments"] for r in rows),
                            table=markdown_table(summary(rows), COLUMNS)) + "\n"


def _parsed(value: str):
    if value in ("True", "False"):
        return value == "True"
    for kind in (int, float):
        try:
            return kind(value)
        except ValueError:
            pass
    return value


def main(argv=None) -> list[dict]:
    arguments = parse_arguments(__doc__, argv, lambda parser: parser.add_argument(
        "--cuts", type=int, default=None, help="cuts per shape (default 200; 4 with --quick)"))
    cuts = arguments.cuts if arguments.cuts is not None else 4 if arguments.quick else 200
    start = time.perf_counter()
    rows = run(arguments.quick, cuts)
    write_csv(arguments.out / "organ_cuts.csv", rows)
    (arguments.out / "organ_cuts.md").write_text(describe(rows, arguments.quick, (time.perf_counter() - start) / 60))
    print(f"wrote {arguments.out / 'organ_cuts.md'} and organ_cuts.csv")
    return rows


if __name__ == "__main__":
    main()
