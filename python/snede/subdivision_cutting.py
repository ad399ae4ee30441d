"""The baseline of §5.4: cutting a 2D triangle mesh by subdivision (Figure 5.2).

Every mesh edge the scalpel's path crosses is split where it is crossed, so each triangle the
path slices becomes three, and the edges joining consecutive crossings are dissected. This is
what interactive cutting tools usually do; snede's DelaunayCutter is measured against it. The
incision ends at the last edge the scalpel crossed (the thesis's subdivision also follows the
scalpel inside the active triangle until it leaves it; that temporary part is not drawn here).
It scans the mesh's edges at every crossing: a reference for comparisons on small meshes,
not an interactive tool.
"""
from __future__ import annotations

import time

import numpy as np

from snede import _checks
from snede.mesh import Mesh
from snede.planar_cutting import PlanarCutResult, _point, sample_path
from snede.cutting import move_along

_END = 1e-9  # a crossing this close to an edge's end (as a fraction of it) is at the vertex


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


class SubdivisionCutter:
    """``SubdivisionCutter(mesh)``: ``move(point)`` and ``cut(path)`` as for
    :class:`snede.DelaunayCutter`, on a bare 2D mesh (reference coordinates)."""

    def __init__(self, mesh):
        if not isinstance(mesh, Mesh):
            raise TypeError(f"SubdivisionCutter cuts a snede.Mesh (the §5.4 baseline), got {type(mesh).__name__}")
        if mesh.cell_dim != 2 or mesh.space_dim != 2:
            raise ValueError(f"SubdivisionCutter needs a 2D triangle mesh; this one has {mesh.cell_dim}-D cells "
                             f"in {mesh.space_dim}-D")
        mesh.require_serial("SubdivisionCutter")
        self.mesh = mesh
        self._last = None  # the scalpel's previous position
        self._end = None   # the vertex where the incision in progress ends, or None outside
        self._incision = set()  # vertices on the incisions: the path runs along their edges

    def _edges(self):
        """(unique edges (m, 2), number of cells on each)."""
        cells = self.mesh.cells
        edges = np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
        return np.unique(edges, axis=0, return_counts=True)

    def _first_crossing(self, p, q, after: float):
        """The first edge crossing of segment p→q strictly beyond fraction ``after``, ignoring edges at
        the incision's end: (fraction along pq, a, b, fraction along ab, on the boundary)."""
        edges, counts = self._edges()
        # Edges at the incision's end, and the lips (which lie along the path, so rounding
        # would find them crossed), do not count.
        lips = np.isin(edges, list(self._incision)).all(axis=1) if self._incision else np.zeros(len(edges), bool)
        keep = ~lips if self._end is None else ~lips & np.all(edges != self._end, axis=1)
        edges, counts = edges[keep], counts[keep]
        x = self.mesh.points
        a, b = x[edges[:, 0]], x[edges[:, 1]]
        d, e = q - p, b - a
        denominator = _cross(d, e)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = _cross(a - p, e) / denominator
            t = _cross(a - p, d) / denominator
        hit = (denominator != 0) & (s > after) & (s <= 1) & (t >= -_END) & (t <= 1 + _END)
        if not hit.any():
            return None
        k = np.flatnonzero(hit)[np.argmin(s[hit])]
        return float(s[k]), int(edges[k, 0]), int(edges[k, 1]), float(np.clip(t[k], 0, 1)), bool(counts[k] == 1)

    def _interior_edge(self, u: int, v: int) -> bool:
        cells = self.mesh.cells
        return int(np.count_nonzero(np.any(cells == u, axis=1) & np.any(cells == v, axis=1))) == 2

    def move(self, point) -> PlanarCutResult:
        p = _point(point)
        start = time.perf_counter()
        before = self.mesh.n_cells
        counts = dict(moves=1, nodes_inserted=0, entries=0, exits=0)
        if self._last is not None and not np.array_equal(p, self._last):
            # The first crossing may lie a rounding error behind the start: the last move then
            # stopped just short of that edge. Later ones lie strictly beyond the one before.
            after = -1e-12
            while (crossing := self._first_crossing(self._last, p, after)) is not None:
                along, a, b, t, boundary = crossing
                after = along + 1e-12
                if t <= _END or t >= 1 - _END:
                    vertex = a if t <= _END else b
                else:
                    result = self.mesh.split_edge(a, b, t)
                    if not result:
                        continue
                    vertex = result.vertex
                    counts["nodes_inserted"] += 1
                if self._end is not None and vertex != self._end and self._interior_edge(self._end, vertex):
                    copies = self.mesh.dissect([[self._end, vertex]])
                    self._incision.update(int(v) for v in np.ravel(copies))
                    self._incision.update((self._end, vertex))
                if boundary and self._end is None:
                    counts["entries"] += 1
                    self._end = vertex
                elif boundary:
                    counts["exits"] += 1
                    self._end = None
                elif self._end is not None:
                    self._end = vertex
        self._last = p
        return PlanarCutResult(**counts, triangles_before=before, triangles_after=self.mesh.n_cells,
                               seconds=time.perf_counter() - start)

    def cut(self, path, step: float | None = None, progress=None) -> PlanarCutResult:
        """Move along the polyline ``path`` ((n, 2)); ``step`` (default: the whole segments)
        only changes how often ``progress(done, total, report)`` is called."""
        points = sample_path(path, np.inf if step is None else _checks.positive(step, "step"))
        return move_along(self.move, points, PlanarCutResult(), progress)
