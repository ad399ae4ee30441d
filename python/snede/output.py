"""Files a person can open: an XDMF + HDF5 time series (ParaView) written by the engine.

Each step stores the displacement and per-cell fields: ``aspect_ratio`` (reference shape,
§3.2.3) and ``inverted`` (1 where det F ≤ 0), and any extra point fields. When the mesh changes
between steps (a cut, a refinement) the new mesh is written and the step points to it.
``read_series`` reads such a series back, each step with its own mesh. meshio cannot:
``meshio.read`` stops at "Unknown section 'Grid'", and ``meshio.xdmf.TimeSeriesReader`` gives
every step the first step's mesh, wrong once the mesh has changed.

``SeriesWriter(base, comm)`` writes one series from the parts of a distributed mesh
(``snede.distribute``): every rank of ``comm`` writes its part into the shared HDF5 file
(MPI-IO) and rank 0 the XDMF file, which reads back like a serial series; the point field
``serial_vertex`` gives each point's id in the serial mesh."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from snede import _snede, series_files
from snede._engine import engine_property
from snede.distributed import agreed
from snede.mesh import Mesh
from snede.part_body import PartBody

__all__ = ["SeriesWriter", "SeriesStep", "read_series"]


class SeriesWriter:
    """``SeriesWriter("out/scene/cantilever")`` writes ``cantilever.xdmf`` and ``cantilever.h5``.

    With ``comm`` (an mpi4py communicator) the writer is shared by its ranks: creating it and
    every ``write_part`` are collective, every rank passes the same ``base``."""

    def __init__(self, base, comm=None):
        base = Path(base)
        self.comm = comm
        if comm is None:
            base.parent.mkdir(parents=True, exist_ok=True)
            self._impl = _snede.XdmfWriter(str(base))
            return
        # Rank 0 makes the folder; every rank learns whether it could, so none waits for the
        # others in the collective file creation.
        problem = None
        if comm.rank == 0:
            try:
                base.parent.mkdir(parents=True, exist_ok=True)
            except OSError as error:
                problem = error
        problem = comm.bcast(problem, root=0)
        if problem is not None:
            raise problem
        self._impl = _snede.XdmfWriter(str(base), comm.py2f())

    @property
    def xdmf_path(self) -> Path:
        return Path(self._impl.xdmf_path)

    @property
    def h5_path(self) -> Path:
        return Path(self._impl.h5_path)

    n_steps = engine_property("n_steps")
    n_meshes = engine_property("n_meshes")

    def write(self, body, time: float = 0.0, displacement=None, point_fields: dict | None = None,
              **cell_fields) -> None:
        """Write the body's state (or ``displacement``) at ``time``, with the standard cell
        fields, extra ones given as arrays of shape (n_cells,) and ``point_fields``
        ({name: array of shape (n_points,)}).

        A field name must read back as it was written, from the HDF5 dataset it names and from
        the XDMF (XML) file: not empty, no '/', no control character (NUL, tab, newline, ...),
        no U+FFFE or U+FFFF, no space at the end, and not taken by another field of the step,
        among them the fields the writer makes itself (``displacement``, ``aspect_ratio``,
        ``min_angle``, ``inverted``, ``group:<name>`` of the mesh's groups), which a field of
        the same name would replace. Any other name raises ValueError naming the field and the
        reason, before the step writes anything (the series stays readable, the writer usable).

        A :class:`snede.PartBody` (a rank's share of a distributed body) is written as
        :meth:`write_part` writes its part (collective)."""
        _refuse_built_in(cell_fields, ("inverted",), "cell")
        u = body.displacement if displacement is None else np.asarray(displacement, dtype=np.float64)
        inverted = np.zeros(body.mesh.n_cells)
        inverted[body.inverted_elements(u)] = 1.0
        if isinstance(body, PartBody):
            self.write_part(body.part, time, u, point_fields, inverted=inverted, **cell_fields)
        else:
            self.write_mesh(body.mesh, time, u, point_fields, inverted=inverted, **cell_fields)

    def write_mesh(self, mesh, time: float = 0.0, displacement=None, point_fields: dict | None = None,
                   **cell_fields) -> None:
        """Write a mesh without a body (a surface mesh, a mesh being edited) with its
        ``aspect_ratio`` and ``min_angle`` (radians; the smallest dihedral angle for tetrahedra)
        cell fields, an optional (n_points, dim) ``displacement``, extra cell fields and
        ``point_fields`` (their names as ``write`` says). The mesh's named groups go along: a
        cell field ``group:<name>`` (1 on the group's cells) per cell group, a point field
        ``group:<name>`` (1 on its faces' vertices) per boundary group. A field of the caller's
        may not take the name of one of these."""
        groups = _group_fields(mesh.cell_groups, mesh.n_cells)
        _refuse_built_in(cell_fields, groups, "cell")
        cell_fields = {**groups, **cell_fields}
        boundary = {name: np.unique(faces) for name, faces in mesh.boundary_groups.items()}
        groups = _group_fields(boundary, mesh.n_points)
        _refuse_built_in(point_fields or {}, groups, "point")
        point_fields = {**groups, **(point_fields or {})}
        u, points, fields = _step_arrays(mesh, displacement, point_fields, cell_fields)
        self._impl.write_step(float(time), mesh._impl, u, fields, points)

    def write_part(self, part, time: float = 0.0, displacement=None, point_fields: dict | None = None,
                   **cell_fields) -> None:
        """Collective: write this rank's part of a distributed mesh (a ``snede.DistributedMesh``
        over the writer's communicator) with the cell fields of ``write_mesh``, all given for
        the rank's local mesh: ``displacement`` (n_local_vertices, dim) for its vertices, owned
        and ghosts (``DistributedStatic.local_displacement()``), ``point_fields`` one value per
        local vertex, extra cell fields one per local cell. Every rank passes the same field
        names; bad input raises the same ValueError on every rank. The file holds the owned
        vertices' values, in PETSc's global vertex order, and the point field ``serial_vertex``."""
        u, points, fields = agreed(part.comm, lambda: _step_arrays(part.local, displacement, point_fields, cell_fields))
        self._impl.write_distributed_step(float(time), part._impl, u, fields, points)


def _group_fields(groups: dict, n: int) -> dict:
    """{"group:<name>": (n,) indicator of the group's rows} for a mesh's named groups."""
    fields = {}
    for name, rows in groups.items():
        indicator = np.zeros(n)
        indicator[rows] = 1.0
        fields[f"group:{name}"] = indicator
    return fields


def _step_arrays(mesh, displacement, point_fields, cell_fields):
    """The arrays of one step of ``mesh`` as the engine takes them: the displacement (zero when
    None), the point fields and the cell fields with ``aspect_ratio`` and ``min_angle`` first.
    Sizes are the engine's to check (on every rank at once for a distributed part)."""
    u = np.zeros((mesh.n_points, mesh.dim)) if displacement is None else np.asarray(displacement, dtype=np.float64)
    for name in [*(point_fields or {}), *cell_fields]:
        _check_encodable(name)
    _refuse_built_in(cell_fields, QUALITY_FIELDS, "cell")
    points = {name: np.asarray(values, dtype=np.float64).ravel() for name, values in (point_fields or {}).items()}
    quality = mesh.quality()
    fields = {"aspect_ratio": quality.aspect_ratio, "min_angle": quality.min_dihedral}
    fields.update({name: np.asarray(values, dtype=np.float64) for name, values in cell_fields.items()})
    return np.ascontiguousarray(u), points, fields


QUALITY_FIELDS = ("aspect_ratio", "min_angle")  # the cell fields of every step


def _refuse_built_in(given: dict, built_in, kind: str) -> None:
    """Refuse a field of the caller's named as one the writer makes itself (``built_in``): as
    keyword arguments it would silently replace that field (or clash with the writer's own
    keyword argument, a TypeError)."""
    for name in given:
        if name in built_in:
            raise ValueError(f"{kind} field name {name!r} is taken: the writer writes a {kind} field of that "
                             "name itself, which yours would replace; give yours another name")


def _check_encodable(name) -> None:
    """Refuse a field name the engine cannot receive (a lone surrogate, as from a file name that
    was not UTF-8) with an error like the engine's, which checks every other rule."""
    try:
        name.encode("utf-8")
    except UnicodeEncodeError as error:
        shown = name.encode("utf-8", "backslashreplace").decode("utf-8")
        raise ValueError(f"field name '{shown}' is not usable: it is not UTF-8 text ({error.reason} "
                         f"at character {error.start})") from None


# -- reading a series back ----------------------------------------------------------------------
@dataclass(eq=False)
class SeriesStep:
    """One step of a series read by ``read_series``.

    ``mesh`` is the mesh the step points to (steps between two mesh changes share one Mesh
    object); ``point_fields`` maps names to arrays with one row per point, among them
    ``displacement`` as (n_points, dim); ``cell_fields`` maps names to (n_cells,) arrays
    (``aspect_ratio``, ``min_angle``, ``inverted`` where written, and the extra ones)."""

    time: float
    mesh: Mesh
    point_fields: dict[str, np.ndarray] = field(default_factory=dict)
    cell_fields: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def displacement(self) -> np.ndarray | None:
        """``point_fields["displacement"]``, (n_points, dim); None if the step has none."""
        return self.point_fields.get("displacement")


def read_series(path) -> list[SeriesStep]:
    """Read back a series that ``SeriesWriter`` wrote: ``path`` is the ``.xdmf`` file (its
    ``.h5`` is found next to it); this, not meshio, reads such series (see the module). Returns one ``SeriesStep`` per step, in order, each with its
    ``time``, its own ``mesh`` (the topology and reference coordinates of that step; steps
    that share a mesh share one Mesh object, so do not edit it in place), ``point_fields``
    (``displacement`` as (n_points, dim) and the scalar point fields) and ``cell_fields``.

    Each step's mesh has the dimension it was written with (a 2D mesh, padded with z = 0 in the
    file, comes back 2D; a surface in 3D, flat or not, as a surface). In a series written before
    steps said their dimension, triangles come back 2D unless some step has a z ≠ 0. Times read
    back exactly (the writer prints 17 significant digits).
    A series that is being written reads as the steps written so far (none: an empty list).
    A missing file raises FileNotFoundError; a file that is not XDMF, is cut short, or refers to
    an HDF5 file or dataset that is missing raises ValueError naming the file and the problem."""
    return [SeriesStep(*step) for step in series_files.read_steps(path, Mesh)]
