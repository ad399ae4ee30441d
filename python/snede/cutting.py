"""Cutting tetrahedral bodies with a scalpel (thesis §3.2–§3.3).

The scalpel is a line segment in deformed space. Each ``move`` sweeps the quadrilateral
between its last and its new position, processed as two sweep triangles; each sweep triangle
selects faces of the mesh (§3.2.1), snaps their vertices onto the sweep (§3.2.2), dissects
the mesh along them (§7.3) and removes the flat elements the snapping left (§3.2.3). A Body
on the mesh keeps its displacement, velocity and constraints across the cut, so a solver
continues from where it was.
"""
from __future__ import annotations

import numpy as np

from snede import _checks, _records, _renamed, _snede
from snede._engine import engine_property
from snede._snede import CutResult, TetrahedralCutterOptions
from snede.mesh import Mesh
from snede.part_body import PartBody
from snede.part_cutting import PartCutter


def body_and_mesh(body_or_mesh, cutter: str):
    """(body or None, mesh, the body's engine model or None) for a cutter's target; refused on
    a distributed mesh's part (cuts are serial for now)."""
    if isinstance(body_or_mesh, Mesh):
        body_or_mesh.require_serial(cutter)
        return None, body_or_mesh, None
    if hasattr(body_or_mesh, "_model") and isinstance(getattr(body_or_mesh, "mesh", None), Mesh):
        body_or_mesh.mesh.require_serial(cutter)
        return body_or_mesh, body_or_mesh.mesh, body_or_mesh._model
    raise TypeError(f"expected a snede.Body or snede.Mesh, got {type(body_or_mesh).__name__}")


def move_along(move, positions, total, progress=None):
    """Calls ``move`` at each of ``positions``, adding the reports to ``total``;
    ``progress(done, count, report)`` after each."""
    for k, position in enumerate(positions):
        report = move(position)
        total = total + report
        if progress is not None:
            progress(k + 1, len(positions), report)
    return total


class TetrahedralCutter:
    """``TetrahedralCutter(body_or_mesh, *, snap=True, remove_degeneracies=True,
    min_aspect_ratio=0.01, large_angle=0.99*pi, fix_free_pieces=True, max_fragment_elements=10)``.

    * ``options``: a :class:`snede.TetrahedralCutterOptions` record holding every setting below
      (default: ``TetrahedralCutterOptions()``, whose fields are the defaults above, the
      engine's); a keyword given (not None) changes its field of a copy. The cutter refuses
      thresholds out of range when it is made.

    * ``body_or_mesh``: a 3D ``snede.Body`` (the scalpel then acts on the deformed body,
      ``X + u``, as the user sees it) or a tetrahedral ``snede.Mesh`` (cut as it is).
    * ``snap``: move the cut faces' vertices onto the sweep (§3.2.2); without it the incision
      is jagged (Figure 3.5). Constrained vertices are never moved.
    * ``remove_degeneracies``, ``min_aspect_ratio``, ``large_angle``: §3.2.3; elements around
      the cut with aspect ratio (min height / max edge) below the threshold are collapsed by
      shape, the rest cut free.
    * ``fix_free_pieces``: a piece the cut separates from every constraint is fixed on one
      face where it is (§3.3), so that the next static solve is well posed.
    * ``max_fragment_elements``: a piece a sweep separates whose volume is at most this many
      mean elements of the mesh is removed (0 keeps them). The cut surface is only placed to
      within about one element, so such a piece (typically one flat tetrahedron between two cut
      faces; anything about two elements across or less) is an artefact of the approximation,
      not a part the scalpel meant to separate.
    * Every sweep of one incision (from placing the scalpel to ``lift``) meets the body as it
      was when the scalpel was placed: a body relaxed between moves (its lips opening under
      gravity) would otherwise have moved the incision's front away from where the next sweep
      starts, leaving a bridge of material. ``cut_triangle`` alone meets the body as it is.

    ``cut_triangle(corners)`` processes one sweep triangle ((3, 3), deformed coordinates);
    ``move(scalpel)`` moves the scalpel ((2, 3): its two ends) and cuts along the sweep from
    its previous position (the first call only places it). Both return a :class:`CutResult`.
    Invalid input raises ``ValueError`` before anything changes.
    """

    def __init__(self, body_or_mesh, *, options: TetrahedralCutterOptions | None = None, snap: bool | None = None,
                 remove_degeneracies: bool | None = None, min_aspect_ratio: float | None = None,
                 large_angle: float | None = None, fix_free_pieces: bool | None = None,
                 max_fragment_elements: int | None = None):
        if max_fragment_elements is not None:
            max_fragment_elements = _checks.count(max_fragment_elements, "max_fragment_elements", 0)
        settings = _records.settings(TetrahedralCutterOptions, options, snap=snap,
                                     remove_degeneracies=remove_degeneracies, min_aspect_ratio=min_aspect_ratio,
                                     large_angle=large_angle, fix_free_pieces=fix_free_pieces,
                                     max_fragment_elements=max_fragment_elements)
        self._settings = settings
        if isinstance(body_or_mesh, PartBody):  # a body on MPI ranks: the cut runs on one of them
            self.body, self.mesh = body_or_mesh, None
            self._impl = PartCutter(body_or_mesh, settings)
            return
        self.body, self.mesh, model = body_and_mesh(body_or_mesh, type(self).__name__)
        if self.mesh.cell_dim != 3:
            raise ValueError(f"TetrahedralCutter needs a tetrahedral mesh; this mesh has {self.mesh.cell_dim}-D cells")
        self._impl = _snede.TetrahedralCutter(self.mesh._impl, model, settings)

    @property
    def options(self) -> TetrahedralCutterOptions:
        """A copy of the settings this cutter was made with."""
        return TetrahedralCutterOptions(**_records.fields(self._settings))

    def cut_triangle(self, corners) -> CutResult:
        if isinstance(self._impl, PartCutter):
            raise NotImplementedError("cut_triangle on a body on MPI ranks: move the scalpel with move() or cut()")
        return self._impl.cut_triangle(_checks.coordinates(corners, (3, 3), "corners"))

    def move(self, scalpel) -> CutResult:
        if isinstance(self._impl, PartCutter):
            return self._impl.move(scalpel)  # checked on every rank together
        return self._impl.move(_checks.coordinates(scalpel, (2, 3), "scalpel"))

    def cut(self, path, progress=None) -> CutResult:
        """Move the scalpel through ``path``, an (n, 2, 3) sequence of scalpel positions; the
        first places it. ``progress(done, total, report)`` is called after each move."""
        path = np.asarray(path, dtype=np.float64)
        if path.ndim != 3 or path.shape[1:] != (2, 3) or len(path) < 2:
            raise ValueError(f"path must be (n, 2, 3) scalpel positions with n >= 2, got shape {path.shape}")
        return move_along(self.move, path, CutResult(), progress)

    def lift(self) -> None:
        """Lift the scalpel out of the body: the next ``move`` only places it, and the next
        cut is a new incision (earlier sweeps no longer count, Figure 3.2)."""
        self._impl.lift()

    placed = engine_property("placed")

    def incision_faces(self) -> np.ndarray:
        """The boundary faces the cuts opened, (n, 3) vertex ids, oriented outward."""
        return self._impl.incision_faces()


def __getattr__(name):  # the names records had before issue 51 (snede._renamed)
    return _renamed.old_name(__name__, globals(), name)
