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

import contextlib
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from snede import _snede
from snede.distributed import agreed
from snede.mesh import Mesh

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

    @property
    def n_steps(self) -> int:
        return self._impl.n_steps

    @property
    def n_meshes(self) -> int:
        return self._impl.n_meshes

    def write(self, body, time: float = 0.0, displacement=None, point_fields: dict | None = None,
              **cell_fields) -> None:
        """Write the body's state (or ``displacement``) at ``time``, with the standard cell
        fields, extra ones given as arrays of shape (n_cells,) and ``point_fields``
        ({name: array of shape (n_points,)}).

        A field name must read back as it was written, from the HDF5 dataset it names and from
        the XDMF (XML) file: not empty, no '/', no control character (NUL, tab, newline, ...),
        no U+FFFE or U+FFFF, no space at the end, and not taken by another field of the step.
        Any other name raises ValueError naming the field and the reason, before the step
        writes anything (the series stays readable, the writer usable)."""
        u = body.displacement if displacement is None else np.asarray(displacement, dtype=np.float64)
        inverted = np.zeros(body.mesh.n_cells)
        inverted[body.inverted_elements(u)] = 1.0
        self.write_mesh(body.mesh, time, u, point_fields, inverted=inverted, **cell_fields)

    def write_mesh(self, mesh, time: float = 0.0, displacement=None, point_fields: dict | None = None,
                   **cell_fields) -> None:
        """Write a mesh without a body (a surface mesh, a mesh being edited) with its
        ``aspect_ratio`` and ``min_angle`` (radians; the smallest dihedral angle for tetrahedra)
        cell fields, an optional (n_points, dim) ``displacement``, extra cell fields and
        ``point_fields`` (their names as ``write`` says). The mesh's named groups go along: a
        cell field ``group:<name>`` (1 on the group's cells) per cell group, a point field
        ``group:<name>`` (1 on its faces' vertices) per boundary group."""
        cell_fields = {**_group_fields(mesh.cell_groups, mesh.n_cells), **cell_fields}
        boundary = {name: np.unique(faces) for name, faces in mesh.boundary_groups.items()}
        point_fields = {**_group_fields(boundary, mesh.n_points), **(point_fields or {})}
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
    points = {name: np.asarray(values, dtype=np.float64).ravel() for name, values in (point_fields or {}).items()}
    quality = mesh.quality()
    fields = {"aspect_ratio": quality.aspect_ratio, "min_angle": quality.min_dihedral}
    fields.update({name: np.asarray(values, dtype=np.float64) for name, values in cell_fields.items()})
    return np.ascontiguousarray(u), points, fields


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


_TOPOLOGIES = {"triangle": 3, "tetrahedron": 4}
_GEOMETRIES = {"XYZ": 3, "XY": 2}
_SERIES_SUFFIXES = (".xdmf", ".xmf")
# What XML formatting puts around a DataItem's path; str.strip() would also take other
# whitespace that a field name may end with.
_XML_WHITESPACE = " \t\n\r"


@dataclass(frozen=True)
class _Item:
    """An HDF DataItem: ``file.h5:/dataset`` with the dimensions the XDMF file announces."""

    file: Path
    dataset: str
    shape: tuple[int, ...]


@dataclass
class _StepRef:
    time: float
    dim: int | None  # of the coordinates, as the step says it (None: a series from before it did)
    corners: int  # vertices per cell: 3 triangles, 4 tetrahedra
    cells: _Item
    points: _Item
    attributes: list[tuple[str, str, str, _Item]]  # name, center ("Node"/"Cell"), type, data


def _xdmf_root(path: Path) -> ET.Element:
    """The parsed XML of an XDMF file; FileNotFoundError if it is missing, ValueError naming the
    file if it is not XML (garbage, cut short, or caught while being rewritten) or not XDMF."""
    if not path.is_file():
        raise FileNotFoundError(f"no series file {path}")
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as error:
        raise ValueError(f"{path}: not a readable XDMF file, the XML does not parse ({error}); "
                         "if a run is writing it, read it again after the next step") from None
    if root.tag != "Xdmf":
        raise ValueError(f"{path}: not an XDMF file (its root element is <{root.tag}>, not <Xdmf>)")
    return root


def _series_collection(root: ET.Element) -> ET.Element | None:
    """The temporal collection grid that SeriesWriter writes, or None."""
    domain = root.find("Domain")
    if domain is None:
        return None
    for grid in domain.findall("Grid"):
        if grid.get("GridType") == "Collection" and grid.get("CollectionType", "Temporal") == "Temporal":
            return grid
    return None


def _is_series(path) -> bool:
    """Whether ``path`` is an XDMF time series (what SeriesWriter writes), as opposed to a
    single mesh (what ``Mesh.write`` writes through meshio). Raises like ``read_series`` for a
    file that is not XDMF at all."""
    path = Path(path)
    return _series_collection(_xdmf_root(path)) is not None


def _data_item(path: Path, parent: ET.Element, where: str) -> _Item:
    item = parent.find("DataItem")
    if item is None:
        raise ValueError(f"{path}: {where} has no <DataItem>")
    if item.get("Format", "XML") != "HDF":
        raise ValueError(f"{path}: {where} stores its data as {item.get('Format', 'XML')}, "
                         "only HDF data items (what SeriesWriter writes) are read")
    text = (item.text or "").strip(_XML_WHITESPACE)
    name, separator, dataset = text.partition(":/")
    if not separator or not name:
        raise ValueError(f"{path}: {where} refers to {text!r}, not to 'file.h5:/dataset'")
    try:
        shape = tuple(int(n) for n in item.get("Dimensions", "").split())
    except ValueError:
        shape = ()
    if not shape or min(shape) < 0:
        raise ValueError(f"{path}: {where} has no usable Dimensions ({item.get('Dimensions')!r})")
    return _Item(path.parent / name, "/" + dataset, shape)


def _step_refs(path: Path, collection: ET.Element) -> list[_StepRef]:
    steps = []
    for index, grid in enumerate(collection.findall("Grid")):
        where = f"step {index}"
        time = grid.find("Time")
        try:
            value = float(time.get("Value"))
        except (AttributeError, TypeError, ValueError):
            raise ValueError(f"{path}: {where} has no <Time Value=...>") from None
        topology, geometry = grid.find("Topology"), grid.find("Geometry")
        if topology is None or geometry is None:
            raise ValueError(f"{path}: {where} has no <Topology> or no <Geometry> "
                             "(not a series written by SeriesWriter)")
        kind = (topology.get("TopologyType") or topology.get("Type") or "").lower()
        if kind not in _TOPOLOGIES:
            raise ValueError(f"{path}: {where} has topology {kind or 'none'!r}; triangles or tetrahedra are read")
        columns = _GEOMETRIES.get(geometry.get("GeometryType") or geometry.get("Type") or "XYZ")
        if columns is None:
            raise ValueError(f"{path}: {where} has geometry type {geometry.get('GeometryType')!r}; XYZ or XY are read")
        dim = _step_dimension(path, grid, where, kind)
        cells = _data_item(path, topology, f"{where} topology")
        points = _data_item(path, geometry, f"{where} geometry")
        if len(cells.shape) != 2 or cells.shape[1] != _TOPOLOGIES[kind]:
            raise ValueError(f"{path}: {where} topology has dimensions {cells.shape} for {kind} cells")
        if len(points.shape) != 2 or points.shape[1] != columns:
            raise ValueError(f"{path}: {where} geometry has dimensions {points.shape} for {columns} coordinates")
        attributes = []
        for attribute in grid.findall("Attribute"):
            name, center = attribute.get("Name"), attribute.get("Center", "Node")
            what = f"{where} field {name!r}"
            if not name or center not in ("Node", "Cell"):
                raise ValueError(f"{path}: {what} is not a named Node or Cell attribute (Center={center!r})")
            item = _data_item(path, attribute, what)
            rows = points.shape[0] if center == "Node" else cells.shape[0]
            if item.shape[0] != rows:
                raise ValueError(f"{path}: {what} has {item.shape[0]} values for {rows} "
                                 f"{'points' if center == 'Node' else 'cells'}")
            attributes.append((name, center, attribute.get("AttributeType", "Scalar"), item))
        steps.append(_StepRef(value, dim, _TOPOLOGIES[kind], cells, points, attributes))
    return steps


def _step_dimension(path: Path, grid: ET.Element, where: str, kind: str) -> int | None:
    """The coordinate dimension the step says it has (``<Information Name="dimension">``),
    None if it does not say."""
    information = grid.find("Information[@Name='dimension']")
    if information is None:
        return None
    value = information.get("Value")
    allowed = ("2", "3") if kind == "triangle" else ("3",)
    if value not in allowed:
        raise ValueError(f"{path}: {where} says its dimension is {value!r}; {kind} cells are in "
                         f"{' or '.join(allowed)} dimensions")
    return int(value)


class _Datasets:
    """Reads the HDF5 datasets the XDMF file refers to, each file opened once, each dataset
    read once; errors name the XDMF file, the HDF5 file and the dataset."""

    def __init__(self, path: Path, stack: contextlib.ExitStack):
        self.path, self.stack = path, stack
        self.files: dict[Path, h5py.File] = {}
        self.cache: dict[tuple[_Item, bool], np.ndarray] = {}

    def _dataset(self, item: _Item) -> h5py.Dataset:
        file = self.files.get(item.file)
        if file is None:
            if not item.file.is_file():
                raise ValueError(f"{self.path}: its data file {item.file} is missing")
            try:
                file = self.files[item.file] = self.stack.enter_context(h5py.File(item.file, "r"))
            except OSError as error:
                raise ValueError(f"{self.path}: cannot read its data file {item.file} ({error})") from None
        dataset = file.get(item.dataset)
        if not isinstance(dataset, h5py.Dataset):
            raise ValueError(f"{self.path}: refers to {item.dataset}, which is not in {item.file}")
        if dataset.shape != item.shape:
            raise ValueError(f"{self.path}: {item.file}:{item.dataset} has shape {dataset.shape}, "
                             f"the XDMF file says {item.shape}")
        return dataset

    def read(self, item: _Item, z_only: bool = False) -> np.ndarray:
        """The dataset, or only its third column (``z_only``)."""
        key = (item, z_only)
        if key not in self.cache:
            dataset = self._dataset(item)
            if z_only:
                self.cache[key] = dataset[:, 2] if len(item.shape) == 2 and item.shape[1] == 3 else np.zeros(0)
            else:
                self.cache[key] = dataset[()]
        return self.cache[key]


def _read(path, last_only: bool = False) -> list[SeriesStep]:
    path = Path(path)
    collection = _series_collection(_xdmf_root(path))
    if collection is None:
        raise ValueError(f"{path}: no temporal collection of grids, not a series written by SeriesWriter "
                         "(Mesh.read reads a single mesh)")
    refs = _step_refs(path, collection)
    if not refs:
        return []
    with contextlib.ExitStack() as stack:
        data = _Datasets(path, stack)
        # snede pads 2D points and vectors with z = 0, and each step says its dimension. In a
        # series from before steps said it, triangles are 2D when no triangle mesh of the
        # series has a z ≠ 0 in its points or vector fields (a flat surface reads as 2D).
        guessed = [ref for ref in refs if ref.dim is None and ref.corners == 3 and ref.points.shape[1] == 3]
        planar = all(not np.any(data.read(item, z_only=True))
                     for ref in guessed
                     for item in [ref.points] + [a[3] for a in ref.attributes if a[2] == "Vector"])
        meshes: dict[tuple[_Item, _Item], Mesh] = {}
        steps = []
        for index, ref in enumerate(refs):
            if last_only and index < len(refs) - 1:
                continue
            dim = ref.dim or (2 if ref.corners == 3 and (planar or ref.points.shape[1] == 2) else 3)
            key = (ref.cells, ref.points)
            if key not in meshes:
                try:
                    meshes[key] = Mesh(data.read(ref.points)[:, :dim], data.read(ref.cells))
                except ValueError as error:
                    raise ValueError(f"{path}: step {index}: the mesh in {ref.cells.file.name}:"
                                     f"{ref.cells.dataset.rsplit('/', 1)[0]} is not valid: {error}") from None
            point_fields, cell_fields = {}, {}
            for name, center, kind, item in ref.attributes:
                values = np.asarray(data.read(item), dtype=np.float64)
                if kind == "Vector" and values.ndim == 2:
                    values = values[:, :dim]
                (point_fields if center == "Node" else cell_fields)[name] = values
            steps.append(SeriesStep(ref.time, meshes[key], point_fields, cell_fields))
    return steps


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
    return _read(path)
