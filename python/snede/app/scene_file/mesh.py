"""The ``[mesh]`` table of a scene file: a mesh file (``file``), a closed surface filled with
tetrahedra (``surface`` and ``size``), or a shape of ``snede.meshing`` (``shape`` and its
parameters); then ``scale``, ``translate`` and ``target_cells``, whatever the source, and
``max_cells``: the most tetrahedra the body may have, as made and as a needle's ``h_ref`` refines
it (``snede.meshing.MAX_CELLS`` unless given), checked before anything is made."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Callable

import numpy as np

from snede import meshing
from snede.mesh import Mesh
from snede.mesh_groups import copy_groups
from snede.app.scene_file.reading import (BOOLEAN, COUNT, COUNTS_3, POINT, POSITIVE, POSITIVE_3, SEED, TEXT, Table,
                                      choice, integer_kind, shown)

SOURCES = ("file", "surface", "shape")
GMSH_SEED = 1  # gmsh's random seed unless the file gives one: the same mesh at every run
# The shapes of snede.meshing a scene file makes, with their parameters (kind, default).
SHAPES = {
    "box": {"size": (POSITIVE_3, [1.0, 1.0, 1.0]), "divisions": (COUNTS_3, [10, 10, 10])},
    "ellipsoid": {"radii": (POSITIVE_3, [0.06, 0.04, 0.03]), "h": (POSITIVE, 0.01), "seed": (SEED, GMSH_SEED)},
    "cylinder": {"length": (POSITIVE, 0.1), "radius": (POSITIVE, 0.03), "h": (POSITIVE, 0.01),
                 "seed": (SEED, GMSH_SEED)},
    "torus": {"radius": (POSITIVE, 0.05), "tube": (POSITIVE, 0.02), "h": (POSITIVE, 0.01), "seed": (SEED, GMSH_SEED)},
    "lumpy": {"radius": (POSITIVE, 0.04), "lumps": (integer_kind("an integer ≥ 0", 0), 6), "h": (POSITIVE, 0.01),
              "seed": (SEED, 0)},
}


def _existing(table: Table, key: str, folder: Path) -> Path:
    """The file ``key`` names, relative to the scene file's folder; an error if there is none."""
    path = folder / table.get(key, TEXT, meaning="a path, relative to the scene file")
    if not path.is_file():
        table.fail(key, f"names no file: {path}")
    return path


def _read(table: Table, key: str, path: Path) -> Mesh:
    try:
        return Mesh.read(path)
    except (ValueError, OSError) as error:
        table.fail(key, f"could not be read: {error}")


def read_mesh(table: Table, folder: Path) -> tuple[Callable[[], Mesh], int]:
    """Check the ``[mesh]`` table; what makes the mesh (its errors name the key) and the most
    cells the body may have."""
    source = table.one_of(SOURCES)
    scale, shift = table.get("scale", POSITIVE, 1.0), np.array(table.get("translate", POINT, [0.0, 0.0, 0.0]))
    target = table.get("target_cells", COUNT, None)
    max_cells = table.get("max_cells", COUNT, meshing.MAX_CELLS)
    if target is not None:
        _check_cells(table, "target_cells", target, max_cells, str(target), "give a smaller one")

    def moved(mesh: Mesh) -> Mesh:
        if scale == 1.0 and not shift.any():
            return mesh
        result = Mesh(mesh.points * scale + shift, mesh.cells)
        copy_groups(mesh, result)  # a file's named groups
        return result

    if source == "file":
        path = _existing(table, "file", folder)
        make = lambda: moved(_read(table, "file", path))  # noqa: E731
    elif source == "surface":
        path = _existing(table, "surface", folder)
        size = table.get("size", POSITIVE, meaning="the tetrahedra's edge length, in metres after scale")
        remesh, seed = table.get("remesh", BOOLEAN, True), table.get("seed", SEED, GMSH_SEED)
        make = lambda: _fill(table, moved(_read(table, "surface", path)), size, remesh, seed, max_cells)  # noqa: E731
    else:
        shape = table.get("shape", choice(SHAPES))
        parameters = {name: table.get(name, kind, default) for name, (kind, default) in SHAPES[shape].items()}
        if shape == "box":  # the count is exact
            _check_cells(table, "divisions", 6 * math.prod(parameters["divisions"]), max_cells,
                         shown(parameters["divisions"]), "give fewer divisions")
        else:
            parameters["max_cells"] = max_cells
        make = lambda: moved(_generate(table, shape, parameters))  # noqa: E731
    table.close()

    def made() -> Mesh:
        mesh = make()
        if mesh.cell_dim != 3:
            table.fail(source, f"gives {mesh!r}: a scene file's body is tetrahedral (fill a closed surface "
                               "with surface = ... and size = ...)")
        if target is not None:
            mesh.refine_uniform(target_cells=target)
        return mesh
    return made, max_cells


def _check_cells(table: Table, key: str, cells: float, max_cells: int, given: str, remedy: str) -> None:
    """Refuse ``cells`` beyond ``max_cells``, naming ``key`` (whose value is ``given``)."""
    try:
        meshing.check_cells(cells, max_cells, given, f"{remedy}, or raise {table.key('max_cells')} if you mean it")
    except ValueError as error:
        table.fail(key, str(error))


def _fill(table: Table, surface: Mesh, size: float, remesh: bool, seed: int, max_cells: int) -> Mesh:
    if not surface.is_surface:
        table.fail("surface", f"holds {surface!r}, not a surface (triangles in 3D); a volume mesh is file = ...")
    try:
        return meshing.tetrahedralize(surface, size, remesh=remesh, seed=seed, max_cells=max_cells)
    except ValueError as error:
        table.fail("surface", f"could not be filled with tetrahedra: {error}")


def _generate(table: Table, shape: str, parameters: dict) -> Mesh:
    try:
        return getattr(meshing, shape)(**parameters)
    except (ValueError, RuntimeError) as error:
        table.fail("shape", f'"{shape}" could not be made: {error}')
