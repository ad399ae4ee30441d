"""A file's groups as Mesh.read gives them (issue 48 item 5), each from a small file written here
and compared with the cells written into it: VTK integer cell data of one component, a gmsh
entity in two physical groups (formats 4.1, 2.2 and 1), gmsh format 1's physical group per
element, and physical groups that share a name (one group, as in gmsh's .geo files)."""
import warnings

import numpy as np
import pytest

import snede

POINTS = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n"
A, B = (0, 1, 2, 3), (1, 2, 3, 4)  # the two tetrahedra, by row of POINTS


def cells_of(mesh, rows) -> set:
    """The vertex sets of ``rows`` of ``mesh.cells``."""
    return {tuple(sorted(cell)) for cell in mesh.cells[rows].tolist()}


def read(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no group is left out, nothing merged with a warning
        mesh = snede.Mesh.read(path)
    np.testing.assert_array_equal(mesh.points, np.array(POINTS.split(), dtype=float).reshape(-1, 3))
    assert cells_of(mesh, np.arange(mesh.n_cells)) == {A, B}
    return mesh


def test_vtk_integer_cell_data_of_one_component_gives_groups(tmp_path):
    """meshio gives ``SCALARS region int 1`` as an (n, 1) array."""
    mesh = read(tmp_path, "regions.vtk", "# vtk DataFile Version 4.2\nregions\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                f"POINTS 5 double\n{POINTS}CELLS 2 10\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 2\n10\n10\n"
                "CELL_DATA 2\nSCALARS region int 1\nLOOKUP_TABLE default\n7\n9\n")
    assert set(mesh.cell_groups) == {"region=7", "region=9"}
    assert cells_of(mesh, mesh.cell_groups["region=7"]) == {A}
    assert cells_of(mesh, mesh.cell_groups["region=9"]) == {B}


GMSH_4 = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
3 1 "{first}"
3 2 "{second}"
$EndPhysicalNames
$Entities
0 0 0 2
1 0 0 0 1 1 1 {entity_1} 0
2 0 0 0 1 1 1 {entity_2} 0
$EndEntities
$Nodes
1 5 1 5
3 1 0 5
1
2
3
4
5
{points}$EndNodes
$Elements
2 2 1 2
3 1 4 1
1 1 2 3 4
3 2 4 1
2 2 3 4 5
$EndElements
"""

GMSH_2 = """$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
3 1 "{first}"
3 2 "{second}"
$EndPhysicalNames
$Nodes
5
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1
5 1 1 1
$EndNodes
$Elements
{count}
{elements}$EndElements
"""


def test_a_gmsh_4_entity_in_two_physical_groups_is_in_both(tmp_path):
    """Entity 1 (tetrahedron A) is in "left" and "all", entity 2 (B) in "all"."""
    mesh = read(tmp_path, "two.msh", GMSH_4.format(first="left", second="all", entity_1="2 1 2", entity_2="1 2",
                                                   points=POINTS))
    assert set(mesh.cell_groups) == {"left", "all"}
    assert cells_of(mesh, mesh.cell_groups["left"]) == {A}
    assert cells_of(mesh, mesh.cell_groups["all"]) == {A, B}


def test_a_gmsh_2_element_in_two_physical_groups_is_written_twice_and_read_once(tmp_path):
    """gmsh writes an element once per physical group in formats 1 and 2."""
    elements = "1 4 2 1 1 1 2 3 4\n2 4 2 2 1 1 2 3 4\n3 4 2 2 2 2 3 4 5\n"
    mesh = read(tmp_path, "two.msh", GMSH_2.format(first="left", second="all", count=3, elements=elements))
    assert mesh.n_cells == 2
    assert cells_of(mesh, mesh.cell_groups["left"]) == {A}
    assert cells_of(mesh, mesh.cell_groups["all"]) == {A, B}


def gmsh_1(elements: str) -> str:
    count = len(elements.splitlines())
    return f"$NOD\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n$ENDNOD\n$ELM\n{count}\n{elements}$ENDELM\n"


def test_gmsh_1_gives_each_physical_group_the_elements_that_carry_it(tmp_path):
    """One elementary entity (1) whose two elements carry physical groups 5 and 6; format 1 has
    no names. A boundary triangle of A carries group 8."""
    mesh = read(tmp_path, "one.msh", gmsh_1("1 4 5 1 4 1 2 3 4\n2 4 6 1 4 2 3 4 5\n3 2 8 2 3 1 2 3\n"))
    assert set(mesh.cell_groups) == {"physical volume 5", "physical volume 6"}
    assert cells_of(mesh, mesh.cell_groups["physical volume 5"]) == {A}
    assert cells_of(mesh, mesh.cell_groups["physical volume 6"]) == {B}
    assert {tuple(sorted(face)) for face in mesh.boundary_groups["physical surface 8"].tolist()} == {(0, 1, 2)}


def test_a_gmsh_1_element_in_two_physical_groups_is_read_once(tmp_path):
    mesh = read(tmp_path, "two.msh", gmsh_1("1 4 1 1 4 1 2 3 4\n2 4 2 1 4 1 2 3 4\n3 4 2 2 4 2 3 4 5\n"))
    assert mesh.n_cells == 2
    assert cells_of(mesh, mesh.cell_groups["physical volume 1"]) == {A}
    assert cells_of(mesh, mesh.cell_groups["physical volume 2"]) == {A, B}


@pytest.mark.parametrize("version", [4, 2])
def test_physical_groups_that_share_a_name_are_one_group(tmp_path, version):
    """Tags 1 and 2 are both named "tissue": one group of both, as gmsh takes a name in a .geo
    file (``Physical Volume("tissue") = {2}`` after one of {1} is refused as a redefinition of
    group 1; ``+=`` adds to it)."""
    if version == 4:
        text = GMSH_4.format(first="tissue", second="tissue", entity_1="1 1", entity_2="1 2", points=POINTS)
    else:
        text = GMSH_2.format(first="tissue", second="tissue", count=2,
                             elements="1 4 2 1 1 1 2 3 4\n2 4 2 2 2 2 3 4 5\n")
    mesh = read(tmp_path, "same.msh", text)
    assert set(mesh.cell_groups) == {"tissue"}
    assert cells_of(mesh, mesh.cell_groups["tissue"]) == {A, B}


def corner_sets(points, cells) -> set:
    """Each cell as the set of its corners' coordinates, to 12 digits (a text file has 16), so
    independent of the points' order."""
    return {tuple(sorted(map(tuple, np.round(points[cell], 12).tolist()))) for cell in cells}


@pytest.mark.parametrize("binary", [0, 1], ids=["text", "binary"])
def test_gmsh_s_own_file_with_an_entity_in_two_groups(tmp_path, binary):
    """A file gmsh writes (format 4.1, text and binary: its $Entities section is read for each
    entity's physical groups), compared with gmsh's elements of each entity."""
    import gmsh

    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("two")
        gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        gmsh.model.occ.addBox(1, 0, 0, 1, 1, 1)
        gmsh.model.occ.fragment([(3, 1)], [(3, 2)])
        gmsh.model.occ.synchronize()
        volumes = sorted(gmsh.model.getEntities(3), key=lambda entity: gmsh.model.occ.getCenterOfMass(*entity)[0])
        (_, left), (_, right) = volumes
        end = [tag for _, tag in gmsh.model.getEntities(2) if abs(gmsh.model.occ.getCenterOfMass(2, tag)[0]) < 1e-9]
        gmsh.model.addPhysicalGroup(3, [left], name="left")
        gmsh.model.addPhysicalGroup(3, [left, right], name="all")
        gmsh.model.addPhysicalGroup(2, end, 7)  # no name: "physical surface 7"
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        points = np.zeros((int(tags.max()) + 1, 3))
        points[tags.astype(int)] = coords.reshape(-1, 3)

        def corners(dim, entities):
            nodes = [gmsh.model.mesh.getElements(dim, entity)[2][0].reshape(-1, dim + 1) for entity in entities]
            return corner_sets(points, np.concatenate(nodes).astype(int))

        expected = {"left": corners(3, [left]), "all": corners(3, [left, right]), "physical surface 7": corners(2, end)}
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", binary)
        path = tmp_path / "two.msh"
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    mesh = snede.Mesh.read(path)
    assert corner_sets(mesh.points, mesh.cells[mesh.cell_groups["left"]]) == expected["left"]
    assert corner_sets(mesh.points, mesh.cells[mesh.cell_groups["all"]]) == expected["all"]
    assert corner_sets(mesh.points, mesh.boundary_groups["physical surface 7"]) == expected["physical surface 7"]
    assert len(expected["left"]) < len(expected["all"]) == mesh.n_cells
