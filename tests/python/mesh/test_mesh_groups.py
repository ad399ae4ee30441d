"""Named groups (issue 34, item 2; python/snede/mesh_groups.py): read from gmsh physical groups
and VTK cell data, followed through refinement and cuts (areas and volumes are the invariants a
group keeps), and used by Body.fix / add_nodal_force / add_traction by name."""
import numpy as np
import pytest

import snede
from mesh_group_checks import body_held_and_loaded_by_groups


def gmsh_box(tmp_path, size=0.08):
    """A 1 × 0.2 × 0.2 box meshed by gmsh with the physical groups "clamped" (x = 0),
    "loaded" (x = 1) and, as volumes, "left" (x < 0.5) and "right" (x > 0.5), written as .msh."""
    import gmsh

    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("groups")
        left = gmsh.model.occ.addBox(0, 0, 0, 0.5, 0.2, 0.2)
        right = gmsh.model.occ.addBox(0.5, 0, 0, 0.5, 0.2, 0.2)
        gmsh.model.occ.fragment([(3, left)], [(3, right)])
        gmsh.model.occ.synchronize()

        def faces_at(x):
            return [tag for dim, tag in gmsh.model.getEntities(2)
                    if abs(gmsh.model.occ.getCenterOfMass(2, tag)[0] - x) < 1e-9
                    and abs(gmsh.model.occ.getMass(2, tag) - 0.04) < 1e-9]

        gmsh.model.addPhysicalGroup(2, faces_at(0.0), name="clamped")
        gmsh.model.addPhysicalGroup(2, faces_at(1.0), name="loaded")
        volumes = sorted(tag for _, tag in gmsh.model.getEntities(3))
        centre = {tag: gmsh.model.occ.getCenterOfMass(3, tag)[0] for tag in volumes}
        gmsh.model.addPhysicalGroup(3, [t for t in volumes if centre[t] < 0.5], name="left")
        gmsh.model.addPhysicalGroup(3, [t for t in volumes if centre[t] > 0.5], name="right")
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.generate(3)
        path = tmp_path / "box.msh"
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def area(mesh, faces):
    c = mesh.points[faces]
    return 0.5 * np.linalg.norm(np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]), axis=1).sum()


def volume(mesh, rows):
    c = mesh.points[mesh.cells[rows]]
    return np.abs(np.linalg.det(c[:, 1:] - c[:, :1])).sum() / 6


def check_groups(mesh):
    boundary, cells = mesh.boundary_groups, mesh.cell_groups
    assert area(mesh, boundary["clamped"]) == pytest.approx(0.04, rel=1e-12)
    assert area(mesh, boundary["loaded"]) == pytest.approx(0.04, rel=1e-12)
    assert np.all(np.isclose(mesh.points[boundary["clamped"]][..., 0], 0.0))
    assert np.all(np.isclose(mesh.points[boundary["loaded"]][..., 0], 1.0))
    assert volume(mesh, cells["left"]) == pytest.approx(0.02, rel=1e-12)
    assert volume(mesh, cells["right"]) == pytest.approx(0.02, rel=1e-12)
    # every cell in exactly one of the two (no bleeding across the interface)
    together = np.concatenate([cells["left"], cells["right"]])
    assert len(together) == mesh.n_cells == len(np.unique(together))
    centroids = mesh.points[mesh.cells].mean(axis=1)
    assert np.all(centroids[cells["left"], 0] < 0.5) and np.all(centroids[cells["right"], 0] > 0.5)


def test_gmsh_physical_groups_are_read_and_follow_refinement(tmp_path):
    mesh = snede.Mesh.read(gmsh_box(tmp_path))
    assert set(mesh.cell_groups) == {"left", "right"}
    assert set(mesh.boundary_groups) == {"clamped", "loaded", "incision"}
    assert len(mesh.boundary_groups["incision"]) == 0
    check_groups(mesh)
    cells = mesh.n_cells
    mesh.refine_uniform(2)
    assert mesh.n_cells > 4 * cells
    check_groups(mesh)
    mesh.refine_around((0.5, 0.1, 0.1), 0.02)
    check_groups(mesh)


def test_faces_a_cut_opens_form_the_incision_group(tmp_path):
    mesh = snede.Mesh.read(gmsh_box(tmp_path))
    faces = mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5) & (x[:, 2] > 0.1 - 1e-9))  # on the interface, upper half
    assert len(faces) > 4
    cut_area = area(mesh, faces)
    mesh.dissect(faces)
    incision = mesh.boundary_groups["incision"]
    assert len(incision) == 2 * len(faces)  # both lips
    assert area(mesh, incision) == pytest.approx(2 * cut_area, rel=1e-12)
    check_groups(mesh)
    mesh.refine_uniform(1)  # the lips' children stay in the incision group
    assert area(mesh, mesh.boundary_groups["incision"]) == pytest.approx(2 * cut_area, rel=1e-12)
    check_groups(mesh)


def test_a_body_is_held_and_loaded_by_group_names(tmp_path):
    mesh = snede.Mesh.read(gmsh_box(tmp_path, size=0.1))
    body = body_held_and_loaded_by_groups(mesh, 250.0)  # 250 Pa on 0.04 m²: 10 N
    assert body.displacement[:, 2].min() < 0
    body.add_nodal_force("right", (0.0, 0.0, -1.0))  # a cell group's vertices
    assert body.external_forces()[:, 2].sum() == pytest.approx(-10.0 - len(mesh.group_vertices("right")))


def test_group_errors_name_the_group_and_the_known_ones(tmp_path):
    mesh = snede.Mesh.read(gmsh_box(tmp_path, size=0.1))
    body = snede.Body(mesh, snede.LinearElastic(1e6, 0.3))
    with pytest.raises(KeyError, match="no group 'top'.*clamped, incision, left, loaded, right"):
        body.fix("top")
    with pytest.raises(KeyError, match="no boundary group 'left'"):
        body.add_traction("left", (0.0, 0.0, 1.0))
    interior = mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5))
    with pytest.raises(ValueError, match="not boundary faces of the mesh"):
        mesh.add_boundary_group("inside", interior)
    with pytest.raises(ValueError, match="'incision' is the group of the faces cuts open"):
        mesh.add_boundary_group("incision", mesh.boundary_faces()[:2])
    with pytest.raises(ValueError, match="indices into the"):
        mesh.add_cell_group("bad", [mesh.n_cells])


def test_groups_given_by_the_user_and_from_vtk_cell_data(tmp_path):
    import meshio

    box = snede.meshing.box((1.0, 1.0, 1.0), (4, 4, 4))
    region = (box.points[box.cells].mean(axis=1)[:, 2] > 0.5).astype(np.int32)
    meshio.write(tmp_path / "box.vtu", meshio.Mesh(box.points, [("tetra", box.cells)], cell_data={"region": [region]}))
    mesh = snede.Mesh.read(tmp_path / "box.vtu")
    assert set(mesh.cell_groups) == {"region=0", "region=1"}
    np.testing.assert_array_equal(mesh.cell_groups["region=1"], np.flatnonzero(region == 1))
    top = mesh.faces_where(lambda x: np.isclose(x[:, 2], 1.0), interior=False)
    mesh.add_boundary_group("top", top)  # the cell groups are kept through the re-basing
    mesh.refine_uniform(1)
    assert volume(mesh, mesh.cell_groups["region=1"]) == pytest.approx(0.5, rel=1e-12)
    assert area(mesh, mesh.boundary_groups["top"]) == pytest.approx(1.0, rel=1e-12)
    plain = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    assert plain.cell_groups == {} and plain.boundary_groups == {}


def test_groups_of_a_plane_sheet_and_of_a_surface_follow_refinement():
    sheet = snede.meshing.rectangle((2.0, 1.0), (8, 4))
    sheet.add_boundary_group("left", sheet.faces_where(lambda x: np.isclose(x[:, 0], 0.0), interior=False))
    sheet.add_cell_group("half", sheet.points[sheet.cells].mean(axis=1)[:, 0] < 1.0)
    sheet.refine_uniform(2)
    left = sheet.boundary_groups["left"]
    assert np.linalg.norm(np.diff(sheet.points[left], axis=1), axis=2).sum() == pytest.approx(1.0, rel=1e-12)
    corners = sheet.points[sheet.cells[sheet.cell_groups["half"]]]
    areas = 0.5 * np.abs(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]))
    assert areas.sum() == pytest.approx(1.0, rel=1e-12)
    surface, _ = snede.meshing.boundary_surface(snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)))
    surface.add_cell_group("top", surface.points[surface.cells].mean(axis=1)[:, 2] > 1.0 - 1e-9)
    surface.refine_uniform(2)
    corners = surface.points[surface.cells[surface.cell_groups["top"]]]
    assert 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                                axis=1).sum() == pytest.approx(1.0, rel=1e-12)


def test_a_scene_file_holds_and_loads_groups_of_its_mesh_file(tmp_path):
    from snede.app import scene_file

    path = gmsh_box(tmp_path, size=0.1)
    scene = tmp_path / "groups.toml"
    scene.write_text(f'''name = "groups"
[mesh]
file = "{path}"
scale = 0.1
[material]
name = "linear"
E = 1e6
nu = 0.3
[[hold]]
group = "clamped"
[[loads.force]]
group = "loaded"
force = [0.0, 0.0, -0.01]
''')
    built = scene_file.load(scene)
    mesh = built.body.mesh
    assert set(mesh.boundary_groups) == {"clamped", "loaded", "incision"}  # kept through the scaling
    loaded = mesh.group_vertices("loaded")
    assert np.all(np.isclose(mesh.points[loaded, 0], 0.1))
    forces = built.body.external_forces()
    np.testing.assert_allclose(forces[loaded].sum(axis=0), (0.0, 0.0, -0.01))  # the region's total
    assert np.abs(np.delete(forces, loaded, axis=0)).max() == 0
    scene.write_text(scene.read_text().replace('group = "loaded"', 'group = "top"'))
    with pytest.raises(snede.app.scene_file.SceneFileError, match="no group 'top'"):
        scene_file.load(scene)


def test_the_output_series_carries_the_groups(tmp_path):
    from snede.output import SeriesWriter, read_series

    mesh = snede.Mesh.read(gmsh_box(tmp_path, size=0.1))
    body = snede.Body(mesh, snede.LinearElastic(1e6, 0.3))
    writer = SeriesWriter(tmp_path / "groups")
    writer.write(body, 0.0)
    mesh.refine_uniform(1)
    writer.write(body, 1.0)
    for step in read_series(writer.xdmf_path):
        left = step.cell_fields["group:left"]
        assert set(np.unique(left)) == {0.0, 1.0} and 0 < left.sum() < len(left)
        clamped = step.point_fields["group:clamped"]
        assert np.all(np.isclose(step.mesh.points[clamped == 1, 0], 0.0))
    assert read_series(writer.xdmf_path)[-1].cell_fields["group:left"].sum() == len(mesh.cell_groups["left"])


def test_a_gmsh_format_1_file_gives_the_groups_too(tmp_path):
    """A gmsh format-1 file (which meshio cannot read; snede's reader of format 1 reads it): its
    physical regions, unnamed in that format, come as "physical volume <number>" and "physical
    surface <number>"."""
    import gmsh

    path = gmsh_box(tmp_path, size=0.1)
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.merge(str(path))
        gmsh.option.setNumber("Mesh.MshFileVersion", 1.0)
        gmsh.write(str(tmp_path / "box1.msh"))
    finally:
        gmsh.finalize()
    mesh = snede.Mesh.read(tmp_path / "box1.msh")
    assert len(mesh.cell_groups) == 2 and all(name.startswith("physical volume ") for name in mesh.cell_groups)
    assert all(name.startswith("physical surface ") for name in mesh.boundary_groups if name != "incision")
    assert len(mesh.boundary_groups) == 3  # two physical surfaces and "incision"
    volumes = sorted(volume(mesh, rows) for rows in mesh.cell_groups.values())
    assert volumes == pytest.approx([0.02, 0.02], rel=1e-12)
