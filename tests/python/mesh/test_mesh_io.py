"""Mesh.read / Mesh.write round trips, files written by gmsh itself, and the canonical meshes
in meshes/ (tools/canonical_meshes.py, the tool that writes them)."""
import contextlib
import importlib.util
import io
import math
import re
from pathlib import Path

import meshio
import numpy as np
import pytest

import snede
from snede import meshing

ROOT = Path(__file__).resolve().parents[3]
MESHES = ROOT / "meshes"


def load_tool(path: Path):
    """A script of tools/ as a module (tools/ is not a package)."""
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


canonical_meshes = load_tool(ROOT / "tools" / "canonical_meshes.py")


def signed_volumes(points, cells):
    corners = np.asarray(points, dtype=float)[np.asarray(cells)]
    edges = corners[:, 1:, :] - corners[:, :1, :]
    return np.linalg.det(edges) / (2.0 if corners.shape[2] == 2 else 6.0)


def cell_key(points, cell):
    """A cell up to an orientation-preserving renumbering: its vertex set and orientation."""
    return frozenset(cell), bool(signed_volumes(points, [cell])[0] > 0)


def assert_same_mesh(a, b):
    """Same points (exactly), and the same cells up to orientation-preserving reordering of the
    vertices within a cell and of the rows."""
    assert a.dim == b.dim
    np.testing.assert_array_equal(a.points, b.points)
    assert a.n_cells == b.n_cells
    assert sorted(cell_key(a.points, c) for c in a.cells) == sorted(cell_key(b.points, c) for c in b.cells)
    assert {cell_key(b.points, c)[1] for c in b.cells} == {True}


def read_quietly(path):
    """Mesh.read, without meshio's stdout noise from its failed first attempt at .msh (ANSYS)."""
    with contextlib.redirect_stdout(io.StringIO()):
        return snede.Mesh.read(path)


def distorted(mesh, amount, seed=0):
    points = mesh.points.copy()
    rng = np.random.default_rng(seed)
    interior = np.setdiff1d(np.arange(mesh.n_points), np.unique(mesh.boundary_faces()))
    points[interior] += amount * rng.uniform(-1, 1, (len(interior), mesh.dim))
    return snede.Mesh(points, mesh.cells)


MAKERS = {
    "2d": lambda: distorted(meshing.rectangle((2.0, 1.0), (5, 3)), 0.05),
    "3d": lambda: distorted(meshing.box((1.0, 2.0, 1.0), (2, 3, 2)), 0.05),
}


@pytest.mark.parametrize("suffix", [".msh", ".vtu", ".vtk", ".xdmf"])
@pytest.mark.parametrize("dim", ["2d", "3d"])
def test_round_trip(tmp_path, dim, suffix):
    mesh = MAKERS[dim]()
    path = tmp_path / f"mesh{suffix}"
    mesh.write(path)
    back = read_quietly(path)
    assert back.n_reoriented == 0
    assert_same_mesh(mesh, back)
    np.testing.assert_array_equal(back.cells, mesh.cells)  # in fact identical, row by row
    back.validate()


@pytest.mark.parametrize("suffix", [".msh", ".vtu"])
def test_round_trip_of_a_dissected_mesh(tmp_path, suffix):
    """After a cut, coincident points (original and copy) survive the file: two pieces."""
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    points = mesh.points
    on_plane = np.isclose(points[:, 0], 0.5)
    faces = {tuple(sorted(np.delete(c, k))) for c in mesh.cells for k in range(4) if on_plane[np.delete(c, k)].all()}
    mesh.dissect(sorted(faces))
    assert mesh.connected_components()[0] == 2
    mesh.write(tmp_path / f"cut{suffix}")
    back = read_quietly(tmp_path / f"cut{suffix}")
    assert_same_mesh(mesh, back)
    assert back.n_points == 27 + 9 and back.connected_components()[0] == 2
    back.validate()


def test_write_creates_parent_folders(tmp_path):
    path = tmp_path / "a" / "b" / "mesh.vtu"
    meshing.rectangle((1.0, 1.0), (1, 1)).write(path)
    assert path.is_file()


def test_read_2d_gives_2d_points(tmp_path):
    mesh = meshing.rectangle((1.0, 1.0), (2, 2))
    mesh.write(tmp_path / "r.vtu")
    raw = meshio.read(tmp_path / "r.vtu")
    assert raw.points.shape[1] == 3 and np.all(raw.points[:, 2] == 0)  # meshio stores z = 0
    back = snede.Mesh.read(tmp_path / "r.vtu")
    assert back.dim == 2 and back.points.shape == (9, 2)


def test_read_gives_a_surface_mesh_for_triangles_off_the_plane(tmp_path):
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    meshio.Mesh(points, [("triangle", np.array([[0, 1, 2], [0, 2, 3]]))]).write(tmp_path / "s.vtu")
    mesh = snede.Mesh.read(tmp_path / "s.vtu")
    assert (mesh.cell_dim, mesh.space_dim, mesh.n_cells) == (2, 3, 2)
    mesh.write(tmp_path / "again.vtu")
    again = snede.Mesh.read(tmp_path / "again.vtu")
    np.testing.assert_array_equal(again.cells, mesh.cells)
    np.testing.assert_array_equal(again.points, points)


def test_read_refuses_a_file_without_cells_it_knows(tmp_path):
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    meshio.Mesh(points, [("line", np.array([[0, 1], [1, 2]]))]).write(tmp_path / "l.vtu")
    with pytest.raises(ValueError, match="no tetrahedra or triangles"):
        snede.Mesh.read(tmp_path / "l.vtu")


def test_read_takes_tetrahedra_from_a_mixed_file(tmp_path):
    """A 3D gmsh-style file also holds boundary triangles: Mesh.read keeps the tetrahedra."""
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    meshio.Mesh(
        mesh.points, [("triangle", mesh.boundary_faces()), ("tetra", mesh.cells)]
    ).write(tmp_path / "mixed.vtu")
    back = snede.Mesh.read(tmp_path / "mixed.vtu")
    assert_same_mesh(mesh, back)


def test_read_repairs_orientation(tmp_path):
    """A file with inverted cells (other conventions exist) reads with positive cells."""
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    inverted = mesh.cells[:, [1, 0, 2, 3]]
    meshio.Mesh(mesh.points, [("tetra", inverted)]).write(tmp_path / "inv.vtu")
    back = snede.Mesh.read(tmp_path / "inv.vtu")
    assert back.n_reoriented == mesh.n_cells
    assert np.all(signed_volumes(back.points, back.cells) > 0)
    assert_same_mesh(mesh, back)


# -- files written by gmsh ------------------------------------------------------------------
def gmsh_written(path, dim):
    """Mesh a unit disk (2D) or a cylinder (3D) with gmsh and let gmsh write the file; return
    gmsh's own count of triangles/tetrahedra and nodes used by them."""
    import gmsh

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("io-test")
        if dim == 2:
            gmsh.model.occ.addDisk(0, 0, 0, 1.0, 1.0)
        else:
            gmsh.model.occ.addCylinder(0, 0, 0, 0.1, 0, 0, 0.03)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3 if dim == 2 else 0.015)
        gmsh.model.mesh.generate(dim)
        gmsh.write(str(path))
        types, _, nodes = gmsh.model.mesh.getElements(dim)
        kind = 2 if dim == 2 else 4
        cells = np.concatenate([n for t, n in zip(types, nodes) if t == kind])
        return len(cells) // (dim + 1), len(np.unique(cells))
    finally:
        gmsh.finalize()


@pytest.mark.parametrize("dim", [2, 3])
def test_read_a_file_written_by_gmsh(tmp_path, dim):
    path = tmp_path / "gmsh.msh"
    n_cells, n_used = gmsh_written(path, dim)
    assert path.read_text().startswith("$MeshFormat\n4.1")
    mesh = read_quietly(path)
    mesh.validate()
    assert mesh.dim == dim and mesh.n_cells == n_cells
    assert len(np.unique(mesh.cells)) == n_used
    total = mesh.quality().volume.sum()
    exact = math.pi if dim == 2 else math.pi * 0.03**2 * 0.1
    assert 0.85 * exact < total < exact  # inscribed polygon / polyhedron


def test_write_msh_is_a_gmsh_file(tmp_path):
    path = tmp_path / "box.msh"
    meshing.box((1.0, 1.0, 1.0), (1, 1, 1)).write(path)
    assert path.read_bytes().startswith(b"$MeshFormat")


def damaged_file(kind: str, path):
    canonical = (MESHES / "cylinder_small.msh").read_bytes()
    contents = {"text": b"this is not a mesh\n", "binary": bytes(range(256)) * 8, "empty": b"",
                "truncated": canonical[: len(canonical) // 2], "header only": canonical[:40]}[kind]
    path.write_bytes(contents)
    return path


@pytest.mark.parametrize("kind", ["text", "binary", "empty", "truncated", "header only"])
def test_read_of_a_damaged_file_raises_a_value_error_naming_the_file(tmp_path, kind):
    """meshio fails on these in several ways (sys.exit, UnicodeDecodeError, IndexError,
    ReadError); Mesh.read turns each into a ValueError that names the file. (This test used to
    accept any Exception at all, so a NameError inside Mesh.read passed it.)"""
    path = damaged_file(kind, tmp_path / "damaged.msh")
    with pytest.raises(ValueError, match=re.escape(str(path))):
        read_quietly(path)


# -- canonical meshes -----------------------------------------------------------------------
def test_canonical_small_cylinder():
    path = MESHES / "cylinder_small.msh"
    assert path.read_text().startswith("$MeshFormat\n2.2 0 8\n")  # gmsh 2.2 ASCII
    mesh = read_quietly(path)
    mesh.validate()
    assert mesh.dim == 3 and mesh.n_reoriented == 0
    assert abs(mesh.n_cells / 1230 - 1) < 0.10  # thesis Table 4.2
    assert abs(mesh.n_points / 308 - 1) < 0.10
    points = mesh.points
    assert points[:, 0].min() == pytest.approx(0.0, abs=1e-12) and points[:, 0].max() == pytest.approx(0.1)
    assert np.all(np.hypot(points[:, 1], points[:, 2]) <= 0.03 * (1 + 1e-9))
    exact = math.pi * 0.03**2 * 0.1
    assert 0.9 * exact < mesh.quality().volume.sum() < exact
    assert mesh.connected_components()[0] == 1


def test_canonical_large_cylinder():
    mesh = read_quietly(MESHES / "cylinder_large.msh")
    mesh.validate()
    assert abs(mesh.n_cells / 9300 - 1) < 0.10 and abs(mesh.n_points / 1911 - 1) < 0.10
    exact = math.pi * 0.03**2 * 0.1
    assert 0.95 * exact < mesh.quality().volume.sum() < exact


@pytest.mark.parametrize(
    "name, make",
    [
        ("box_2x2x2.msh", lambda: meshing.box((1, 1, 1), (2, 2, 2))),
        ("rectangle_4x4.msh", lambda: meshing.rectangle((1, 1), (4, 4))),
    ],
)
def test_canonical_structured_meshes_are_what_the_generators_make(name, make):
    mesh = read_quietly(MESHES / name)
    expected = make()
    np.testing.assert_array_equal(mesh.points, expected.points)
    np.testing.assert_array_equal(mesh.cells, expected.cells)


def test_regenerate_canonical_meshes(tmp_path, capsys):
    assert canonical_meshes.MESH_DIR == MESHES
    assert canonical_meshes.main([str(tmp_path)]) == 0
    table = capsys.readouterr().out
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == sorted(c.file for c in canonical_meshes.CANONICAL)
    for name in ("box_2x2x2.msh", "rectangle_4x4.msh"):
        assert (tmp_path / name).read_bytes() == (MESHES / name).read_bytes(), name
    lines = {line.split()[0]: line.split() for line in table.splitlines() if line.endswith(tuple("0123456789"))}
    # file, cells, points, min/max edge, min/max dihedral (degrees): box 2x2x2 of edge 1/2.
    box = lines["box_2x2x2.msh"]
    assert box[1:3] == ["48", "27"]
    assert float(box[3]) == pytest.approx(0.5) and float(box[4]) == pytest.approx(math.sqrt(3) / 2, rel=1e-3)
    assert float(box[5]) == pytest.approx(45.0) and float(box[6]) == pytest.approx(90.0)
    rect = lines["rectangle_4x4.msh"]
    assert rect[1:3] == ["32", "25"]
    assert float(rect[3]) == pytest.approx(0.25) and float(rect[4]) == pytest.approx(math.sqrt(2) / 4, rel=1e-3)
    for name, (cells, points) in {"cylinder_small.msh": (1230, 308), "cylinder_large.msh": (9300, 1911)}.items():
        mesh = read_quietly(tmp_path / name)
        assert lines[name][1:3] == [str(mesh.n_cells), str(mesh.n_points)]
        assert abs(mesh.n_cells / cells - 1) < 0.10 and abs(mesh.n_points / points - 1) < 0.10


def test_regenerate_usage_error(capsys):
    assert canonical_meshes.main(["a", "b"]) == 2
    assert "usage" in capsys.readouterr().err
