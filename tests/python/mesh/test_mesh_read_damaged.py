"""Mesh.read of damaged files that crashed the interpreter in gmsh's reader, the fallback where
meshio fails (issue 48 item 3): a ValueError of one line naming the file and what is wrong. Each
read runs in a child interpreter, so that a crash fails the test instead of killing pytest."""
import struct
import subprocess
import sys

import numpy as np
import pytest

import snede

POINTS = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)]
TETRAHEDRA = [(1, 2, 3, 4), (2, 3, 4, 5)]  # gmsh's node numbers

GMSH_2 = """$MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
{nodes}
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 1 1 1
$EndNodes
$Elements
2
1 4 2 1 1 1 2 3 4
2 4 2 1 1 2 3 4 5
$EndElements
"""

GMSH_1 = """$NOD
{nodes}
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 1 1 1
$ENDNOD
$ELM
2
1 4 1 1 4 1 2 3 4
2 4 1 1 4 2 3 4 5
$ENDELM
"""

VTK = """# vtk DataFile Version 4.2
two tetrahedra
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 5 double
0 0 0
1 0 0
0 1 0
0 0 1
1 1 1
{cells}
4 0 1 2 3
4 1 2 3 4
CELL_TYPES 2
10
10
"""


def binary_gmsh_2(nodes: int) -> bytes:
    """The two tetrahedra as a binary gmsh 2.2 file whose $Nodes says ``nodes``."""
    head = b"$MeshFormat\n2.2 1 8\n" + struct.pack("<i", 1) + b"\n$EndMeshFormat\n"
    points = b"".join(struct.pack("<i3d", k + 1, *p) for k, p in enumerate(POINTS))
    cells = struct.pack("<3i", 4, len(TETRAHEDRA), 2) + b"".join(
        struct.pack("<7i", k + 1, 1, 1, *t) for k, t in enumerate(TETRAHEDRA))
    return (head + b"$Nodes\n%d\n" % nodes + points + b"\n$EndNodes\n$Elements\n%d\n" % len(TETRAHEDRA) + cells
            + b"\n$EndElements\n")


def read_in_child(path) -> str:
    """Mesh.read(path) in a child interpreter: the ValueError's message; the test fails if the
    child dies (a crash) or reads the file."""
    code = ("import sys, snede\ntry:\n    snede.Mesh.read(sys.argv[1])\nexcept ValueError as error:\n"
            "    print(error)\n    sys.exit(3)\n")
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 3, f"Mesh.read ended with {done.returncode}: {done.stdout}{done.stderr[-2000:]}"
    message = done.stdout.strip()
    assert "\n" not in message and message.startswith(f"{path}: ")
    return message


def test_a_gmsh_2_file_with_one_node_line_more_than_its_count(tmp_path):
    path = tmp_path / "nodes.msh"
    path.write_text(GMSH_2.format(nodes=4))
    assert read_in_child(path) == f"{path}: line 5: $Nodes announces 4, but 5 lines follow before $EndNodes"


def test_a_gmsh_1_file_with_one_node_line_more_than_its_count(tmp_path):
    path = tmp_path / "nodes.msh"
    path.write_text(GMSH_1.format(nodes=4))
    assert read_in_child(path) == f"{path}: line 2: $NOD announces 4, but 5 lines follow before $ENDNOD"


def test_a_vtk_file_whose_cells_line_lost_its_count(tmp_path):
    path = tmp_path / "cells.vtk"
    path.write_text(VTK.format(cells="CELLS 10"))
    assert read_in_child(path) == (f"{path}: line 11: 'CELLS 10' should be 'CELLS <number of cells> "
                                   "<number of values>'")


def test_a_crash_of_gmsh_s_reader_is_a_value_error(tmp_path):
    """A binary file, whose counts are not checked before gmsh's reader: the reader crashes in its
    own process."""
    path = tmp_path / "binary.msh"
    path.write_bytes(binary_gmsh_2(len(POINTS) - 1))
    message = read_in_child(path)
    assert "gmsh: its reader crashed on this file (SIGSEGV)" in message


def test_the_files_undamaged_read_as_written(tmp_path):
    expected = np.array(TETRAHEDRA) - 1
    for name, content in (("text.msh", GMSH_2.format(nodes=5)), ("format1.msh", GMSH_1.format(nodes=5)),
                          ("cells.vtk", VTK.format(cells="CELLS 2 10")), ("binary.msh", binary_gmsh_2(5))):
        path = tmp_path / name
        (path.write_bytes if isinstance(content, bytes) else path.write_text)(content)
        mesh = snede.Mesh.read(path)
        np.testing.assert_array_equal(mesh.points, POINTS)
        assert sorted(map(sorted, mesh.cells.tolist())) == expected.tolist()


def test_gmsh_s_reader_still_reads_in_its_own_process(tmp_path):
    """An OFF file with its counts on the first line, which meshio refuses and gmsh reads."""
    path = tmp_path / "square.off"
    path.write_text("OFF 4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0.5\n3 0 1 2\n3 1 3 2\n")
    mesh = snede.Mesh.read(path)
    np.testing.assert_array_equal(mesh.points, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.5]])
    assert sorted(map(sorted, mesh.cells.tolist())) == [[0, 1, 2], [1, 2, 3]]


def test_a_gmsh_2_file_with_one_element_line_more_than_its_count(tmp_path):
    """meshio reads the elements the count announces, and gmsh's reader too: one cell was lost
    without a word."""
    path = tmp_path / "elements.msh"
    path.write_text(GMSH_2.format(nodes=5).replace("$Elements\n2\n", "$Elements\n1\n"))
    with pytest.raises(ValueError) as error:
        snede.Mesh.read(path)
    assert str(error.value) == f"{path}: line 13: $Elements announces 1, but 2 lines follow before $EndElements"
