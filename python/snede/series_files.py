"""Reading the XDMF + HDF5 time series that ``snede.output.SeriesWriter`` writes: the XDMF file's
steps and the HDF5 datasets they refer to, checked and read into arrays. ``snede.output.read_series``
and ``Mesh.read`` (the last step of a series) make their meshes from them; this module imports no
mesh, so that ``snede.mesh`` can read a series without importing ``snede.output``."""
from __future__ import annotations

import contextlib
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

_TOPOLOGIES = {"triangle": 3, "tetrahedron": 4}
_GEOMETRIES = {"XYZ": 3, "XY": 2}
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


def is_series(path) -> bool:
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

    def rows(self, item: _Item, start: int, stop: int) -> np.ndarray:
        """Rows start..stop − 1 of the dataset, read alone (a rank's share of a mesh)."""
        return self._dataset(item)[start:stop]

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


def _last_step(path: Path) -> _StepRef:
    collection = _series_collection(_xdmf_root(path))
    if collection is None:
        raise ValueError(f"{path}: no temporal collection of grids, not a series written by SeriesWriter")
    refs = _step_refs(path, collection)
    if not refs:
        raise ValueError(f"{path}: the series has no steps (yet): no mesh to read")
    if refs[-1].dim is None:
        raise ValueError(f"{path}: from before series said their dimension; read it with snede.Mesh.read and "
                         "snede.distribute")
    return refs[-1]


def read_last_mesh_share(path, rank: int, ranks: int) -> tuple[np.ndarray, np.ndarray, bool]:
    """Rank ``rank``'s share of the last step's mesh of the series at ``path``, read alone (no
    rank reads the whole): its share of the cells, in file order, and of the points, as
    ``(cells, points, on_ranks)`` — what ``snede.distribute_cells`` takes; ``on_ranks``: the
    series was written on MPI ranks, its points in PETSc's order with their serial ids in the
    field ``serial_vertex`` (``read_serial_vertices``). Errors as ``read_series``."""
    path = Path(path)
    last = _last_step(path)

    def share(n: int) -> tuple[int, int]:
        return rank * n // ranks, (rank + 1) * n // ranks

    with contextlib.ExitStack() as stack:
        data = _Datasets(path, stack)
        cells = data.rows(last.cells, *share(last.cells.shape[0]))
        points = data.rows(last.points, *share(last.points.shape[0]))[:, :last.dim]
    on_ranks = any(name == "serial_vertex" and center == "Node" for name, center, *_ in last.attributes)
    return np.asarray(cells, dtype=np.int64), np.asarray(points, dtype=np.float64), on_ranks


def read_serial_vertices(path, rows: np.ndarray) -> np.ndarray:
    """The field ``serial_vertex`` of the last step at the point rows ``rows`` (read alone)."""
    path = Path(path)
    last = _last_step(path)
    item = next(item for name, center, _, item in last.attributes if name == "serial_vertex" and center == "Node")
    order = np.argsort(rows)
    with contextlib.ExitStack() as stack:
        values = _Datasets(path, stack)._dataset(item)[np.asarray(rows)[order]] if len(rows) else np.zeros(0)
    serial = np.empty(len(rows), dtype=np.int64)
    serial[order] = np.rint(np.asarray(values, dtype=np.float64)).astype(np.int64)
    return serial


def read_steps(path, make_mesh, last_only: bool = False) -> list[tuple]:
    """The steps of the series at ``path`` as (time, mesh, point_fields, cell_fields), the mesh
    made by ``make_mesh(points, cells)`` once for the steps that share it (``snede.output.SeriesStep``
    says what the fields hold); only the last step with ``last_only``. Errors as ``read_series``."""
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
        meshes = {}
        steps = []
        for index, ref in enumerate(refs):
            if last_only and index < len(refs) - 1:
                continue
            dim = ref.dim or (2 if ref.corners == 3 and (planar or ref.points.shape[1] == 2) else 3)
            key = (ref.cells, ref.points)
            if key not in meshes:
                try:
                    meshes[key] = make_mesh(data.read(ref.points)[:, :dim], data.read(ref.cells))
                except ValueError as error:
                    raise ValueError(f"{path}: step {index}: the mesh in {ref.cells.file.name}:"
                                     f"{ref.cells.dataset.rsplit('/', 1)[0]} is not valid: {error}") from None
            point_fields, cell_fields = {}, {}
            for name, center, kind, item in ref.attributes:
                values = np.asarray(data.read(item), dtype=np.float64)
                if kind == "Vector" and values.ndim == 2:
                    values = values[:, :dim]
                (point_fields if center == "Node" else cell_fields)[name] = values
            steps.append((ref.time, meshes[key], point_fields, cell_fields))
    return steps
