"""Mesh.read of every format users bring (issue 34 item 1): gmsh's .msh 1, 2 and 4 written by gmsh
itself (format 1, SOFA's liver.msh among them, meshio cannot read), VTK legacy (unstructured grids
and POLYDATA surfaces) and VTU, Medit, and the surface formats STL, OBJ, OFF and PLY written by
meshio; each compared with the mesh written. Errors name the file and the reason, and no file
makes the interpreter exit (meshio calls sys.exit)."""
import re

import meshio
import numpy as np
import pytest
from closed_surfaces import assert_same_cells, icosphere
from expected_errors import refused

import snede


def read(path):
    mesh = snede.Mesh.read(path)
    mesh.validate()
    return mesh


# -- gmsh's own files -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def gmsh_files(tmp_path_factory):
    """A ball meshed by gmsh and written by gmsh in formats 1, 2.2 and 4.1, text and binary; with
    gmsh's own points and tetrahedra."""
    import gmsh

    folder = tmp_path_factory.mktemp("gmsh")
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("ball")
        gmsh.model.occ.addSphere(0, 0, 0, 1.0)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, _, nodes = gmsh.model.mesh.getElements(3)
        points = np.zeros((int(tags.max()) + 1, 3))
        points[tags.astype(int)] = coords.reshape(-1, 3)
        expected = points, nodes[0].astype(int).reshape(-1, 4)
        files = {}
        for version in (1.0, 2.2, 4.1):
            for binary in (0, 1):
                gmsh.option.setNumber("Mesh.MshFileVersion", version)
                gmsh.option.setNumber("Mesh.Binary", binary)
                files[version, binary] = folder / f"ball-{version}-{'binary' if binary else 'text'}.msh"
                gmsh.write(str(files[version, binary]))
    finally:
        gmsh.finalize()
    return files, expected


@pytest.mark.parametrize("binary", [0, 1], ids=["text", "binary"])
@pytest.mark.parametrize("version", [1.0, 2.2, 4.1])
def test_gmsh_files_of_every_version_read_as_gmsh_wrote_them(gmsh_files, version, binary):
    files, expected = gmsh_files
    mesh = read(files[version, binary])
    assert mesh.cell_dim == 3
    assert_same_cells(mesh.points, mesh.cells, *expected, atol=0 if binary else 1e-15)  # text: 16 digits


def test_gmsh_format_1_is_what_meshio_cannot_read(gmsh_files):
    """The files snede's reader of format 1 is for: SOFA's liver.msh is one ($NOD ... $ELM)."""
    files, _ = gmsh_files
    assert files[1.0, 0].read_text().startswith("$NOD\n")
    with pytest.raises(Exception):
        meshio.gmsh.read(str(files[1.0, 0]))


LIVER_LIKE = """$NOD
5
2 0 0 0
3 1 0 0
5 0 1 0
7 0 0 1
11 1 1 1
$ENDNOD
$ELM
3
1 4 1 1 4 2 3 5 7
2 4 1 1 4 3 5 7 11
3 2 1 1 3 2 3 5
$ENDELM
"""


def test_a_format_1_file_like_sofas_liver_with_gaps_in_its_node_numbers(tmp_path):
    """SOFA's liver.msh layout (element lines: number, type 4, physical, elementary, 4 nodes); the
    node numbers here skip some, so they cannot be taken as row numbers."""
    path = tmp_path / "liver-like.msh"
    path.write_text(LIVER_LIKE)
    mesh = read(path)
    points = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]
    np.testing.assert_array_equal(mesh.points, points)
    assert_same_cells(mesh.points, mesh.cells, points, [[0, 1, 2, 3], [1, 2, 3, 4]])


# -- files meshio writes ----------------------------------------------------------------------------
def ball():
    """A small tetrahedral ball and its boundary, made by snede (gmsh) and written by meshio."""
    mesh = snede.meshing.ellipsoid((1.0, 1.0, 1.0), h=0.6, seed=1)
    return mesh.points, mesh.cells


VOLUME_FORMATS = [("vtk", {"binary": False}), ("vtk", {"binary": True}), ("vtu", {}), ("mesh", {}), ("xdmf", {})]


@pytest.mark.parametrize("suffix, options", VOLUME_FORMATS, ids=["vtk-text", "vtk-binary", "vtu", "medit", "xdmf"])
def test_volume_formats_round_trip(tmp_path, suffix, options):
    points, cells = ball()
    path = tmp_path / f"ball.{suffix}"
    meshio.write_points_cells(path, points, [("tetra", cells)], **options)
    mesh = read(path)
    np.testing.assert_array_equal(mesh.points, points)
    assert_same_cells(mesh.points, mesh.cells, points, cells)


SURFACE_FORMATS = [("stl", {"binary": False}), ("stl", {"binary": True}), ("obj", {}), ("off", {}),
                   ("ply", {"binary": False}), ("ply", {"binary": True}), ("vtk", {}), ("mesh", {})]


@pytest.mark.parametrize("suffix, options", SURFACE_FORMATS,
                         ids=["stl-text", "stl-binary", "obj", "off", "ply-text", "ply-binary", "vtk", "medit"])
def test_surface_formats_give_a_surface_mesh(tmp_path, suffix, options):
    points, triangles = icosphere(2)
    path = tmp_path / f"sphere.{suffix}"
    meshio.write_points_cells(path, points, [("triangle", triangles)], **options)
    mesh = read(path)
    assert mesh.is_surface and (mesh.cell_dim, mesh.dim) == (2, 3)
    assert len(mesh.boundary_faces()) == 0  # still closed
    if suffix == "stl" and options["binary"]:
        points = points.astype(np.float32).astype(np.float64)  # binary STL stores float32
    assert_same_cells(mesh.points, mesh.cells, points, triangles)


def test_quads_and_polygons_are_split_into_triangles(tmp_path):
    """An OBJ cube of six quads (and a hexagon-capped prism side): each polygon becomes a fan."""
    path = tmp_path / "cube.obj"
    corners = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    path.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join(f"f {a} {b} {c} {d}\n"
                                                                                 for a, b, c, d in faces))
    mesh = read(path)
    assert mesh.n_cells == 12 and len(mesh.boundary_faces()) == 0
    assert mesh.quality().volume.sum() == pytest.approx(6.0)  # areas: six unit squares
    hexagon = tmp_path / "hexagon.obj"
    angles = np.arange(6) * np.pi / 3
    hexagon.write_text("".join(f"v {np.cos(a)} {np.sin(a)} 0\n" for a in angles) + "f 1 2 3 4 5 6\n")
    flat = read(hexagon)
    assert flat.dim == 2 and flat.n_cells == 4
    assert flat.quality().volume.sum() == pytest.approx(3 * np.sqrt(3) / 2)


def test_triangles_with_a_repeated_vertex_are_left_out_with_a_warning(tmp_path):
    """STL files hold triangles whose corners coincide (meshio merges them into one point)."""
    points, triangles = icosphere(1)
    path = tmp_path / "with-slivers.stl"
    corners = np.concatenate([points[triangles], points[[[0, 0, 1]]]]).reshape(-1, 3)  # the last: corners 0, 0, 1
    with np.errstate(invalid="ignore"):  # meshio's normal of the triangle without area
        meshio.write_points_cells(path, corners, [("triangle", np.arange(len(corners)).reshape(-1, 3))], binary=False)
    with pytest.warns(UserWarning, match=re.escape(f"{path}: 1 triangles with a repeated vertex (no area) left out")):
        mesh = snede.Mesh.read(path)
    assert_same_cells(mesh.points, mesh.cells, points, triangles)


# -- VTK legacy POLYDATA (neither meshio nor gmsh reads it) -----------------------------------------------
SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 1], [2, 1, 1]], dtype=float)
#: a quad [0 1 2 3], a triangle [1 4 2] and a strip [4 5 2] (one triangle); a line and a vertex
SQUARE_TRIANGLES = [[0, 1, 2], [0, 2, 3], [1, 4, 2], [4, 5, 2]]


def polydata_text(version="3.0"):
    points = "\n".join(" ".join(f"{x:g}" for x in p) for p in SQUARE)
    if version == "5.1":
        cells = ("POLYGONS 3 7\nOFFSETS vtktypeint64\n0 4 7\nCONNECTIVITY vtktypeint64\n0 1 2 3 1 4 2\n"
                 "TRIANGLE_STRIPS 2 3\nOFFSETS vtktypeint64\n0 3\nCONNECTIVITY vtktypeint64\n4 5 2\n")
    else:
        cells = "VERTICES 1 2\n1 0\nLINES 1 3\n2 0 1\nPOLYGONS 2 9\n4 0 1 2 3\n3 1 4 2\nTRIANGLE_STRIPS 1 4\n3 4 5 2\n"
    metadata = "METADATA\nINFORMATION 0\n\n" if version == "5.1" else ""
    return (f"# vtk DataFile Version {version}\nsquare\nASCII\nDATASET POLYDATA\nPOINTS 6 float\n{points}\n{metadata}"
            f"{cells}POINT_DATA 6\nSCALARS s float 1\nLOOKUP_TABLE default\n0 1 2 3 4 5\n")


@pytest.mark.parametrize("version", ["3.0", "5.1"])
def test_polydata_text(tmp_path, version):
    path = tmp_path / "square.vtk"
    path.write_text(polydata_text(version))
    mesh = read(path)
    assert mesh.is_surface
    np.testing.assert_array_equal(mesh.points, SQUARE)
    assert_same_cells(mesh.points, mesh.cells, SQUARE, SQUARE_TRIANGLES)


def test_polydata_binary(tmp_path):
    """Binary legacy VTK is big-endian, each array on the line after its keyword (like SOFA's liver.vtk)."""
    cells = np.array([4, 0, 1, 2, 3, 3, 1, 4, 2], dtype=">i4")
    path = tmp_path / "square.vtk"
    path.write_bytes(b"# vtk DataFile Version 3.0\nsquare\nBINARY\nDATASET POLYDATA\nPOINTS 6 double\n"
                     + SQUARE.astype(">f8").tobytes() + b"\nPOLYGONS 2 9\n" + cells.tobytes()
                     + b"\nTRIANGLE_STRIPS 1 4\n" + np.array([3, 4, 5, 2], dtype=">i4").tobytes() + b"\n")
    mesh = read(path)
    np.testing.assert_array_equal(mesh.points, SQUARE)
    assert_same_cells(mesh.points, mesh.cells, SQUARE, SQUARE_TRIANGLES)


@pytest.mark.parametrize("binary", [False, True], ids=["text", "binary"])
def test_polydata_of_triangles_only(tmp_path, binary):
    points, triangles = icosphere(2)
    cells = np.c_[np.full(len(triangles), 3), triangles]
    if binary:
        arrays = (points.astype(">f4").tobytes(), cells.astype(">i4").tobytes())
        points = points.astype(np.float32).astype(np.float64)
    else:
        arrays = ("\n".join(" ".join(map(repr, p)) for p in points.tolist()).encode(),
                  "\n".join(" ".join(map(str, c)) for c in cells.tolist()).encode())
    path = tmp_path / "sphere.vtk"
    path.write_bytes(b"# vtk DataFile Version 2.0\nsphere\n" + (b"BINARY" if binary else b"ASCII")
                     + f"\nDATASET POLYDATA\nPOINTS {len(points)} float\n".encode() + arrays[0]
                     + f"\nPOLYGONS {len(cells)} {cells.size}\n".encode() + arrays[1] + b"\n")
    mesh = read(path)
    np.testing.assert_array_equal(mesh.points, points)
    assert_same_cells(mesh.points, mesh.cells, points, triangles)


def test_an_xml_file_named_vtk_reads_as_vtu(tmp_path):
    """SOFA's Bunny.vtk is a VTU file under a .vtk name."""
    points, cells = ball()
    meshio.write_points_cells(tmp_path / "ball.vtu", points, [("tetra", cells)])
    (tmp_path / "ball.vtk").write_bytes((tmp_path / "ball.vtu").read_bytes())
    mesh = read(tmp_path / "ball.vtk")
    assert_same_cells(mesh.points, mesh.cells, points, cells)


# -- errors ---------------------------------------------------------------------------------------
def read_refused(path, *fragments, error=ValueError):
    """Mesh.read(path) raises ``error`` whose message names the file and holds every fragment."""
    return refused(lambda: snede.Mesh.read(path), str(path), *fragments, error=error)


def test_a_missing_file():
    read_refused("/no/such/mesh.msh", "no mesh file", error=FileNotFoundError)


@pytest.mark.parametrize("suffix", [".msh", ".vtk", ".stl", ".obj", ".off", ".ply", ".mesh", ".vtu"])
def test_a_file_no_reader_takes_says_why_each_failed_and_does_not_exit(tmp_path, suffix, capfd):
    """meshio calls sys.exit on some of these (it is caught); nothing is printed. (Not "$NOD": a
    gmsh format 1 file goes to snede's reader of that format alone, test_mesh_read_damaged.py.)"""
    path = tmp_path / f"nonsense{suffix}"
    path.write_text("$Nodes\n3\n1 0 0\n")
    message = read_refused(path, "could not read this file as a mesh", "meshio: ")
    assert ("gmsh: " in message) == (suffix in (".msh", ".vtk", ".stl", ".mesh", ".off"))
    assert capfd.readouterr() == ("", "")


@pytest.mark.parametrize("suffix", [".msh", ".vtu", ".ply"])
def test_where_meshio_exits_mesh_read_raises_with_meshios_reason(tmp_path, suffix):
    path = tmp_path / f"nonsense{suffix}"
    path.write_text("$Nodes\n3\n1 0 0\n")
    with pytest.raises(SystemExit):
        meshio.read(path)
    read_refused(path, "meshio: ")


def test_an_unknown_suffix(tmp_path):
    path = tmp_path / "mesh.xyz"
    path.write_text("1 2 3\n")
    read_refused(path, "meshio: ", "xyz")


def test_a_damaged_polydata_file_says_where_its_cells_go_wrong(tmp_path):
    path = tmp_path / "damaged.vtk"
    path.write_text(polydata_text().replace("4 0 1 2 3", "9 0 1 2 3"))
    read_refused(path, "VTK POLYDATA: the cells' sizes run past the section's 9 values: the file is damaged")


def test_polydata_without_points(tmp_path):
    path = tmp_path / "empty.vtk"
    path.write_text("# vtk DataFile Version 3.0\nnothing\nASCII\nDATASET POLYDATA\nPOLYGONS 1 4\n3 0 1 2\n")
    read_refused(path, "VTK POLYDATA: no POINTS section")


def test_a_file_with_neither_tetrahedra_nor_triangles(tmp_path):
    path = tmp_path / "lines.vtk"
    meshio.write_points_cells(path, SQUARE, [("line", np.array([[0, 1], [1, 2]]))])
    read_refused(path, "no tetrahedra or triangles (cell types: ['line'])")


def test_a_non_manifold_surface_is_refused_naming_the_file(tmp_path):
    """Three triangles on one edge (SOFA's dragon.stl has such edges)."""
    path = tmp_path / "fin.stl"
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], dtype=float)
    meshio.write_points_cells(path, points, [("triangle", np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]]))], binary=False)
    message = read_refused(path, "face +<0 1> is shared by 3 cells", "not a manifold mesh")
    assert message.startswith(f"{path}: ")


def test_bad_cells_are_refused_naming_the_file(tmp_path):
    path = tmp_path / "flat.vtu"
    meshio.write_points_cells(path, SQUARE, [("tetra", np.array([[0, 1, 2, 3]]))])  # four points in a plane
    read_refused(path, "volume")
