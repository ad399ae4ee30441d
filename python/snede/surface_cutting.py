"""Cutting triangulated surfaces in 3D with a line-segment scalpel (thesis §5.3).

The scalpel is a segment in space whose ends move with constant velocity between samples.
Where it meets the surface it drags an active node, the tip of an incision; after every
step the triangles around it are remeshed as in the 2D Delaunay cut (flips by the unfolded
empty-circle criterion, removal of nodes closer than ``eps_edge``, incision splits), so the
mesh stays small and well shaped. A segment can cut a curved surface in several places at
once (§5.3.2): every place it touches anew starts an incision, an incision branches where
the scalpel meets its triangles in several places (a fold), and incisions that meet end
together. On a membrane Body the scalpel moves in deformed coordinates and the mesh is
edited in the reference configuration; the body keeps its state, so a pre-tensioned
membrane opens as it is cut.
"""
from __future__ import annotations

import numpy as np

from snede import _checks, _records, _snede
from snede.cutting import body_and_mesh, move_along
from snede._snede import SurfaceCutterOptions
from snede.planar_cutting import IncisionCutter, PlanarCutResult


class SurfaceCutter(IncisionCutter):
    """Delaunay cutting of a surface mesh or membrane Body (triangles in 3D) with a segment.

    ``SurfaceCutter(body_or_mesh, *, options=None, eps_edge=None, eps_entry=None, eps_exit=None)``:
    thresholds in the reference configuration, by default (None or 0) h̄/3, h̄/6 and h̄/6 with h̄
    the mean edge length (§5.4). ``options``: a :class:`snede.SurfaceCutterOptions` record
    holding them (default: its defaults, the engine's); a keyword given changes its field of a
    copy. The engine refuses a negative or non-finite value when the cutter is made.

    ``move(segment)`` moves the scalpel to ``segment`` ((2, 3): its two ends, deformed
    coordinates); the first move places it, entering where it pierces the surface. Later
    moves start incisions where the scalpel touches the surface anew (Figure 5.12): the swept
    scalpel crossing a boundary edge into its triangle, an end of the scalpel passing through
    a triangle, or the scalpel meeting an interior edge from outside both its triangles (a
    crest; that incision branches at once). Each incision follows the scalpel, branches where
    the scalpel meets its triangles in several places, and ends where it leaves through the
    boundary or meets another incision. ``cut(path)`` moves through ``path`` ((n, 2, 3)
    scalpel positions, the first places it). Both return a :class:`snede.PlanarCutResult`
    (the 2D cutter's fields plus ``branches`` and ``annihilations``). Invalid input raises
    ``ValueError`` before anything changes.

    Edits made by others between moves are followed as by the 2D cutter; an incision whose
    tip they took away ends, and the next move raises :data:`snede.IncisionLost`
    naming it (the other incisions go on with the move after it).
    """

    def __init__(self, body_or_mesh, *, options: SurfaceCutterOptions | None = None, eps_edge=None, eps_entry=None,
                 eps_exit=None):
        self.body, self.mesh, model = body_and_mesh(body_or_mesh, type(self).__name__)
        if self.mesh.cell_dim != 2 or self.mesh.space_dim != 3:
            raise ValueError(f"{type(self).__name__} needs a surface mesh (triangles in 3D); this one has "
                             f"{self.mesh.cell_dim}-D cells in {self.mesh.space_dim}-D")
        settings = _records.settings(SurfaceCutterOptions, options, eps_edge=eps_edge, eps_entry=eps_entry,
                                     eps_exit=eps_exit)
        self._impl = _snede.SurfaceCutter(self.mesh._impl, model, settings)

    @property
    def active_nodes(self) -> list[int]:
        """The tips of the incisions in progress (entry nodes included), oldest first."""
        return [int(v) for v in self._impl.active_nodes.ravel()]

    @property
    def active_node(self) -> int | None:
        """The tip of the oldest incision in progress, or None (see ``active_nodes``)."""
        nodes = self.active_nodes
        return nodes[0] if nodes else None

    def move(self, segment) -> PlanarCutResult:
        segment = _checks.coordinates(segment, (2, 3), "segment")
        if np.array_equal(segment[0], segment[1]):
            raise ValueError(f"segment: the scalpel's two ends coincide: {segment.tolist()}")
        return self._impl.move(segment)

    def cut(self, segments, progress=None) -> PlanarCutResult:
        """Move the scalpel through ``segments`` ((n, 2, 3), n >= 2; the first places it);
        ``progress(done, total, report)`` is called after each move. The whole path is checked
        before the first move."""
        segments = np.asarray(segments, dtype=np.float64)
        if segments.ndim != 3 or segments.shape[1:] != (2, 3) or len(segments) < 2:
            raise ValueError(f"segments must be (n, 2, 3) scalpel positions with n >= 2, got shape {segments.shape}")
        if not np.all(np.isfinite(segments)):
            raise ValueError("segments has non-finite coordinates")
        if np.any(np.all(segments[:, 0] == segments[:, 1], axis=1)):
            raise ValueError("segments: a scalpel position has coinciding ends")
        return move_along(self.move, segments, PlanarCutResult(), progress)

