"""Local mesh edits (thesis §3.2.3, §5.2.2, §5.3.1, §7.3): edge flip, edge split, vertex
insertion, edge collapse, vertex removal and node snapping. Each returns an ``EditResult``:
truthy when done; when refused, ``reason`` says why and the mesh is exactly as it was (same
cells, points and ``revision``). Geometric decisions use exact predicates; a Body on the
mesh carries its displacement (and velocity) to new and moved vertices by their parents."""
from __future__ import annotations

import functools

import numpy as np

from snede import _checks, _snede

EditResult = _snede.EditResult


def _fraction(value, what: str) -> float:
    value = float(value)
    if not np.isfinite(value):
        raise ValueError(f"{what} must be finite, got {value}")
    return value


def serial_only(edit):
    """Refuses ``edit`` on one rank's part of a distributed mesh (issue 18: topology changes
    stay serial), naming it."""
    @functools.wraps(edit)
    def checked(self, *args, **kwargs):
        self.require_serial(edit.__name__)
        return edit(self, *args, **kwargs)
    return checked


class MeshEdits:
    """Mixed into ``snede.Mesh``; every method takes vertex ids (rows of ``points``)."""

    def require_serial(self, operation: str) -> None:
        """Raises NotImplementedError naming ``operation`` if this mesh is one rank's part of a
        distributed mesh (``snede.distribute``): cuts, bisection and needle insertion change
        the topology, which is serial for now (an edit of one part would leave the others and
        PETSc's numbering behind)."""
        part = self.__dict__.get("_distributed_part")
        if part is not None:
            raise NotImplementedError(
                f"{operation} on {part}: topology changes (cuts, bisection, needle insertion) are serial for "
                "now; change the serial mesh on one rank, or a serial copy (snede.Mesh(mesh.points, mesh.cells))")

    def _vertex(self, value, what: str = "vertex") -> int:
        return _checks.index(value, what, self.n_points, "vertex ids")

    @serial_only
    def flip_edge(self, a: int, b: int) -> EditResult:
        """Replace the two triangles sharing edge (a, b) by the two sharing the other diagonal
        (§5.2.2, Figure 5.9). Triangle meshes and surfaces. Refused on the boundary, for a
        non-convex quadrilateral, when the new edge exists, or when a surface would fold."""
        return _snede.flip_edge(self._impl, self._vertex(a, "a"), self._vertex(b, "b"))

    def is_locally_delaunay(self, a: int, b: int) -> bool:
        """§5.2.1: no vertex opposite edge (a, b) lies strictly inside the other triangle's
        circumcircle (2D triangle meshes; boundary edges are Delaunay)."""
        return _snede.is_locally_delaunay(self._impl, self._vertex(a, "a"), self._vertex(b, "b"))

    @serial_only
    def split_edge(self, a: int, b: int, t: float = 0.5) -> EditResult:
        """Add the vertex (1 − t)·x_a + t·x_b (0 < t < 1) and halve every cell around edge
        (a, b); ``result.vertex`` is the new vertex. Triangles, surfaces and tetrahedra."""
        return _snede.split_edge(self._impl, self._vertex(a, "a"), self._vertex(b, "b"), _fraction(t, "t"))

    @serial_only
    def insert_vertex(self, element: int, weights) -> EditResult:
        """Insert a vertex at barycentric ``weights`` (cell_dim + 1 numbers ≥ 0 summing to 1,
        in the order of ``element_vertices(element)``) in the cell with element id ``element``
        (``cell_ids[row]`` for a row of ``cells``; ids, unlike rows, survive edits), splitting it
        into 3 triangles or 4 tetrahedra; in 3D one zero weight puts it on a face, whose one or
        two tetrahedra are split. Refused on an edge (use ``split_edge``) or too close to a side."""
        element = _checks.index(element, "element", _checks.ID_LIMIT, "element ids")
        weights = np.ascontiguousarray(weights, dtype=np.float64)
        if weights.shape != (self.cell_dim + 1,):
            raise ValueError(f"weights must have shape ({self.cell_dim + 1},), got {weights.shape}")
        return _snede.insert_vertex(self._impl, element, weights)

    @serial_only
    def collapse_edge(self, keep: int, gone: int, t: float = 0.0) -> EditResult:
        """Merge ``gone`` into ``keep`` (§3.2.3, Figure 3.10): the cells around the edge
        vanish, ``keep`` moves to (1 − t)·x_keep + t·x_gone (0 ≤ t ≤ 1) and ``gone`` is
        removed. Refused when the link condition fails (the topology would change) or a
        surviving cell would be flat or inverted."""
        return _snede.collapse_edge(self._impl, self._vertex(keep, "keep"), self._vertex(gone, "gone"), _fraction(t, "t"))

    @serial_only
    def remove_vertex_by_flips(self, vertex: int) -> EditResult:
        """Remove ``vertex`` and retriangulate the hole it leaves (§5.3.1, Figure 5.10);
        a boundary vertex only if it lies exactly on the segment between its boundary
        neighbours. Triangle meshes and surfaces."""
        return _snede.remove_vertex_by_flips(self._impl, self._vertex(vertex))

    @serial_only
    def snap_vertex(self, vertex: int, parents, weights) -> EditResult:
        """Move ``vertex`` to ``Σ weights[i]·x[parents[i]]`` (§3.2 node snapping; ``parents``
        may include ``vertex``), re-interpolating a Body's fields. Refused when a cell of its
        star would become flat or inverted."""
        return _snede.snap_vertex(self._impl, self._vertex(vertex), *self._parents(parents, weights))
