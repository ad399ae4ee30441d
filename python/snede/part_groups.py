"""A serial mesh's named groups carried onto its parts (issue 52): when rank 0's mesh is
distributed (``snede.distribute``, ``DistributedMesh.read`` of a gmsh or VTK file), every rank's
part gets the same group names, each holding the members that lie on the rank: the cells of a
cell group that the rank was given, and the faces of a boundary group that are boundary faces of
the rank's cells. So ``body.fix("held")`` and ``body.add_traction("pressed", ...)`` name the same
groups on a part as on the serial mesh. Members are matched by their corners' serial vertex ids;
a boundary face of the serial mesh belongs to one cell, hence to one rank, so a traction on it is
counted once. The faces cuts opened (``"incision"``) are not carried: a part cannot be cut.
"""
from __future__ import annotations

import numpy as np

from snede.mesh_groups import INCISION


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


def _keys(sorted_corners: np.ndarray) -> np.ndarray:
    """One comparable item per row (its bytes), so rows are matched by np.isin."""
    rows = np.ascontiguousarray(sorted_corners, dtype=np.int64)
    return rows.view(np.dtype((np.void, 8 * rows.shape[1]))).ravel()
