"""The §6.8.1 needle test situation, defined once for the needle scene, the chapter 6
experiments and the update-rate benchmark.

A plane-stress slab 0.1 × 0.1 m, 0.01 m thick, E = 34 kPa, ν = 0.34, fixed at x = 0.1 m; the
needle enters at (0, 0.05) along +x to a depth of 70 mm. Element sizes h_k = 0.1 m · 2^-k:
the start mesh has edges h_start (uniform right triangles), refinement goes to h_ref.
"""
from __future__ import annotations

import numpy as np

import snede

SIZE, THICKNESS, DEPTH = 0.1, 0.01, 0.07
YOUNG, POISSON = 34e3, 0.34
ENTRY, DIRECTION = (0.0, 0.05), (1.0, 0.0)


def h(k: int) -> float:
    """h_k = 0.1 m · 2^-k (§6.8.1)."""
    return SIZE * 2.0 ** -k


def held(points, fixed: str = "right") -> np.ndarray:
    """(n,) bool: the vertices the slab is held at, its right side (``fixed="right"``) or bottom."""
    if fixed == "right":
        return np.isclose(points[:, 0], SIZE)
    if fixed == "bottom":
        return np.isclose(points[:, 1], 0.0)
    raise ValueError(f"fixed must be 'right' or 'bottom', got {fixed!r}")


def slab_body(h_start: int, material=None, *, fixed: str = "right", formulation: str = "p1") -> "snede.Body":
    """The slab meshed with right triangles of leg h_{h_start} (2·4^h_start cells), held on the
    right side (``fixed="right"``, §6.8.1) or at the bottom (``"bottom"``, Figure 6.12)."""
    n = 2 ** h_start
    mesh = snede.meshing.rectangle((SIZE, SIZE), (n, n))
    body = snede.Body(mesh, material or snede.LinearElastic(YOUNG, POISSON), density=1000.0, thickness=THICKNESS,
                      formulation=formulation)
    body.fix(held(mesh.points, fixed))
    return body


def needle_for(body, h_ref: int | None, *, friction=None, entry=ENTRY, direction=DIRECTION, **solver) -> "snede.NeedleInsertion":
    """A NeedleInsertion on the slab with the Figure 6.4 stand-in profile, refining to h_{h_ref}."""
    return snede.NeedleInsertion(body, entry, direction, friction or snede.FrictionProfile.figure_6_4(),
                                 h_ref=None if h_ref is None else h(h_ref), **solver)
