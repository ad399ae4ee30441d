"""Cutting 2D triangle meshes with a point scalpel (thesis §5.2): the Delaunay cut.

The scalpel drags the active node, the tip of the incision, through the mesh; after every
move the triangles around it are remeshed (Delaunay flips, removal of nodes closer than
``eps_edge``, incision splits behind the scalpel), so the mesh stays small and well shaped.
On a Body the scalpel moves in deformed coordinates and the mesh is edited in the reference
configuration; the body keeps its state, so a stretched sheet opens as it is cut.
"""
from __future__ import annotations

import math

import numpy as np

from snede import _checks, _records, _renamed, _snede
from snede._engine import engine_property
from snede._snede import DelaunayCutterOptions, PlanarCutResult
from snede.cutting import body_and_mesh, move_along

#: Raised by a Delaunay cutter's ``move`` (a RuntimeError) when edits others made to the mesh
#: since its last move — a collapse, a dissection, a removal — took an incision's active node
#: away and left no vertex that is that incision's tip; the message names the node and what
#: happened to it. Edits that leave a tip (a collapse into a neighbour, splits, bisection,
#: flips) are followed instead, and the cut goes on.
IncisionLost = _snede.IncisionLost


def _point(value) -> np.ndarray:
    return _checks.coordinates(value, (2,), "the scalpel, a point with 2 coordinates,")


def sample_path(path, step: float) -> np.ndarray:
    """The polyline ``path`` ((n, 2), n ≥ 2) sampled so that consecutive points are at most
    ``step`` apart; its vertices are kept."""
    path = np.asarray(path, dtype=np.float64)
    if path.ndim != 2 or path.shape[1] != 2 or len(path) < 2:
        raise ValueError(f"path must be an (n, 2) polyline with n >= 2 points, got shape {path.shape}")
    if not np.all(np.isfinite(path)):
        raise ValueError("path has non-finite coordinates")
    points = [path[0]]
    for a, b in zip(path[:-1], path[1:]):
        pieces = max(1, int(math.ceil(np.linalg.norm(b - a) / step)))
        points.extend(a + (b - a) * k / pieces for k in range(1, pieces + 1))
    return np.array(points)


class IncisionCutter:
    """What the Delaunay cutters (2D sheets, surfaces in 3D) share: their thresholds, the
    incision's active node and edges, and lifting the scalpel. ``_impl`` is the engine's cutter."""

    eps_edge = engine_property("eps_edge")
    eps_entry = engine_property("eps_entry")
    eps_exit = engine_property("eps_exit")

    def lift(self) -> None:
        """Lift the scalpel: an incision in progress stays as it is; the next move only places it."""
        self._impl.lift()

    @property
    def active_node(self) -> int | None:
        """The vertex at the tip of the incision in progress, or None."""
        node = self._impl.active_node
        return None if node < 0 else int(node)

    def incision_edges(self) -> np.ndarray:
        """The boundary edges the cuts made (both lips), (n, 2) vertex ids."""
        return self._impl.incision_edges()


class DelaunayCutter(IncisionCutter):
    """Delaunay cutting of a 2D triangle mesh or plane-stress Body (§5.2.2, §5.4).

    ``DelaunayCutter(body_or_mesh, *, options=None, eps_edge=None, eps_entry=None, eps_exit=None,
    short_edge_angle=None)``: thresholds in the reference configuration; by default (None or 0)
    the thesis's h̄/3, h̄/6 and h̄/6 with h̄ the mean edge length. ``short_edge_angle`` (radians,
    below π/2) replaces ``eps_edge`` by the scale-free criterion of §5.5: an interior neighbour
    of the active node is removed when every angle facing their edge is smaller. ``options``: a
    :class:`snede.DelaunayCutterOptions` record holding them all (default: its defaults, the
    engine's); a keyword given changes its field of a copy. The engine refuses a negative or
    non-finite value when the cutter is made.

    ``move(point)`` moves the scalpel ((2,), deformed coordinates): the first move from outside
    the body that crosses its boundary enters, an incision follows the scalpel, and leaving
    the body finishes the cut. ``cut(path)`` samples the polyline ``path`` ((n, 2)) and moves
    along it. Both return a :class:`PlanarCutResult`. Invalid input raises ``ValueError``
    before anything changes.

    The cutter watches the mesh (§7.4): edits made by others between moves (collapses, splits,
    flips, refinement, removals, dissections) keep ``active_node`` and ``incision_edges()``
    right, or the next move raises :data:`IncisionLost` and lifts the scalpel (the move after
    it only places it).
    """

    def __init__(self, body_or_mesh, *, options: DelaunayCutterOptions | None = None, eps_edge=None, eps_entry=None,
                 eps_exit=None, short_edge_angle=None):
        self.body, self.mesh, model = body_and_mesh(body_or_mesh, type(self).__name__)
        if self.mesh.cell_dim != 2 or self.mesh.space_dim != 2:
            raise ValueError(f"{type(self).__name__} needs a 2D triangle mesh; this one has {self.mesh.cell_dim}-D cells "
                             f"in {self.mesh.space_dim}-D")
        settings = _records.settings(DelaunayCutterOptions, options, eps_edge=eps_edge, eps_entry=eps_entry,
                                     eps_exit=eps_exit, short_edge_angle=short_edge_angle)
        self._impl = _snede.DelaunayCutter(self.mesh._impl, model, settings)

    def move(self, point) -> PlanarCutResult:
        return self._impl.move(_point(point))

    def cut(self, path, step: float | None = None, progress=None) -> PlanarCutResult:
        """Move along the polyline ``path`` ((n, 2)), sampled every ``step`` (default
        ``eps_edge``); ``progress(done, total, report)`` is called after each move."""
        points = sample_path(path, self.eps_edge if step is None else _checks.positive(step, "step"))
        return move_along(self.move, points, PlanarCutResult(), progress)



def __getattr__(name):  # the names records had before issue 51 (snede._renamed)
    return _renamed.old_name(__name__, globals(), name)
