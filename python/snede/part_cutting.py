"""A scalpel on a body that no rank holds whole (issue 52, item 3; thesis §3.2–§3.3).

``snede.TetrahedralCutter(part_body)`` cuts a :class:`snede.PartBody` with the serial cutter,
on one rank. Before each move every rank finds its cells near the sweep (their boxes in the
configuration the incision began in meet the sweep's box), the cells of the previous sweep's
memory, and three rings of cells around them (vertex stars, across the rank boundary: what
snapping, the degeneracy removal's collapses and their checks reach); those not already on the
cutting rank move there (``part_moves.moved_part``), with the displacement, the incision's
configuration and the conditions. The cutting rank then runs the serial ``TetrahedralCutter``
on its part, on a serial Body of its cells (which carries the displacement and constraints
through the cut as serially), the cutter going on from its memory (``TetrahedralCutter.memory``:
the scalpel, the remembered sweeps, the placed vertices, the joined and incision faces, by
global vertex id). The edited part is then spread over the ranks again (DMPlex rebalances a
crowded one), the new vertices numbered after the others and the ids made dense.

What differs from the serial cutter: the pieces are counted, tiny fragments removed and loose
pieces held after each move (over every rank's cells), where the serial cutter does it after
each of a move's two sweep triangles; a loose piece is held on a face of its cell of lowest
vertex ids (serially: of its first cell); vertices made by the cut are numbered after all the
others (serially a removed vertex's id is reused), so ties between vertex ids can break
otherwise. Each move costs the parts' size (two exchanges of every rank's cells), not the
cut's.
"""
from __future__ import annotations

import numpy as np

from snede import _checks, _snede
from snede._snede import CutResult, TetrahedralCutterOptions
from snede.distributed import agreed
from snede.part_moves import moved_part

# Rings of vertex stars around the cells a sweep may meet that the cutting rank takes with
# them: the snapped vertices' stars (1), the collapses of the degenerate cells among them and
# the stars those collapses check (2, 3).
RINGS = 3


class PartCutter:
    """The scalpel of ``snede.TetrahedralCutter(part_body, ...)``: the serial cutter's ``move``,
    ``lift``, ``placed`` and ``incision_faces`` (``TetrahedralCutter.cut`` moves it along a path;
    ``cut_triangle`` is serial only), collective on the body's ranks, every rank giving the same
    scalpel."""

    def __init__(self, body, settings: TetrahedralCutterOptions):
        from snede import _records

        if body.dim != 3 or body.mesh.cell_dim != 3:
            raise ValueError("TetrahedralCutter needs a tetrahedral mesh")
        self.body, self.settings = body, settings
        # The serial cutter on the cutting rank counts no pieces of its own: that is done over
        # every rank's cells after the move.
        engine = _records.fields(settings)
        engine.update(max_fragment_elements=0, fix_free_pieces=False)
        self._engine_settings = TetrahedralCutterOptions(**engine)
        self.cutting_rank = 0
        self._scalpel = None  # (6,) the scalpel's ends, on every rank
        self._memory = None  # the serial cutter's memory by global vertex ids, on the cutting rank
        self._incision = np.zeros((0, 3), dtype=np.int64)  # incision faces by global ids, every rank

    @property
    def comm(self):
        return self.body.comm

    @property
    def placed(self) -> bool:
        return self._scalpel is not None

    def lift(self) -> None:
        """Lift the scalpel (the next move only places it; the next cut is a new incision)."""
        self._scalpel = None
        if self._memory is not None:
            self._memory.update(scalpel=None, cut_configuration=np.zeros((0, 3)), joined=np.zeros((0, 3), np.int64),
                                sweeps=np.zeros((0, 9)), previous_touched=np.zeros((0, 4), np.int64))
        self.body._cut_configuration = None

    def incision_faces(self) -> np.ndarray:
        """This rank's incision faces: (n, 3) local vertex indices of ``body.mesh``, oriented
        outward (the faces the cuts opened that lie on this rank's cells)."""
        part = self.body.part
        order = np.argsort(part.global_vertex, kind="stable")
        held = part.global_vertex[order]
        if not len(self._incision) or not len(held):
            return np.zeros((0, 3), dtype=np.int64)
        at = np.clip(np.searchsorted(held, self._incision), 0, len(held) - 1)
        here = np.all(held[at] == self._incision, axis=1)
        faces = order[at[here]]
        boundary = {tuple(sorted(f)) for f in self.body.mesh.boundary_faces().tolist()}
        mine = np.array([tuple(sorted(f)) in boundary for f in faces.tolist()], dtype=bool)
        return faces[mine].reshape(-1, 3)

    def move(self, scalpel) -> CutResult:
        """Move the scalpel ((2, 3): its two ends) and cut along the sweep (collective; the first
        call only places it)."""
        def checked():
            ends = _checks.coordinates(scalpel, (2, 3), "scalpel").ravel()
            if np.array_equal(ends[:3], ends[3:]):
                raise ValueError("TetrahedralCutter.move: the scalpel's two ends coincide (a segment of zero length)")
            self.body._require_same("TetrahedralCutter.move", scalpel=ends.tobytes())
            return ends

        ends = agreed(self.comm, checked)
        if self._scalpel is None:  # placed: every sweep of this incision meets the body as it is now
            self._scalpel = ends
            self.body._cut_configuration = self.body._displacement.copy()
            return CutResult()
        self._gather_near(np.vstack([self._scalpel.reshape(2, 3), ends.reshape(2, 3)]))
        report = self._cut_on_cutting_rank(ends)
        self._scalpel = ends
        self._spread()
        return self._with_pieces(report)

    # -- the cells near the sweep, to the cutting rank -------------------------------------
    def _gather_near(self, corners: np.ndarray) -> None:
        """``corners``: the scalpel's ends before and after the move, (4, 3)."""
        body, comm = self.body, self.comm
        part, mesh = body.part, body.mesh
        cells = mesh.cells
        near = _meeting_the_sweep((mesh.points + body._cut_configuration)[cells], corners)
        remembered = comm.bcast(self._remembered_vertices() if comm.rank == self.cutting_rank else None,
                                root=self.cutting_rank)
        near |= np.isin(part.global_vertex[cells], remembered).any(axis=1)
        for _ in range(RINGS):
            marked = np.unique(part.global_vertex[cells[near]])
            every = np.unique(np.concatenate(comm.allgather(marked)))
            near |= np.isin(part.global_vertex[cells], every).any(axis=1)
        moving = int(np.count_nonzero(near)) if comm.rank != self.cutting_rank else 0
        # The cutting rank's part made anew unless its vertices are in global id order, as
        # part_as_given makes them (a part DMPlex rebalanced is not; the serial cutter breaks
        # exact ties by vertex id: an edge crossed at its middle marks its lower id), and none has
        # recorded parents (a refinement in place adds such vertices; the cut's new vertices are
        # found by theirs).
        stale = comm.rank == self.cutting_rank and bool(np.any(np.diff(part.global_vertex) <= 0))
        stale = stale or body._refiner is not None
        if comm.allreduce(moving) == 0 and not comm.allreduce(int(stale)):
            return
        destination = np.where(near, self.cutting_rank, comm.rank)
        self._move(destination, keep_as_given=True, ids=part.global_vertex.astype(np.int64))

    def _remembered_vertices(self) -> np.ndarray:
        """The global ids of the joined faces' and the latest sweep's tetrahedra's vertices."""
        if self._memory is None:
            return np.zeros(0, dtype=np.int64)
        return np.unique(np.concatenate([self._memory["joined"].ravel(), self._memory["previous_touched"].ravel()]))

    def _move(self, destination: np.ndarray, keep_as_given: bool, ids: np.ndarray) -> None:
        """The body's cells to ``destination`` (one rank per live cell), the displacement, the
        incision's configuration and the conditions following their vertices."""
        body = self.body
        fields = [body._displacement, body._cut_configuration if body._cut_configuration is not None
                  else np.zeros_like(body._displacement)]
        new, (u, configuration), dense = moved_part(body.part, ids, destination, fields, keep_as_given)
        body._take_part(new, u, dense.new)
        if body._cut_configuration is not None:
            body._cut_configuration = configuration
        self._renumber_memory(dense.new)

    def _renumber_memory(self, new) -> None:
        """The memory's and the incision's global ids through ``new`` (collective)."""
        on_cutting = self.comm.rank == self.cutting_rank and self._memory is not None
        keys = ("placed", "joined", "incision", "previous_touched")
        flat = np.concatenate([self._memory[k].ravel() for k in keys]) if on_cutting else np.zeros(0, np.int64)
        mapped = new(np.concatenate([flat, self._incision.ravel()]))
        if on_cutting:
            start = 0
            for k in keys:
                shape = self._memory[k].shape
                self._memory[k] = mapped[start:start + self._memory[k].size].reshape(shape)
                start += self._memory[k].size
            self._memory["placed"] = self._memory["placed"][self._memory["placed"] >= 0]
            for k in ("joined", "incision", "previous_touched"):
                rows = self._memory[k]
                self._memory[k] = rows[np.all(rows >= 0, axis=1)]
        incision = mapped[len(flat):].reshape(-1, 3)
        self._incision = incision[np.all(incision >= 0, axis=1)]

    # -- the serial cutter on the cutting rank ---------------------------------------------
    def _cut_on_cutting_rank(self, ends: np.ndarray) -> CutResult:
        comm = self.comm
        outcome = agreed(comm, lambda: self._serial_cut(ends) if comm.rank == self.cutting_rank else None)
        report, updates, incision = comm.bcast(outcome, root=self.cutting_rank)
        self.body._apply_conditions(**updates)
        self._incision = incision
        return report

    def _serial_cut(self, ends: np.ndarray):
        """On the cutting rank: the serial cutter's move on this part; the report, and what
        changed of the conditions (by global ids) for every rank."""
        from snede.body import Body

        body, part = self.body, self.body.part
        mesh = body.mesh
        serial = Body(mesh, body.material, density=body.density, thickness=body.thickness)
        serial.displacement = body._displacement
        local_of = dict(zip(part.global_vertex.tolist(), range(len(part.global_vertex))))
        fixed = [(local_of[v], value) for v, value in body._fixed.items() if v in local_of]
        if fixed:
            serial.fix(np.array([v for v, _ in fixed]), np.array([value for _, value in fixed]))
        for v, (direction, anchor) in body._sliding.items():
            if v in local_of:
                serial._model.slide(np.array([local_of[v]]), np.asarray(direction, dtype=np.float64))
        for name, forces in body._channels.items():
            mine = [(local_of[v], f) for v, f in forces.items() if v in local_of]
            if mine:
                serial.add_nodal_force(np.array([v for v, _ in mine]), np.array([f for _, f in mine]), name)
        serial.displacement = body._displacement  # sliding anchors are where the vertices are
        cutter = _snede.TetrahedralCutter(mesh._impl, serial._model, self._engine_settings)
        aside = self._restore(cutter, local_of, body._cut_configuration)
        report = cutter.move(ends)
        ids = self._ids_after_cut(mesh, part)
        memory = cutter.memory()
        self._memory = self._memory_by_ids(memory, ids, aside)
        body._displacement = np.ascontiguousarray(serial.displacement)
        body._cut_configuration = np.asarray(memory["cut_configuration"]).reshape(-1, 3)
        body._cut_ids = ids
        return report, self._condition_updates(serial, ids), self._memory["incision"]

    def _restore(self, cutter, local_of: dict, configuration: np.ndarray) -> dict:
        """The memory, in this part's local ids, given back to ``cutter``; what lies elsewhere
        (placed vertices and incision faces the move cannot reach) is returned set aside."""
        memory = self._memory
        given = {"scalpel": self._scalpel.copy(), "cut_configuration": np.ascontiguousarray(configuration),
                 "sweeps": np.zeros((0, 9)), "placed": np.zeros(0, np.int64),
                 "joined": np.zeros((0, 3), np.int64), "incision": np.zeros((0, 3), np.int64),
                 "previous_touched": np.zeros((0, 4), np.int64)}
        aside = {"placed": np.zeros(0, np.int64), "incision": np.zeros((0, 3), np.int64)}
        if memory is not None:
            given["sweeps"] = memory["sweeps"]
            lookup = np.vectorize(lambda v: local_of.get(int(v), -1), otypes=[np.int64])
            mesh = self.body.mesh
            # What this part has: its vertices, its boundary faces and its cells.
            present = {"incision": _row_keys(mesh.boundary_faces()), "previous_touched": _row_keys(mesh.cells)}
            for key in ("placed", "joined", "incision", "previous_touched"):
                rows = memory[key]
                local = lookup(rows) if rows.size else rows.astype(np.int64)
                here = local >= 0 if local.ndim == 1 else np.all(local >= 0, axis=1)
                if key in present and len(local):
                    here &= np.isin(_row_keys(np.where(local >= 0, local, 0)), present[key])
                given[key] = np.ascontiguousarray(local[here])
                if key in aside:
                    aside[key] = rows[~here]
        cutter.restore(given)
        return aside

    def _ids_after_cut(self, mesh, part) -> np.ndarray:
        """Each row of the cut part's mesh: its global id, −1 for a removed row; vertices the cut
        added get ids after every other (in row order)."""
        n_rows = mesh.n_points
        ids = np.full(n_rows, -1, dtype=np.int64)
        before = len(part.global_vertex)
        ids[:before] = part.global_vertex
        live = np.asarray(mesh.live_vertices, dtype=bool)
        added = np.union1d(np.asarray(mesh._impl.rows_with_parents(), dtype=np.int64).ravel(),
                           np.arange(before, n_rows))
        added = added[live[added]]
        ids[~live] = -1
        ids[added] = part.n_global_vertices + np.arange(len(added))
        return ids

    @staticmethod
    def _memory_by_ids(memory: dict, ids: np.ndarray, aside: dict) -> dict:
        out = {"scalpel": memory["scalpel"], "sweeps": np.asarray(memory["sweeps"]).reshape(-1, 9)}
        for key, width in (("placed", 0), ("joined", 3), ("incision", 3), ("previous_touched", 4)):
            rows = ids[np.asarray(memory[key], dtype=np.int64)]
            out[key] = rows.reshape(-1, width) if width else rows.ravel()
        out["placed"] = np.unique(np.concatenate([out["placed"], aside["placed"]]))
        out["incision"] = np.concatenate([out["incision"], aside["incision"]])
        return out

    def _condition_updates(self, serial, ids: np.ndarray) -> dict:
        """The conditions of the cut part's vertices after the cut, by global id: the ids whose
        conditions they replace, fixed (ids, values), sliding (ids, directions, anchors), each
        channel's (ids, forces)."""
        fixed, anchors, _ = serial._model.constraint_table()
        sliding, directions, slide_anchors = serial._model.sliding_table()
        fixed, sliding = fixed.ravel(), sliding.ravel()
        channels = {}
        for name in serial._model.load_channels:
            forces = serial._model.channel_forces(name)
            loaded = np.flatnonzero(np.any(forces != 0, axis=1) & (ids >= 0))
            channels[name] = (ids[loaded], forces[loaded])
        return {"replaced": ids[ids >= 0], "fixed": (ids[fixed], anchors),
                "sliding": (ids[sliding], directions, slide_anchors), "channels": channels}

    # -- the edited part spread over the ranks again ---------------------------------------
    def _spread(self) -> None:
        body, comm = self.body, self.comm
        ids = body._cut_ids if comm.rank == self.cutting_rank else body.part.global_vertex.astype(np.int64)
        body._cut_ids = None
        destination = np.full(body.mesh.n_cells, comm.rank)
        self._move(destination, keep_as_given=False, ids=ids)

    # -- the pieces over every rank ----------------------------------------------------------
    def _with_pieces(self, report: CutResult) -> CutResult:
        """The pieces after the move: tiny fragments removed, loose pieces held (§3.3)."""
        body, comm = self.body, self.comm
        labels, n_pieces, loose = body.problem()._impl.pieces()
        volume = _cell_volumes(body.mesh)
        piece_volume = np.zeros(n_pieces)
        np.add.at(piece_volume, labels.ravel(), volume)
        piece_volume = comm.allreduce(piece_volume)
        piece_cells = comm.allreduce(np.bincount(labels.ravel(), minlength=n_pieces))
        limit = self.settings.max_fragment_elements * piece_volume.sum() / max(piece_cells.sum(), 1)
        fragments = np.flatnonzero(piece_volume <= limit) if self.settings.max_fragment_elements > 0 else []
        fragments = [p for p in fragments if p != int(np.argmax(piece_volume))]
        if len(fragments):
            report.fragments_removed += len(fragments)
            report.fragment_elements += int(piece_cells[fragments].sum())
            dropped = np.isin(labels.ravel(), fragments)
            self._move(np.where(dropped, -1, comm.rank), keep_as_given=True,
                       ids=body.part.global_vertex.astype(np.int64))
            labels, n_pieces, loose = body.problem()._impl.pieces()
            piece_cells = comm.allreduce(np.bincount(labels.ravel(), minlength=n_pieces))
        report.components = int(n_pieces)
        report.piece_elements = sorted(piece_cells.tolist(), reverse=True) if n_pieces > 1 else []
        # The cutting rank's serial cutter counted its part's pieces alone: the counts are these.
        report.free_pieces, report.pieces_fixed = len(loose), 0
        if len(loose) and self.settings.fix_free_pieces:
            self._hold(labels.ravel(), loose.ravel())
            report.pieces_fixed = len(loose)
        return report

    def _hold(self, labels: np.ndarray, loose: np.ndarray) -> None:
        """Each loose piece fixed on one face (its cell of lowest sorted vertex ids), where it is."""
        body, comm = self.body, self.comm
        cells = np.sort(body.part.global_vertex[body.mesh.cells], axis=1)
        chosen = []
        for piece in loose.tolist():
            mine = cells[labels == piece]
            best = min(map(tuple, mine.tolist())) if len(mine) else None
            every = [c for c in comm.allgather(best) if c is not None]
            chosen.append(min(every))
        faces = np.array([cell[:3] for cell in chosen], dtype=np.int64).ravel()
        selected = np.isin(body.part.global_vertex, faces)
        body.fix(selected, body._displacement[selected])


def _cell_volumes(mesh) -> np.ndarray:
    x = mesh.points[mesh.cells]
    return np.abs(np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), x[:, 3] - x[:, 0])) / 6.0


def _row_keys(rows: np.ndarray) -> np.ndarray:
    """Each row's vertex set as one comparable item (sorted, as bytes), for np.isin."""
    from snede.part_groups import _keys

    return _keys(np.sort(np.asarray(rows, dtype=np.int64), axis=1))


def _meeting_the_sweep(tetrahedra: np.ndarray, scalpels: np.ndarray) -> np.ndarray:
    """Which of ``tetrahedra`` ((n, 4, 3) corners) may meet the sweep of the scalpel from
    ``scalpels[:2]`` to ``scalpels[2:]``: the two sweep triangles TetrahedralCutter.move makes. A
    tetrahedron meets a triangle only if their boxes overlap and its corners are not all strictly
    on one side of the triangle's plane (rounding: a margin of 1e-9 of the sizes involved), so the
    cells kept are a thin layer along the sweep, not its whole box."""
    p0, p1, q0, q1 = scalpels
    lo, hi = tetrahedra.min(axis=1), tetrahedra.max(axis=1)
    kept = np.zeros(len(tetrahedra), dtype=bool)
    for triangle in ((p0, p1, q1), (p0, q1, q0)):
        a, b, c = (np.asarray(v, dtype=np.float64) for v in triangle)
        normal = np.cross(b - a, c - a)
        length = np.linalg.norm(normal)
        if length == 0:
            continue  # a half that sweeps no area
        normal /= length
        side = (tetrahedra - a) @ normal
        margin = 1e-9 * (np.abs(tetrahedra).max() + np.abs(a).max() + np.linalg.norm(b - a) + np.linalg.norm(c - a))
        straddles = (side.min(axis=1) <= margin) & (side.max(axis=1) >= -margin)
        box = np.all((lo <= np.maximum.reduce([a, b, c])) & (hi >= np.minimum.reduce([a, b, c])), axis=1)
        kept |= straddles & box
    return kept
