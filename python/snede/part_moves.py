"""Cells moved between the ranks of a distributed mesh, with what lives on their vertices
(issue 52): the parts made anew from the cells each rank is sent, fields carried by global
vertex id, the global ids made dense again after vertices were added or removed, and the named
groups following their members. A cut on ranks gathers the cells near the scalpel on one rank
with it and spreads the edited cells back (part_cutting.py).

Every call is collective. The work is the parts' (each rank sends its cells and its owned
vertices' values once): not yet proportional to the cells that move.
"""
from __future__ import annotations

import numpy as np

from snede import _snede
from snede.distributed import DistributedMesh, _part


def _bounds(n: int, size: int) -> np.ndarray:
    """The global id ranges the ranks hold during an exchange: rank r holds [b[r], b[r+1])."""
    return np.array([n * r // size for r in range(size + 1)], dtype=np.int64)


def _holder(ids: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    return np.searchsorted(bounds, ids, side="right") - 1


def _split(comm, ids: np.ndarray, rows: np.ndarray | None, bounds: np.ndarray):
    """``ids`` (and their ``rows``) sent each to the rank holding it; what this rank received."""
    holder = _holder(ids, bounds)
    order = np.argsort(holder, kind="stable")
    cuts = np.searchsorted(holder[order], np.arange(comm.size + 1))
    sent = [(ids[order[cuts[r]:cuts[r + 1]]], None if rows is None else rows[order[cuts[r]:cuts[r + 1]]])
            for r in range(comm.size)]
    got = comm.alltoall(sent)
    got_ids = np.concatenate([i for i, _ in got]).astype(np.int64)
    got_rows = None if rows is None else np.concatenate([r for _, r in got]).reshape(len(got_ids), *rows.shape[1:])
    return got_ids, got_rows


def _ask(comm, ids: np.ndarray, bounds: np.ndarray, answer) -> np.ndarray:
    """For each of ``ids``, ``answer(asked ids)`` evaluated at the rank holding it, back in order."""
    holder = _holder(ids, bounds)
    order = np.argsort(holder, kind="stable")
    cuts = np.searchsorted(holder[order], np.arange(comm.size + 1))
    asked = comm.alltoall([ids[order[cuts[r]:cuts[r + 1]]] for r in range(comm.size)])
    replies = comm.alltoall([answer(np.asarray(a, dtype=np.int64)) for a in asked])
    out = np.concatenate(replies) if replies else np.zeros(0)
    result = np.empty((len(ids),) + out.shape[1:], dtype=out.dtype)
    result[order] = out
    return result


class DenseIds:
    """The global ids in use (by some rank's cell, among ``n_ids``) numbered anew 0..n−1 in
    their order; ``new(ids)`` maps ids in use (−1 for one no longer used). Collective."""

    def __init__(self, comm, used: np.ndarray, n_ids: int):
        self.comm, self.bounds = comm, _bounds(n_ids, comm.size)
        got, _ = _split(comm, np.unique(used), None, self.bounds)
        first, last = self.bounds[comm.rank], self.bounds[comm.rank + 1]
        in_use = np.zeros(last - first, dtype=bool)
        in_use[got - first] = True
        offset = comm.exscan(int(in_use.sum())) or 0
        self._numbers = np.where(in_use, offset + np.cumsum(in_use) - 1, -1).astype(np.int64)
        self._first = first
        self.n = comm.allreduce(int(in_use.sum()))

    def new(self, ids: np.ndarray) -> np.ndarray:
        ids = np.asarray(ids, dtype=np.int64).ravel()
        return _ask(self.comm, ids, self.bounds, lambda asked: self._numbers[asked - self._first])


def moved_part(part: DistributedMesh, ids: np.ndarray, destination: np.ndarray, fields: list[np.ndarray],
               keep_as_given: bool) -> tuple[DistributedMesh, list[np.ndarray], DenseIds]:
    """``part``'s live cells (rows of ``part.local.cells``) each sent to rank ``destination``
    (−1: dropped);
    ``ids`` is the global id of each local vertex row (−1 for a removed row; rows beyond the
    part's own may be vertices an edit added, with ids from ``part.n_global_vertices`` on), and
    each of ``fields`` ((n_rows, width), by row) is carried to the new part's vertices by id.
    Ids no cell uses any more are dropped and the rest numbered densely in their order (the
    returned ``DenseIds`` maps old ids to new). With ``keep_as_given`` every rank keeps the cells
    it was sent; otherwise DMPlex rebalances when a rank holds more than 1.2 times the mean.
    The cell and boundary groups of ``part.local`` follow their members (gathered on every rank
    by their vertices' ids: O(group size)). Returns the new part, the fields on its vertices and
    the id map."""
    comm, mesh = part.comm, part.local
    kept = destination >= 0
    cells = ids[mesh.cells]
    n_ids = max(comm.allgather(int(ids.max()) + 1 if len(ids) else 0))
    dense = DenseIds(comm, cells[kept].ravel(), n_ids)
    cells = dense.new(cells.ravel()).reshape(cells.shape)
    # The values of each vertex once, from one holder (the lowest rank holding it), to the rank
    # holding its new id's range.
    live = np.flatnonzero(ids >= 0)
    new_ids = dense.new(ids[live])
    in_use = new_ids >= 0
    live, new_ids = live[in_use], new_ids[in_use]
    fields = [np.asarray(f, dtype=np.float64).reshape(len(ids), np.shape(f)[-1]) for f in fields]
    values = np.hstack([mesh.points[live]] + [f[live] for f in fields])
    bounds = _bounds(dense.n, comm.size)
    got_ids, got_values = _split(comm, new_ids, values, bounds)
    first, last = bounds[comm.rank], bounds[comm.rank + 1]
    table = np.zeros((last - first, values.shape[1]))
    table[got_ids - first] = got_values
    space = mesh.points.shape[1]
    groups = _group_members(mesh, cells, kept, dense, ids)
    sent = comm.alltoall([cells[destination == r] for r in range(comm.size)])
    given = np.concatenate(sent).reshape(-1, cells.shape[1]) if sent else cells[:0]
    new = _part(comm, _snede.distribute_cells(comm.py2f(), cells.shape[1] - 1, np.ascontiguousarray(given),
                                              np.ascontiguousarray(table[:, :space]), keep_as_given))
    carried = _ask(comm, new.global_vertex.astype(np.int64), bounds, lambda asked: table[asked - first, space:])
    widths = np.cumsum([0] + [f.shape[1] for f in fields])
    moved_fields = [carried[:, widths[k]:widths[k + 1]] for k in range(len(fields))]
    _give_group_members(new, comm, groups)
    return new, moved_fields, dense


def _group_members(mesh, cells_by_new_id: np.ndarray, kept: np.ndarray, dense: DenseIds,
                   ids: np.ndarray) -> tuple[dict, dict]:
    """This rank's members of each group by new global ids (cells kept; faces), sorted rows."""
    from snede.mesh_groups import INCISION

    cell_groups = {name: np.sort(cells_by_new_id[rows[kept[rows]]], axis=1) for name, rows in mesh.cell_groups.items()}
    faces = {name: members for name, members in mesh.boundary_groups.items() if name != INCISION}
    face_ids = {name: np.sort(ids[members], axis=1) for name, members in faces.items()}
    names = sorted(face_ids)
    flat = np.concatenate([face_ids[n].ravel() for n in names]) if names else np.zeros(0, dtype=np.int64)
    mapped = dense.new(flat)
    face_groups, start = {}, 0
    for name in names:
        count = face_ids[name].size
        rows = mapped[start:start + count].reshape(-1, face_ids[name].shape[1])
        face_groups[name] = np.sort(rows[np.all(rows >= 0, axis=1)], axis=1)
        start += count
    return cell_groups, face_groups


def _give_group_members(part: DistributedMesh, comm, groups: tuple[dict, dict]) -> None:
    from snede import part_groups

    part_groups.give_groups(part, *part_groups.gathered(comm, groups))
