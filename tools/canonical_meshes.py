"""Regenerate the small canonical meshes kept in the repository's ``meshes/`` folder.

    .venv/bin/python tools/canonical_meshes.py [output-folder]      # or: make meshes

writes the meshes below (default folder: ``meshes/`` at the repository root), reads each file back to check that ``Mesh.read`` returns
exactly the points and cells that were written, and prints a table of what it wrote.

The cylinders follow the two cylinders of the thesis's Table 4.2 (length 0.1 m, radius 0.03 m,
about 1230 tetrahedra / 308 nodes and about 9300 tetrahedra / 1911 nodes). gmsh's Delaunay
mesher has a different ratio of tetrahedra to nodes than the mesher used there, so no ``h``
matches both counts exactly; the chosen target edge lengths give (gmsh 4.15, seed 1):

==================  =========  ==========  =====  ==============================
file                ``h`` (m)  tetrahedra  nodes  versus Table 4.2
==================  =========  ==========  =====  ==============================
cylinder_small.msh  0.0112     1125        328    −8.5 % tetrahedra, +6.5 % nodes
cylinder_large.msh  0.0054     8724        1958   −6.2 % tetrahedra, +2.5 % nodes
==================  =========  ==========  =====  ==============================

gmsh's output is not monotone in ``h`` (h = 0.0109 gives 1209 tetrahedra but 361 nodes),
which is why round values inside the ±10 % band were chosen rather than a fitted ``h``.
Another gmsh version may produce different counts: the files, not the generator, are the
reference.

Files are written as gmsh 2.2 ASCII (``$MeshFormat 2.2 0 8``), which gmsh itself, meshio and
most finite-element tools read; coordinates are written with 17 significant digits, so they
read back bit for bit. (``Mesh.write`` is not used: for ``.msh`` meshio picks its ANSYS
writer first, see the test ``tests/python/mesh/test_mesh_io.py::test_write_msh_is_a_gmsh_file``.)
"""
from __future__ import annotations

import contextlib
import io
import sys
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np

from snede import meshing
from snede.mesh import Mesh

#: The repository's ``meshes/`` folder, found relative to this file (python/snede/../../meshes).
MESH_DIR = Path(__file__).resolve().parent.parent / "meshes"

LENGTH = 0.1  #: cylinder length (m), Table 4.2
RADIUS = 0.03  #: cylinder radius (m), Table 4.2
SEED = 1  #: gmsh random seed for the cylinders
H_SMALL = 0.0112  #: target edge length of cylinder_small.msh (~1230 tetrahedra / 308 nodes)
H_LARGE = 0.0054  #: target edge length of cylinder_large.msh (~9300 tetrahedra / 1911 nodes)


class Canonical(NamedTuple):
    file: str
    description: str
    make: Callable[[], Mesh]


CANONICAL: tuple[Canonical, ...] = (
    Canonical(
        "cylinder_small.msh",
        f"cylinder length {LENGTH} m, radius {RADIUS} m, gmsh h = {H_SMALL} m, seed {SEED}",
        lambda: meshing.cylinder(LENGTH, RADIUS, H_SMALL, seed=SEED),
    ),
    Canonical(
        "cylinder_large.msh",
        f"cylinder length {LENGTH} m, radius {RADIUS} m, gmsh h = {H_LARGE} m, seed {SEED}",
        lambda: meshing.cylinder(LENGTH, RADIUS, H_LARGE, seed=SEED),
    ),
    Canonical(
        "box_2x2x2.msh",
        "unit cube, 2x2x2 cubes, Kuhn split (48 tetrahedra)",
        lambda: meshing.box((1.0, 1.0, 1.0), (2, 2, 2)),
    ),
    Canonical(
        "rectangle_4x4.msh",
        "unit square, 4x4 squares split along (x, y)-(x+h, y+h) (32 triangles)",
        lambda: meshing.rectangle((1.0, 1.0), (4, 4)),
    ),
)


def write_gmsh22(mesh: Mesh, path: Path) -> None:
    """Write ``mesh`` as a gmsh 2.2 ASCII file (triangles get z = 0)."""
    import meshio

    points = mesh.points
    if mesh.dim == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    kind = "tetra" if mesh.dim == 3 else "triangle"
    ones = np.ones(mesh.n_cells, dtype=np.int64)  # one physical group / one geometrical entity
    data = meshio.Mesh(
        points,
        [(kind, mesh.cells)],
        cell_data={"gmsh:physical": [ones], "gmsh:geometrical": [ones]},
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    meshio.write(str(path), data, file_format="gmsh22", binary=False)


def edge_lengths(mesh: Mesh) -> np.ndarray:
    """Lengths of the distinct edges of ``mesh``."""
    cells = mesh.cells
    pairs = [(i, j) for i in range(cells.shape[1]) for j in range(i + 1, cells.shape[1])]
    edges = np.concatenate([cells[:, [i, j]] for i, j in pairs])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    points = mesh.points
    return np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1)


class Written(NamedTuple):
    file: str
    cells: int
    points: int
    min_edge: float
    max_edge: float
    min_dihedral_deg: float
    max_dihedral_deg: float


def regenerate(directory: Path = MESH_DIR) -> list[Written]:
    """Write every canonical mesh into ``directory``, check each reads back exactly, and
    return a summary row per file."""
    directory = Path(directory)
    rows = []
    for canonical in CANONICAL:
        mesh = canonical.make()
        mesh.validate()
        path = directory / canonical.file
        write_gmsh22(mesh, path)
        with contextlib.redirect_stdout(io.StringIO()):  # meshio prints the failed ANSYS attempt
            back = Mesh.read(path)
        if not (np.array_equal(back.points, mesh.points) and np.array_equal(back.cells, mesh.cells)):
            raise RuntimeError(f"{path}: Mesh.read does not return the points and cells that were written")
        lengths = edge_lengths(mesh)
        quality = mesh.quality()
        rows.append(
            Written(
                canonical.file,
                mesh.n_cells,
                mesh.n_points,
                float(lengths.min()),
                float(lengths.max()),
                float(np.degrees(quality.min_dihedral.min())),
                float(np.degrees(quality.max_dihedral.max())),
            )
        )
    return rows


def format_table(rows: list[Written]) -> str:
    header = ("file", "cells", "points", "min edge", "max edge", "min dihedral°", "max dihedral°")
    body = [
        (r.file, str(r.cells), str(r.points), f"{r.min_edge:.4g}", f"{r.max_edge:.4g}",
         f"{r.min_dihedral_deg:.2f}", f"{r.max_dihedral_deg:.2f}")
        for r in rows
    ]
    widths = [max(len(line[k]) for line in [header, *body]) for k in range(len(header))]

    def line(cells):
        return "  ".join(c.ljust(w) if k == 0 else c.rjust(w) for k, (c, w) in enumerate(zip(cells, widths)))

    return "\n".join([line(header), line(["-" * w for w in widths]), *map(line, body)])


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) > 1 or (argv and argv[0].startswith("-")):
        print("usage: python tools/canonical_meshes.py [output-folder]", file=sys.stderr)
        return 2
    directory = Path(argv[0]) if argv else MESH_DIR
    rows = regenerate(directory)
    print(f"wrote {len(rows)} meshes to {directory} (dihedral: smallest/largest interior angle in 2D)")
    print(format_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
