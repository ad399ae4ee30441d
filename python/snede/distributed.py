"""Meshes distributed over MPI ranks by PETSc's DMPlex (issue 18, first part).

``snede.distribute(mesh, comm=None)`` is collective: rank 0 passes the serial mesh (the other
ranks may pass it too, or None; only rank 0's is read), and every rank gets its part: the cells
PETSc's partitioner gave it, as a :class:`snede.Mesh` with local vertex ids, the serial id of
each local vertex (``global_vertex``), and which of them the rank owns (``owned``; a vertex on
several ranks' cells is owned by exactly one). Cells are not overlapped. A problem with rank
0's input raises the same ``ValueError`` on every rank. Run with ``mpirun -n N``.

Solvers on a distributed mesh are not there yet: this is the partition they will run on.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from snede import _snede
from snede.mesh import Mesh


@dataclass
class DistributedMesh:
    """This rank's part of a distributed mesh (see :func:`distribute`)."""

    comm: object  # mpi4py communicator
    local: Mesh
    global_vertex: np.ndarray  # (n_local_vertices,) serial vertex id of each local vertex
    owned: np.ndarray  # (n_local_vertices,) bool: this rank owns the vertex
    n_global_vertices: int
    n_global_cells: int
    _impl: object = None  # keeps the engine's part (which holds `local`) alive


def distribute(mesh: Mesh | None, comm=None) -> DistributedMesh:
    """Partition rank 0's ``mesh`` over ``comm`` (default ``MPI.COMM_WORLD``) with DMPlex;
    every rank returns its part. Collective."""
    from mpi4py import MPI

    comm = MPI.COMM_WORLD if comm is None else comm
    serial = mesh._impl if (comm.rank == 0 and isinstance(mesh, Mesh)) else None
    part = _snede.distribute_mesh(comm.py2f(), serial)
    return DistributedMesh(comm=comm, local=Mesh._wrap(part.local), global_vertex=part.global_vertex.ravel().copy(),
                           owned=part.owned.ravel().astype(bool), n_global_vertices=int(part.n_global_vertices),
                           n_global_cells=int(part.n_global_cells), _impl=part)
