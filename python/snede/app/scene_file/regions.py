"""The regions of a scene file that ``[[hold]]`` and ``[[loads.force]]`` tables pick vertices
with: one key of ``side = "x = min"``, ``box = {min, max}``, ``plane = {point, normal}``,
``patch = {point, radius}`` or ``group = "name"`` (one of the mesh's named groups, e.g. a gmsh
physical group of the file), and ``within`` (a distance, for a side or a plane)."""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

import numpy as np

from snede.app.scene_file.reading import DIRECTION, NON_NEGATIVE, POINT, POSITIVE, REFUSED, Kind, Table

KINDS = ("side", "box", "plane", "patch", "group")
_SIDE = re.compile(r"^\s*([xyz])\s*=\s*(min|max)\s*$")
SIDE = Kind('a side such as "x = min" or "z = max"', lambda v: v if isinstance(v, str) and _SIDE.match(v) else REFUSED)
EXACT = 1e-6  # ``within`` of a side or a plane by default, times the mesh's largest extent


@dataclass
class Region:
    """Vertices picked by one rule: ``pick(mesh)`` gives their ids (on the reference
    positions); ``key`` and ``description`` name it in messages."""

    key: str
    description: str
    pick: Callable


def _within(mesh, within: float | None) -> float:
    live = mesh.points[mesh.live_vertices]
    return EXACT * float(np.ptp(live, axis=0).max()) if within is None else within


def _side(side: str, within: float | None):
    axis, end = _SIDE.match(side).groups()

    def pick(mesh):
        x = mesh.points[:, "xyz".index(axis)]
        edge = x[mesh.live_vertices].min() if end == "min" else x[mesh.live_vertices].max()
        return np.flatnonzero((np.abs(x - edge) <= _within(mesh, within)) & mesh.live_vertices)
    return pick


def _box(low, high):
    def pick(mesh):
        return np.flatnonzero(np.all((mesh.points >= low) & (mesh.points <= high), axis=1) & mesh.live_vertices)
    return pick


def _plane(point, normal, within: float | None):
    normal = normal / np.linalg.norm(normal)

    def pick(mesh):
        distance = np.abs((mesh.points - point) @ normal)
        return np.flatnonzero((distance <= _within(mesh, within)) & mesh.live_vertices)
    return pick


GROUP = Kind("the name of one of the mesh's groups (a string)", lambda v: v if isinstance(v, str) and v else REFUSED)


def _group(mesh, name: str) -> np.ndarray:
    try:
        return mesh.group_vertices(name)
    except KeyError as error:
        raise ValueError(error.args[0]) from None


def read_region(table: Table) -> Region:
    """The region of a ``[[hold]]`` or ``[[loads.force]]`` table."""
    kind = table.one_of(KINDS)
    key = table.key(kind)
    within = table.get("within", NON_NEGATIVE, None) if kind in ("side", "plane") else None
    close = f" within {within:g}" if within is not None else ""
    if kind == "side":
        side = table.get("side", SIDE)
        return Region(key, f'side "{side}"{close}', _side(side, within))
    if kind == "group":
        name = table.get("group", GROUP)
        return Region(key, f'group "{name}"', lambda mesh: _group(mesh, name))
    shape = table.table(kind)
    if kind == "box":
        low, high = np.array(shape.get("min", POINT)), np.array(shape.get("max", POINT))
        if np.any(low > high):
            shape.fail("max", f"must be at least {shape.key('min')} in every coordinate, got {high.tolist()} "
                              f"and min {low.tolist()}")
        region = Region(key, f"box from {low.tolist()} to {high.tolist()}", _box(low, high))
    elif kind == "plane":
        point, normal = np.array(shape.get("point", POINT)), np.array(shape.get("normal", DIRECTION))
        region = Region(key, f"plane through {point.tolist()} normal to {normal.tolist()}{close}",
                        _plane(point, normal, within))
    else:
        point, radius = np.array(shape.get("point", POINT)), shape.get("radius", POSITIVE)
        region = Region(key, f"patch of radius {radius:g} around {point.tolist()}",
                        lambda mesh: mesh.boundary_patch(point, radius))
    shape.close()
    return region
