"""Reading mesh files for ``Mesh.read``: meshio's reader for the file's suffix first, then gmsh's
own reader (in a child process: it crashes on some damaged files) for what meshio cannot read,
a reader of VTK legacy POLYDATA surfaces, which neither reads, and one of gmsh's format 1, which
meshio cannot read and gmsh's reader reads without each element's physical group. Every reader
gives ``(points, blocks)``: (n, 2|3) points and {meshio cell type: (m, corners) vertex indices},
quads and polygons split into triangles; and the file's named groups.

Text gmsh 2 and VTK legacy files are checked first, where their readers misread or crash: each
gmsh section has the lines its count announces, each VTK section line its numbers."""
from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import numpy as np

from snede import _gmsh
from snede._errors import Error

#: meshio's format for each suffix Mesh.read knows by name
MESHIO_FORMATS = {".msh": "gmsh", ".vtk": "vtk", ".vtu": "vtu", ".mesh": "medit", ".meshb": "medit", ".stl": "stl",
                  ".obj": "obj", ".off": "off", ".ply": "ply", ".xdmf": "xdmf", ".xmf": "xdmf"}
#: suffixes gmsh's own reader is tried on when meshio fails
GMSH_SUFFIXES = (".msh", ".vtk", ".stl", ".mesh", ".off")


class DamagedFile(Error, ValueError):
    """A file that contradicts itself (a count and the lines that follow it): no reader is tried
    on it."""


def read_blocks(path: Path) -> tuple[np.ndarray, dict[str, np.ndarray], list]:
    """The points, cell blocks and named groups of the first reader that reads ``path``; a
    ValueError naming the file and why each reader failed if none does, or what is wrong with
    the file if it is damaged. OSError (permissions, a folder) passes. Groups are (cell type,
    name, (m, corners) vertex indices) triples, one per cell type and name: gmsh's physical
    groups (those that share a name joined), or a VTK file's integer cell data (``"array=value"``)."""
    reasons = []
    try:
        with open(path, "rb") as file:  # a folder or an unreadable file: the OSError says why
            head = file.read(256)
        check_counts(path, head)
        for name, reader in _readers(path, head):
            try:
                points, blocks, *groups = reader(path)
            except (OSError, DamagedFile):
                raise
            except Exception as error:  # meshio's parsers fail in many ways
                reasons.append(f"{name}: {_reason(error)}")
                continue
            if len(points):
                return points, blocks, _joined(groups[0] if groups else [])
            reasons.append(f"{name}: no points in it")
    except DamagedFile as error:
        raise ValueError(f"{path}: {error}") from None
    raise ValueError(f"{path}: could not read this file as a mesh ({'; '.join(reasons)})")


def _joined(groups: list) -> list:
    """One group per cell type and name. Physical groups that share a name are one group, as a
    name is in gmsh (a second ``Physical Volume("a") = ...`` in a .geo file redefines group "a");
    so are one array value's cells in several blocks."""
    joined: dict[tuple[str, str], list] = {}
    for kind, name, cells in groups:
        joined.setdefault((kind, name), []).append(np.asarray(cells, dtype=np.int64))
    return [(kind, name, np.concatenate(parts)) for (kind, name), parts in joined.items()]


def _reason(error: Exception) -> str:
    """The error's message, after its type unless it is a ValueError or meshio's ReadError."""
    kind = type(error).__name__
    return str(error) if kind in ("ValueError", "ReadError") else f"{kind}: {error}"


def _readers(path: Path, head: bytes) -> list:
    suffix = path.suffix.lower()
    if suffix == ".msh" and head.lstrip().startswith(b"$NOD"):  # gmsh format 1: meshio cannot read it
        return [("gmsh format 1", read_gmsh_1)]
    readers = [("meshio", _meshio_reader(MESHIO_FORMATS.get(suffix)))]
    if suffix == ".vtk" and head.lstrip().startswith(b"<"):  # an XML (VTU) file named .vtk
        readers.append(("meshio as VTU", _meshio_reader("vtu")))
    if suffix == ".vtk" and b"POLYDATA" in head.upper():
        readers.append(("VTK POLYDATA", read_vtk_polydata))
    if suffix in GMSH_SUFFIXES:
        readers.append(("gmsh", read_with_gmsh))
    return readers


def _meshio_reader(file_format: str | None):
    def read(path: Path):
        import meshio

        # meshio prints why its readers failed (and rich warnings), then calls sys.exit: keep
        # the noise out, and give what it printed last as the reason.
        printed = io.StringIO()
        try:
            with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(io.StringIO()):
                data = meshio.read(str(path), file_format=file_format)
        except SystemExit:
            lines = printed.getvalue().strip().splitlines()
            raise ValueError(lines[-1] if lines else "could not parse it") from None
        blocks = collect((block.type, block.data) for block in data.cells)
        if file_format == "gmsh":
            return (np.asarray(data.points),) + _gmsh_groups(path, data, blocks)
        return np.asarray(data.points), blocks, _cell_data_groups(data)
    return read


#: the cell types groups are read for, with their dimension (gmsh's physical groups are per dimension)
_GROUP_TYPES = {"tetra": 3, "triangle": 2, "line": 1}


def _cell_data_groups(data) -> list:
    """Of a file of another format than gmsh's: the physical groups of gmsh's tags if meshio
    gives them (a file converted by meshio from gmsh's), named by its field data; else (cell
    type, "array=value", cells) for each value of an integer cell-data array (of one component:
    VTK's ``SCALARS region int 1`` comes as (n, 1)) with at most 64 values."""
    if "gmsh:physical" in data.cell_data:
        names = {(int(value[1]), int(value[0])): name for name, value in data.field_data.items() if len(value) >= 2}
        return _physical_groups(_tagged_by_element(data), names)
    groups = []
    for array_name, arrays in data.cell_data.items():
        if array_name.startswith("gmsh:"):  # gmsh's elementary entities are not groups
            continue
        for block, values in zip(data.cells, arrays):
            values = _column(values)
            if block.type not in _GROUP_TYPES or values.ndim != 1 or values.dtype.kind not in "iu":
                continue
            distinct = np.unique(values)
            if len(distinct) <= 64:
                groups += [(block.type, f"{array_name}={int(v)}", block.data[values == v]) for v in distinct]
    return groups


def _gmsh_groups(path: Path, data, blocks: dict) -> tuple[dict, list]:
    """The cell blocks and physical groups of a gmsh file meshio read. meshio keeps one physical
    group per element and one per name, so the groups come from the file's own sections: in
    format 4 each entity's groups ($Entities), in format 2 each element's group, an element in
    two groups written twice (taken once in the blocks)."""
    version, names, entity_groups = _gmsh_sections(path)
    tagged = []  # (cell type, cells, physical tag)
    if version >= 4:
        for block, entities in zip(data.cells, data.cell_data.get("gmsh:geometrical", [])):
            dim = _GROUP_TYPES.get(block.type)
            for entity in np.unique(entities) if dim else ():
                tagged += [(block.type, block.data[entities == entity], tag)
                           for tag in entity_groups.get((dim, int(entity)), ())]
    else:
        tagged = _tagged_by_element(data)
        blocks = {kind: _unrepeated(cells) for kind, cells in blocks.items()}
    return blocks, _physical_groups(tagged, names)


def _tagged_by_element(data) -> list:
    """(cell type, cells, physical tag) from meshio's physical tag of each element."""
    tagged = []
    for block, tags in zip(data.cells, data.cell_data.get("gmsh:physical", [])):
        tags = _column(tags)
        tagged += [(block.type, block.data[tags == tag], int(tag)) for tag in np.unique(tags) if tag > 0]
    return tagged


def _column(values) -> np.ndarray:
    """A cell-data array of one component as (n,)."""
    values = np.asarray(values)
    return values[:, 0] if values.ndim == 2 and values.shape[1] == 1 else values


def _physical_groups(tagged: list, names: dict) -> list:
    """(cell type, name, cells) from (cell type, cells, physical tag): named by the file's
    $PhysicalNames ({(dim, tag): name}), else as ``_gmsh.unnamed_group``."""
    groups = []
    for kind, cells, tag in tagged:
        dim = _GROUP_TYPES.get(kind)
        if dim:
            groups.append((kind, names.get((dim, tag)) or _gmsh.unnamed_group(dim, tag), cells))
    return groups


def _unrepeated(cells: np.ndarray) -> np.ndarray:
    """The cells without the repeats of an earlier one, in their order: gmsh formats 1 and 2
    write an element once per physical group it is in."""
    if len(cells) < 2:
        return cells
    _, first = np.unique(cells, axis=0, return_index=True)
    return cells[np.sort(first)]


def read_with_gmsh(path: Path):
    """gmsh's own reader, in a child process (``_gmsh.read_file_in_child``)."""
    points, blocks, groups = _gmsh.read_file_in_child(path)
    return points, collect(blocks), groups


# -- gmsh's sections ----------------------------------------------------------------------------
def _gmsh_sections(path: Path) -> tuple[float, dict, dict]:
    """A gmsh file's version, its $PhysicalNames as {(dim, tag): name} (every one: meshio keeps
    one tag per name) and, in format 4, each entity's physical groups from $Entities as
    {(dim, entity): [tags]} (meshio keeps the first). Both sections come before $Nodes."""
    head = bytearray()
    with open(path, "rb") as file:
        while chunk := file.read(1 << 20):
            head += chunk
            if (end := head.find(b"$Nodes", max(len(head) - len(chunk) - 8, 0))) >= 0:
                del head[end:]
                break
    header = re.search(rb"^\$MeshFormat\s+(\S+)\s+(\d+)\s+(\d+)", head, re.M)
    if header is None:
        raise ValueError("no $MeshFormat section")
    version, binary, size = float(header[1]), header[2] == b"1", int(header[3])
    names = {}
    section = _gmsh_section(head, b"PhysicalNames")
    for line in (section or b"").decode("utf-8", "replace").splitlines():
        if match := re.match(r'\s*(\d+)\s+(\d+)\s+"(.*)"\s*$', line):
            names[int(match[1]), int(match[2])] = match[3]
    section = _gmsh_section(head, b"Entities") if version >= 4 else None
    return version, names, {} if section is None else _entity_groups(section, version, binary, size)


def _gmsh_section(head: bytes, name: bytes) -> bytes | None:
    """The body of a gmsh file's section ``$name`` ... ``$Endname`` (up to the end if it has none)."""
    start = re.search(rb"^\$" + name + rb"[ \t]*\r?\n", head, re.M)
    if start is None:
        return None
    end = head.find(b"$End" + name, start.end())
    return bytes(head[start.end():end if end >= 0 else len(head)])


def _entity_groups(section: bytes, version: float, binary: bool, size: int) -> dict:
    """{(dim, entity): physical tags} from the body of a format 4 $Entities section: per
    dimension a count, then per entity its tag, bounding box (a point's is its position in 4.1),
    physical tags and (above points) bounding entities, each list after its length."""
    if binary:
        types, position = {"size": np.dtype(f"<u{size}"), "int": np.dtype("<i4"), "double": np.dtype("<f8")}, 0

        def take(kind: str, count: int):
            nonlocal position
            values = np.frombuffer(section, types[kind], count, position)
            position += values.nbytes
            return values
    else:
        words, position = section.split(), 0

        def take(kind: str, count: int):
            nonlocal position
            position += count
            if position > len(words):
                raise ValueError("it ends early")
            return words[position - count:position] if kind == "double" else [int(w) for w in words[position - count:position]]
    groups = {}
    try:
        for dim, count in enumerate(take("size", 4)):
            for _ in range(int(count)):
                entity = int(take("int", 1)[0])
                take("double", 3 if dim == 0 and version >= 4.1 else 6)
                groups[dim, entity] = [int(tag) for tag in take("int", int(take("size", 1)[0]))]
                if dim > 0:
                    take("int", int(take("size", 1)[0]))
    except ValueError as error:
        raise ValueError(f"its $Entities section is damaged ({error})") from None
    return groups


# -- gmsh format 1 ------------------------------------------------------------------------------
def read_gmsh_1(path: Path):
    """gmsh's format 1 ($NOD and $ELM sections; SOFA's liver.msh): the nodes, the elements of the
    types in ``_gmsh.TYPES``, and each element's physical group ("physical volume N": the format
    has no names). An element line is ``number type physical elementary node-count nodes...``."""
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    node_lines, element_lines = _counted_section(lines, "$NOD"), _counted_section(lines, "$ELM")
    if node_lines is None or element_lines is None:
        raise DamagedFile(f"no {'$NOD' if node_lines is None else '$ELM'} section")
    numbers, points = _numbered_points(node_lines)
    if len(numbers) == 0:
        return points, {}, []
    elements: dict[str, list] = {}  # cell type → [(line number, physical tag, node numbers)]
    for number, line in element_lines:
        try:
            values = [int(word) for word in line.split()]
        except ValueError:
            values = []
        if len(values) < 5 or len(values) != 5 + values[4]:
            raise DamagedFile(f"line {number}: an element is 'number type physical elementary node-count nodes...', "
                              f"found {line.strip()!r}")
        if values[1] in _gmsh.TYPES:
            kind, corners = _gmsh.TYPES[values[1]]
            if values[4] != corners:
                raise DamagedFile(f"line {number}: a {kind} has {corners} nodes, not {values[4]}")
            elements.setdefault(kind, []).append((number, values[2], values[5:]))
    order = np.argsort(numbers)
    tagged = []  # (cell type, cells, physical tag)
    blocks = {}
    for kind, entries in elements.items():
        nodes = np.array([entry[2] for entry in entries], dtype=np.int64)
        rows = order[np.minimum(np.searchsorted(numbers, nodes, sorter=order), len(numbers) - 1)]
        if np.any(unknown := numbers[rows] != nodes):
            entry = int(np.flatnonzero(unknown.any(axis=1))[0])
            raise DamagedFile(f"line {entries[entry][0]}: node {nodes[unknown][0]} is not in $NOD")
        tags = np.array([entry[1] for entry in entries])
        tagged += [(kind, rows[tags == tag], int(tag)) for tag in np.unique(tags) if tag > 0]
        blocks[kind] = rows
    blocks = {kind: _unrepeated(cells) for kind, cells in collect(blocks.items()).items()}
    return points, blocks, _physical_groups(tagged, {})


def _numbered_points(node_lines: list) -> tuple[np.ndarray, np.ndarray]:
    """The node numbers and (n, 3) points of "number x y z" lines, each number once."""
    rows = [line.split() for _, line in node_lines]
    try:
        values = np.array(rows, dtype=float).reshape(len(rows), 4)
    except ValueError:
        number, line = next((n, line) for (n, line), words in zip(node_lines, rows)
                            if len(words) != 4 or not all(map(_is_number, words)))
        raise DamagedFile(f"line {number}: a node is 'number x y z', found {line.strip()!r}") from None
    numbers = values[:, 0].astype(np.int64)
    distinct, counts = np.unique(numbers, return_counts=True)
    if np.any(counts > 1):
        repeated = distinct[counts > 1][0]
        first, second = [n for (n, _), number in zip(node_lines, numbers) if number == repeated][:2]
        raise DamagedFile(f"node {repeated} is on lines {first} and {second}")
    return numbers, values[:, 1:]


def _is_number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


# -- counts checked before reading --------------------------------------------------------------
def _counted_section(lines: list[str], header: str) -> list[tuple[int, str]] | None:
    """The lines of a gmsh text section (``header``, a count, as many lines, ``$End...``) as
    (line number, line), blank lines left out; None if the file has no such section. A
    DamagedFile names the line if the count is not the number of lines: gmsh's reader crashes on
    one line too many, and meshio's reads one line too few without a word."""
    end = "$END" + header[1:].upper()  # format 1's are upper case, format 2's "$EndNodes"
    start = next((k for k, line in enumerate(lines) if line.startswith(header) and line.rstrip() == header), None)
    if start is None:
        return None
    count = lines[start + 1].strip() if start + 1 < len(lines) else ""
    if not count.isdigit():
        raise DamagedFile(f"line {start + 2}: {header} is followed by its count, not {count!r}")
    body = []
    for number, line in enumerate(lines[start + 2:], start + 3):
        if line.startswith("$") and line.split()[0].upper() == end:
            break
        if line and not line.isspace():
            body.append((number, line))
    else:
        raise DamagedFile(f"line {start + 1}: {header} has no {end if header.isupper() else '$End' + header[1:]} "
                          "after it")
    if len(body) != int(count):
        raise DamagedFile(f"line {start + 2}: {header} announces {int(count)}, but {len(body)} lines follow "
                          f"before {line.split()[0]}")
    return body


#: a VTK legacy file's section lines and what follows their keyword (the counts, and POINTS' type)
_CELLS = ("<number of cells>", "<number of values>")
_VTK_SECTION_LINES = {"POINTS": ("<number of points>", "<type>"), "CELLS": _CELLS, "VERTICES": _CELLS,
                      "LINES": _CELLS, "POLYGONS": _CELLS, "TRIANGLE_STRIPS": _CELLS,
                      "CELL_TYPES": ("<number of cells>",), "CELL_DATA": ("<number of cells>",),
                      "POINT_DATA": ("<number of points>",)}


def check_counts(path: Path, head: bytes) -> None:
    """A DamagedFile if a text gmsh 2 file's $Nodes, $Elements or $PhysicalNames section has not
    the lines its count announces, or a text VTK legacy file's section line has not its numbers
    (gmsh's reader crashes, or meshio's misreads, on these)."""
    gmsh_2 = re.match(rb"\s*\$MeshFormat\s+2(\.\d+)?\s+0\s", head)
    vtk = re.match(rb"# vtk DataFile[^\n]*\n[^\n]*\n\s*ASCII\s", head, re.I)
    if not (gmsh_2 or vtk):
        return
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    if gmsh_2:
        for header in ("$PhysicalNames", "$Nodes", "$Elements"):
            _counted_section(lines, header)
        return
    for number, line in enumerate(lines, 1):
        words = line.split()
        form = _VTK_SECTION_LINES.get(words[0]) if words else None
        if form is not None and (len(words) != 1 + len(form) or not all(
                word.isdigit() for word, field in zip(words[1:], form) if field.startswith("<number"))):
            raise DamagedFile(f"line {number}: {line.strip()!r} should be '{words[0]} {' '.join(form)}'")


# -- VTK legacy POLYDATA ------------------------------------------------------------------------
_VTK_TYPES = {"float": "f4", "double": "f8", "int": "i4", "unsigned_int": "u4", "long": "i8", "unsigned_long": "u8",
              "vtktypeint32": "i4", "vtktypeint64": "i8", "short": "i2", "unsigned_short": "u2"}


class _Words:
    """The words of a VTK legacy file after its header, and its arrays (text, or big-endian binary
    data starting on the line after the word before them)."""

    _WORD = re.compile(rb"\S+")

    def __init__(self, data: bytes, start: int, binary: bool):
        self.data, self.position, self.binary = data, start, binary

    def next(self) -> str | None:
        match = self._WORD.search(self.data, self.position)
        if match is None:
            return None
        self.position = match.end()
        return match.group().decode("ascii", "replace")

    def peek(self) -> str | None:
        match = self._WORD.search(self.data, self.position)
        return None if match is None else match.group().decode("ascii", "replace")

    def array(self, count: int, vtk_type: str) -> np.ndarray:
        code = _VTK_TYPES.get(vtk_type.lower())
        if code is None:
            raise ValueError(f"unknown VTK data type {vtk_type!r}")
        if self.binary:
            self.position = self.data.index(b"\n", self.position) + 1
            values = np.frombuffer(self.data, dtype=">" + code, count=count, offset=self.position)
            self.position += count * values.itemsize
            return values.astype(code)
        words = self.data[self.position:].split(None, count)
        if len(words) < count:
            raise ValueError(f"the file ends inside an array of {count} values")
        self.position = len(self.data) - (len(words[count]) if len(words) > count else 0)
        return np.array(words[:count]).astype("f8" if code[0] == "f" else code)  # text: keep its digits


def read_vtk_polydata(path: Path):
    """A VTK legacy file of ``DATASET POLYDATA`` (ASCII or binary, VTK 2 to 5.1 layouts): its
    points and the triangles of its polygons (split into fans) and triangle strips."""
    data = path.read_bytes()
    lines = data.split(b"\n", 4)
    if len(lines) < 5 or not lines[0].startswith(b"# vtk DataFile"):
        raise ValueError("no '# vtk DataFile' header")
    encoding, dataset = lines[2].strip().upper(), lines[3].split()
    if encoding not in (b"ASCII", b"BINARY") or dataset[1:2] != [b"POLYDATA"]:
        raise ValueError(f"not an ASCII or BINARY POLYDATA file ({lines[2].strip()!r}, {lines[3].strip()!r})")
    words = _Words(data, len(data) - len(lines[4]), encoding == b"BINARY")
    points, blocks = None, []
    while (key := words.next()) is not None and key.upper() not in ("POINT_DATA", "CELL_DATA"):
        key = key.upper()
        if key == "POINTS":
            n = int(words.next())
            points = words.array(3 * n, words.next()).reshape(n, 3)
        elif key in ("VERTICES", "LINES", "POLYGONS", "TRIANGLE_STRIPS"):
            cells = _vtk_cells(words, int(words.next()), int(words.next()))
            if key == "POLYGONS":
                blocks += [("polygon", rows) for rows in cells if rows.shape[1] >= 3]
            elif key == "TRIANGLE_STRIPS":
                blocks += [("triangle", _strips(rows)) for rows in cells if rows.shape[1] >= 3]
        # other words (a METADATA section's entries) are passed over up to the next section
    if points is None:
        raise ValueError("no POINTS section")
    return points, collect(blocks)


def _vtk_cells(words: _Words, first: int, second: int) -> list[np.ndarray]:
    """The cells of a VERTICES/LINES/POLYGONS/TRIANGLE_STRIPS section, whose header gave ``first``
    and ``second``: (cells, total size) with each cell's vertex count first (VTK < 5.1), or
    (offsets, connectivity) followed by OFFSETS and CONNECTIVITY arrays (VTK 5.1). One (m, k)
    array of vertex indices per cell size k."""
    if words.peek() == "OFFSETS":
        words.next()
        offsets = words.array(first, words.next()).astype(np.int64)
        if words.next() != "CONNECTIVITY":
            raise ValueError("OFFSETS without CONNECTIVITY")
        connectivity = words.array(second, words.next()).astype(np.int64)
        starts, sizes = offsets[:-1], np.diff(offsets)
    else:
        connectivity = words.array(second, "int").astype(np.int64)
        k = int(connectivity[0]) if second else 0
        if second == first * (k + 1) and np.all(connectivity[::k + 1] == k):  # all of one size
            return [connectivity.reshape(first, k + 1)[:, 1:]]
        starts = np.empty(first, dtype=np.int64)
        position = 0
        for cell in range(first):  # each count says where the next cell starts
            count = int(connectivity[position]) if position < second else -1
            if not 0 <= count < second - position:
                raise ValueError(f"the cells' sizes run past the section's {second} values: the file is damaged")
            starts[cell] = position + 1
            position += count + 1
        if position != second:
            raise ValueError(f"cell sizes add up to {position}, the section says {second}")
        sizes = connectivity[starts - 1]
    return [connectivity[starts[sizes == k, None] + np.arange(k)] for k in np.unique(sizes)]


def _strips(strips: np.ndarray) -> np.ndarray:
    """The triangles of triangle strips of k vertices (m, k): (j, j + 1, j + 2), every second
    one turned so that all share one orientation."""
    j = np.arange(strips.shape[1] - 2)
    corners = np.c_[j, j + 1, j + 2]
    corners[1::2] = corners[1::2][:, [1, 0, 2]]
    return strips[:, corners].reshape(-1, 3)


def collect(blocks) -> dict[str, np.ndarray]:
    """{cell type: (m, corners) vertex indices} from (cell type, cells) pairs, blocks of one type
    joined; quads and polygons (``"polygon"``, rows of k ≥ 3 vertices) become triangles, each a
    fan (0, j, j + 1) from its first vertex."""
    joined: dict[str, list[np.ndarray]] = {}
    for kind, cells in blocks:
        cells = np.asarray(cells, dtype=np.int64)
        if kind in ("quad", "polygon"):
            j = np.arange(1, cells.shape[1] - 1)
            kind, cells = "triangle", np.stack([np.repeat(cells[:, :1], len(j), 1), cells[:, j], cells[:, j + 1]],
                                               axis=-1).reshape(-1, 3)
        joined.setdefault(kind, []).append(cells)
    return {kind: np.concatenate(parts) for kind, parts in joined.items()}
