"""A serial mesh's named groups carried onto its parts (issue 52): when rank 0's mesh is
distributed (``snede.distribute``, ``DistributedMesh.read`` of a gmsh or VTK file), every rank's
part gets the same group names, each holding the members that lie on the rank: the cells of a
cell group that the rank was given, and the faces of a boundary group that are boundary faces of
the rank's cells. So ``body.fix("held")`` and ``body.add_traction("pressed", ...)`` name the same
groups on a part as on the serial mesh. Members are matched by their corners' serial vertex ids;
a boundary face of the serial mesh belongs to one cell, hence to one rank, so a traction on it is
counted once. The faces cuts opened (``"incision"``) are not carried: a part's cut faces are its
scalpel's ``incision_faces()`` (part_cutting.py).

A part refined on the ranks (``PartBody.refine_uniform`` ...) finds its groups by where things
lie, as a serial mesh's groups follow bisection (mesh_groups.py): a cell is in the groups of the
member that holds its centroid, a boundary face in those of the member face its centroid lies
on; the members' corners are gathered from every rank, since rebalancing may move a cell away
from the rank of its parent.
"""
from __future__ import annotations

import numpy as np

from snede.mesh_groups import INCISION, _containing


def serial_groups(mesh) -> tuple[dict, dict]:
    """The groups of a serial mesh as they travel: cell groups and boundary groups (name →
    members' corners as sorted serial vertex ids)."""
    cells = {name: np.sort(mesh.cells[rows], axis=1) for name, rows in mesh.cell_groups.items()}
    faces = {name: np.sort(members, axis=1) for name, members in mesh.boundary_groups.items() if name != INCISION}
    return cells, faces


def give_groups(part, cell_groups: dict, face_groups: dict) -> None:
    """Name on ``part.local`` the members of each group (``serial_groups``' form) that lie on
    this rank; every rank gets every name, maybe empty."""
    local = part.local
    to_serial = part.global_vertex
    if cell_groups:
        local_cells = _keys(np.sort(to_serial[local.cells], axis=1))
        for name, members in cell_groups.items():
            local.add_cell_group(name, np.flatnonzero(np.isin(local_cells, _keys(members))))
    if face_groups:
        boundary = local.boundary_faces()
        local_faces = _keys(np.sort(to_serial[boundary], axis=1))
        for name, members in face_groups.items():
            local.add_boundary_group(name, boundary[np.isin(local_faces, _keys(members))])


def group_shapes(mesh, comm) -> tuple[dict, dict]:
    """The members of ``mesh``'s groups on every rank of ``comm`` as their corners' coordinates
    (name → (n, corners, dim)), gathered on every rank (collective)."""
    cells = {name: mesh.points[mesh.cells[rows]] for name, rows in mesh.cell_groups.items()}
    faces = {name: mesh.points[members] for name, members in mesh.boundary_groups.items() if name != INCISION}
    return gathered(comm, (cells, faces))


def gathered(comm, groups: tuple[dict, dict]) -> tuple[dict, dict]:
    """Each rank's (cell groups, boundary groups), name → member rows, joined over the ranks of
    ``comm``: every name on every rank, with every rank's members (collective)."""
    every = comm.allgather(groups)

    def joined(kind: int) -> dict:
        names = sorted({name for rank_groups in every for name in rank_groups[kind]})
        return {name: np.concatenate([g[kind][name] for g in every if name in g[kind]]) for name in names}

    return joined(0), joined(1)


def give_group_shapes(mesh, boundary: np.ndarray, cell_shapes: dict, face_shapes: dict) -> None:
    """Name on ``mesh`` (a part) its cells whose centroids lie in a group's member cells and its
    ``boundary`` faces (the body's, (n, cell_dim)) whose centroids lie on a group's member faces:
    exactly, not the nearest, since the members are only some of the cells (a child's centroid
    lies inside its parent)."""
    centroids = mesh.points[mesh.cells].mean(axis=1)
    for name, shapes in cell_shapes.items():
        mesh.add_cell_group(name, np.flatnonzero(_containing(centroids, shapes, nearest=False) >= 0))
    corners = mesh.points[boundary]
    for name, shapes in face_shapes.items():
        mesh.add_boundary_group(name, boundary[_containing(corners.mean(axis=1), shapes, corners, nearest=False) >= 0])


def _keys(sorted_corners: np.ndarray) -> np.ndarray:
    """One comparable item per row (its bytes), so rows are matched by np.isin."""
    rows = np.ascontiguousarray(sorted_corners, dtype=np.int64)
    return rows.view(np.dtype((np.void, 8 * rows.shape[1]))).ravel()
