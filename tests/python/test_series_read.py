"""Reading an XDMF series back (issue 14, item 8): ``snede.output.read_series`` gives every step
with the mesh it had (the series changes mesh in the middle), and ``Mesh.read`` of a series
gives the mesh of its last step. meshio cannot read these files (a temporal collection whose
steps point to different meshes), so before read_series ``Mesh.read`` raised a ValueError."""
import re

import h5py
import numpy as np
import pytest

import snede
from snede import meshing
from snede.output import SeriesStep, SeriesWriter, read_series


class Recorder:
    """A SeriesWriter that keeps copies of what each step wrote, to compare with the file."""

    def __init__(self, base):
        self.writer = SeriesWriter(base)
        self.written = []

    @property
    def xdmf(self):
        return self.writer.xdmf_path

    def write(self, body, time, point_fields=None, **cell_fields):
        mesh = body.mesh
        inverted = np.zeros(mesh.n_cells)
        inverted[body.inverted_elements(body.displacement)] = 1.0
        quality = mesh.quality()
        self.written.append(dict(
            time=time, dim=mesh.dim, points=mesh.points.copy(), cells=mesh.cells.copy(),
            point_fields={"displacement": body.displacement.copy(),
                          **{k: np.array(v, dtype=float) for k, v in (point_fields or {}).items()}},
            cell_fields={"aspect_ratio": quality.aspect_ratio.copy(), "min_angle": quality.min_dihedral.copy(),
                         "inverted": inverted, **{k: np.array(v, dtype=float) for k, v in cell_fields.items()}}))
        self.writer.write(body, time, point_fields=point_fields, **cell_fields)


def assert_steps_equal(steps, written):
    assert [s.time for s in steps] == [w["time"] for w in written]
    for step, w in zip(steps, written):
        assert isinstance(step, SeriesStep)
        assert step.mesh.dim == w["dim"] and step.mesh.n_reoriented == 0
        np.testing.assert_array_equal(step.mesh.points, w["points"])
        np.testing.assert_array_equal(step.mesh.cells, w["cells"])
        assert step.point_fields.keys() == w["point_fields"].keys()
        assert step.cell_fields.keys() == w["cell_fields"].keys()
        for name, values in w["point_fields"].items():
            np.testing.assert_array_equal(step.point_fields[name], values, err_msg=name)
        for name, values in w["cell_fields"].items():
            np.testing.assert_array_equal(step.cell_fields[name], values, err_msg=name)
        np.testing.assert_array_equal(step.displacement, w["point_fields"]["displacement"])
        assert step.displacement.shape == (step.mesh.n_points, w["dim"])


def assert_same_mesh(a, b):
    assert (a.dim, a.cell_dim) == (b.dim, b.cell_dim)
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.cells, b.cells)


def sheet_series(tmp_path):
    """A 2D sheet: two steps on one mesh, a cut through the middle, a refinement, and a vertex
    added and removed again (a dead row in the points)."""
    mesh = meshing.rectangle((2.0, 1.0), (4, 2))
    body = snede.Body(mesh, snede.LinearElastic(E=1e3, nu=0.3), thickness=0.01)
    series = Recorder(tmp_path / "sheet")
    body.displacement = 0.01 * mesh.points**2
    series.write(body, 0.0, point_fields={"height": mesh.points[:, 1]}, label=np.arange(mesh.n_cells))
    body.displacement = 0.02 * mesh.points**2
    series.write(body, 0.5, point_fields={"height": mesh.points[:, 1]}, label=np.arange(mesh.n_cells))
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 1.0)))
    series.write(body, 1.25)
    assert mesh.refine_around([0.5, 0.5], 0.3) > 0
    v = mesh.add_vertex([0, 1], [0.5, 0.5])
    mesh.remove_vertex(v)
    assert mesh.n_live_points == mesh.n_points - 1
    body.displacement = body.displacement + 1e-3
    series.write(body, 2.0)
    assert (series.writer.n_steps, series.writer.n_meshes) == (4, 3)
    return series


def block_series(tmp_path):
    """A 3D block: two steps on one mesh, cut through at x = 0.5, refined."""
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = snede.Body(mesh, snede.LinearElastic(E=1e3, nu=0.3))
    series = Recorder(tmp_path / "out" / "block")
    for time in (0.0, 0.5):
        body.displacement = time * 0.01 * mesh.points**2
        series.write(body, time, point_fields={"x": mesh.points[:, 0]})
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5)))
    body.displacement = 0.01 * np.sin(mesh.points)
    series.write(body, 1.0, point_fields={"x": mesh.points[:, 0]}, piece=mesh.connected_components()[1])
    mesh.refine_uniform(1)
    series.write(body, 3.5, point_fields={"x": mesh.points[:, 0]}, piece=mesh.connected_components()[1])
    assert (series.writer.n_steps, series.writer.n_meshes) == (4, 3)
    return series


def test_a_2d_series_with_mesh_changes_reads_back_exactly(tmp_path):
    series = sheet_series(tmp_path)
    steps = read_series(series.xdmf)
    assert_steps_equal(steps, series.written)
    assert all(s.mesh.dim == 2 and s.mesh.cell_dim == 2 for s in steps)  # not a surface at z = 0
    assert steps[0].mesh is steps[1].mesh  # one mesh, one Mesh object
    assert len({id(s.mesh) for s in steps}) == 3
    assert steps[2].mesh.connected_components()[0] == 2  # the cut survives (coincident points)
    assert steps[3].mesh.n_points == steps[3].mesh.n_live_points  # the dead row reads as an unused point
    for step in steps:
        step.mesh.validate()


def test_a_3d_series_with_mesh_changes_reads_back_exactly(tmp_path):
    series = block_series(tmp_path)
    steps = read_series(str(series.xdmf))  # a str works too
    assert_steps_equal(steps, series.written)
    assert steps[0].mesh is steps[1].mesh and steps[2].mesh is not steps[3].mesh
    assert steps[3].mesh.n_cells == 2 * steps[2].mesh.n_cells == 96
    assert steps[3].mesh.connected_components()[0] == 2


@pytest.mark.parametrize("make", [sheet_series, block_series])
def test_mesh_read_of_a_series_gives_the_last_mesh(tmp_path, make):
    series = make(tmp_path)
    mesh = snede.Mesh.read(series.xdmf)
    last = series.written[-1]
    assert mesh.dim == last["dim"]
    np.testing.assert_array_equal(mesh.points, last["points"])
    np.testing.assert_array_equal(mesh.cells, last["cells"])
    assert_same_mesh(mesh, read_series(series.xdmf)[-1].mesh)


def test_a_surface_series_reads_back_as_a_surface(tmp_path):
    surface, _ = meshing.boundary_surface(meshing.box((1.0, 2.0, 3.0), (1, 2, 2)))
    writer = SeriesWriter(tmp_path / "surface")
    u = 0.1 * surface.points[:, ::-1]
    writer.write_mesh(surface, 0.0, displacement=u)
    (step,) = read_series(writer.xdmf_path)
    assert step.mesh.is_surface and (step.mesh.cell_dim, step.mesh.space_dim) == (2, 3)
    assert_same_mesh(step.mesh, surface)
    np.testing.assert_array_equal(step.displacement, u)
    assert set(step.cell_fields) == {"aspect_ratio", "min_angle"}
    assert_same_mesh(snede.Mesh.read(writer.xdmf_path), surface)


def test_a_series_being_written_reads_as_the_steps_so_far(tmp_path):
    mesh = meshing.rectangle((1.0, 1.0), (2, 2))
    writer = SeriesWriter(tmp_path / "live")
    assert read_series(writer.xdmf_path) == []  # created, nothing written yet
    with pytest.raises(ValueError, match="no steps"):
        snede.Mesh.read(writer.xdmf_path)
    writer.write_mesh(mesh, 0.0)
    assert [s.time for s in read_series(writer.xdmf_path)] == [0.0]
    writer.write_mesh(mesh, 1.0)  # the reader closed the .h5: the writer goes on
    steps = read_series(writer.xdmf_path)
    assert [s.time for s in steps] == [0.0, 1.0] and steps[0].mesh is steps[1].mesh
    np.testing.assert_array_equal(steps[1].displacement, np.zeros((9, 2)))


def test_a_single_mesh_xdmf_is_still_read_by_meshio(tmp_path):
    """Mesh.write's .xdmf (one grid, no time series) still goes through meshio; read_series
    says it is not a series."""
    mesh = meshing.rectangle((1.0, 1.0), (2, 2))
    mesh.write(tmp_path / "one.xdmf")
    assert_same_mesh(snede.Mesh.read(tmp_path / "one.xdmf"), mesh)
    with pytest.raises(ValueError, match="not a series written by SeriesWriter"):
        read_series(tmp_path / "one.xdmf")


# -- broken files -------------------------------------------------------------------------------
def small_series(tmp_path):
    mesh = meshing.rectangle((1.0, 1.0), (2, 2))
    writer = SeriesWriter(tmp_path / "small")
    writer.write_mesh(mesh, 0.0)
    mesh.refine_uniform(1)
    writer.write_mesh(mesh, 1.0)
    return writer


def named(path, what):
    return re.escape(str(path)) + ".*" + what


def test_a_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match=re.escape(str(tmp_path / "none.xdmf"))):
        read_series(tmp_path / "none.xdmf")


@pytest.mark.parametrize("content", [b"\x89HDF\r\n\x1a\n\x00\x00garbage", b"", b"this is not a series\n"])
def test_a_garbage_file(tmp_path, content):
    path = tmp_path / "garbage.xdmf"
    path.write_bytes(content)
    with pytest.raises(ValueError, match=named(path, "does not parse")):
        read_series(path)
    with pytest.raises(ValueError, match=re.escape(str(path))):
        snede.Mesh.read(path)


def test_xml_that_is_not_xdmf(tmp_path):
    path = tmp_path / "page.xdmf"
    path.write_text("<html><body>hello</body></html>\n")
    with pytest.raises(ValueError, match=named(path, "not an XDMF file.*<html>")):
        read_series(path)


def test_a_truncated_file(tmp_path):
    """Cut short, as a reader may find it while the writer rewrites it."""
    writer = small_series(tmp_path)
    text = writer.xdmf_path.read_text()
    writer.xdmf_path.write_text(text[: len(text) * 2 // 3])
    with pytest.raises(ValueError, match=named(writer.xdmf_path, "does not parse")):
        read_series(writer.xdmf_path)
    with pytest.raises(ValueError, match=named(writer.xdmf_path, "does not parse")):
        snede.Mesh.read(writer.xdmf_path)


def test_a_missing_h5(tmp_path):
    writer = small_series(tmp_path)
    writer.h5_path.unlink()
    with pytest.raises(ValueError, match=named(writer.xdmf_path, "data file .*small.h5 is missing")):
        read_series(writer.xdmf_path)
    with pytest.raises(ValueError, match="small.h5 is missing"):
        snede.Mesh.read(writer.xdmf_path)


def test_an_h5_that_is_not_hdf5(tmp_path):
    writer = small_series(tmp_path)
    writer.h5_path.write_text("not HDF5")
    with pytest.raises(ValueError, match=named(writer.xdmf_path, "cannot read its data file")):
        read_series(writer.xdmf_path)


@pytest.mark.parametrize("dataset", ["/step/1/displacement", "/mesh/1/cells", "/step/0/aspect_ratio"])
def test_a_dataset_missing_from_the_h5(tmp_path, dataset):
    writer = small_series(tmp_path)
    with h5py.File(writer.h5_path, "r+") as f:
        del f[dataset]
    with pytest.raises(ValueError, match=named(writer.xdmf_path, re.escape(dataset) + ", which is not in .*small.h5")):
        read_series(writer.xdmf_path)


def test_a_dataset_of_the_wrong_shape(tmp_path):
    writer = small_series(tmp_path)
    with h5py.File(writer.h5_path, "r+") as f:
        del f["/step/1/min_angle"]
        f["/step/1/min_angle"] = np.zeros(3)
    with pytest.raises(ValueError, match=named(writer.xdmf_path, "min_angle has shape \\(3,\\)")):
        read_series(writer.xdmf_path)


def test_times_read_back_bit_for_bit(tmp_path):
    # The XDMF holds the times as text: written with 17 significant digits (before: 6, so
    # 0.123456789 came back as 0.123457).
    times = [0.0, 0.123456789, 1234567.125, 1e-300, 2.0 / 3.0]
    mesh = meshing.rectangle((1.0, 1.0), (2, 2))
    writer = SeriesWriter(tmp_path / "times")
    for t in times:
        writer.write_mesh(mesh, time=t)
    assert [step.time for step in read_series(writer.xdmf_path)] == times


# -- field names and dimensions (issue 38, item 6) ----------------------------------------------
def labelled_series(tmp_path):
    """A series with one step, its cell field ``label`` and point field ``height``."""
    mesh = meshing.rectangle((1.0, 1.0), (2, 2))
    writer = SeriesWriter(tmp_path / "names")
    writer.write_mesh(mesh, 0.0, point_fields={"height": mesh.points[:, 1]}, label=np.arange(mesh.n_cells))
    return mesh, writer


@pytest.mark.parametrize("name, shown, why", [
    ("a\0b", r"a\x00b", r"control character U\+0000"),  # HDF5 cut the dataset name, the XML did not parse
    ("two\nlines", r"two\x0alines", r"control character U\+000A"),  # read back with a space for the newline
    ("tab\tstop", r"tab\x09stop", r"control character U\+0009"),
    ("return\r", r"return\x0d", r"control character U\+000D"),  # the XML reads it as a newline
    ("bell\x07", r"bell\x07", r"control character U\+0007"),  # not an XML character: the XML did not parse
    ("odd\ufffe", r"odd\ufffe", r"U\+FFFE, which is not an XML character"),
    ("trailing ", "trailing ", "ends with a space"),  # the path to its dataset lost the space
    ("lone\ud800", r"lone\ud800", "not UTF-8"),  # a surrogate: Python holds it, UTF-8 cannot
])
@pytest.mark.parametrize("center", ["cell", "point"])
def test_a_field_name_that_would_not_read_back_is_refused_before_anything_is_written(tmp_path, name, shown, why,
                                                                                     center):
    mesh, writer = labelled_series(tmp_path)
    values = np.zeros(mesh.n_cells if center == "cell" else mesh.n_points)
    fields = {name: values} if center == "cell" else {"point_fields": {name: values}}
    with pytest.raises(ValueError, match=f"field name '{re.escape(shown)}' is not usable.*{why}"):
        writer.write_mesh(mesh, 1.0, **fields)
    assert writer.n_steps == 1
    with h5py.File(writer.h5_path, "r") as f:
        assert list(f["/step"]) == ["0"]  # nothing of the refused step in the file
    (step,) = read_series(writer.xdmf_path)  # the earlier step still reads
    assert set(step.cell_fields) == {"aspect_ratio", "min_angle", "label"}
    assert set(step.point_fields) == {"displacement", "height"}
    writer.write_mesh(mesh, 1.0)
    assert [s.time for s in read_series(writer.xdmf_path)] == [0.0, 1.0]  # and the writer goes on


@pytest.mark.parametrize("name", ["é ü 中", "😀", "E<1&2 'x\"", "a\x7fb", "a\x85b", "ideographic space\u3000",
                                  "\u2028line separator", "a:∕b", " inner  spaces"])
def test_field_names_that_xml_and_hdf5_can_hold_read_back_exactly(tmp_path, name):
    mesh, writer = labelled_series(tmp_path)
    writer.write_mesh(mesh, 1.0, point_fields={name: mesh.points[:, 0]}, **{name + " per cell": np.arange(mesh.n_cells)})
    step = read_series(writer.xdmf_path)[1]
    np.testing.assert_array_equal(step.point_fields[name], mesh.points[:, 0])
    np.testing.assert_array_equal(step.cell_fields[name + " per cell"], np.arange(mesh.n_cells))


def flat_surface(mesh2d):
    """The triangles of a 2D mesh as a surface in 3D lying in z = 0."""
    return snede.Mesh(np.column_stack([mesh2d.points, np.zeros(mesh2d.n_points)]), mesh2d.cells)


def test_each_step_keeps_its_dimension(tmp_path):
    """The file pads 2D with z = 0; a 2D step followed by a surface step read back as two
    surfaces, and a surface lying in z = 0 as a 2D mesh."""
    sheet = meshing.rectangle((2.0, 1.0), (4, 2))
    surface, _ = meshing.boundary_surface(meshing.box((1.0, 2.0, 3.0), (1, 2, 2)))
    flat = flat_surface(sheet)
    meshes = [sheet, surface, flat, sheet]
    writer = SeriesWriter(tmp_path / "mixed")
    for time, mesh in enumerate(meshes):
        writer.write_mesh(mesh, float(time), displacement=0.01 * mesh.points)
    steps = read_series(writer.xdmf_path)
    assert [s.mesh.dim for s in steps] == [2, 3, 3, 2]
    for step, mesh in zip(steps, meshes):
        assert_same_mesh(step.mesh, mesh)
        np.testing.assert_array_equal(step.displacement, 0.01 * mesh.points)
    assert_same_mesh(snede.Mesh.read(writer.xdmf_path), sheet)


def test_a_flat_surface_series_reads_back_as_a_surface(tmp_path):
    flat = flat_surface(meshing.rectangle((1.0, 1.0), (2, 2)))
    writer = SeriesWriter(tmp_path / "flat")
    writer.write_mesh(flat, 0.0)
    (step,) = read_series(writer.xdmf_path)
    assert step.mesh.is_surface and step.displacement.shape == (flat.n_points, 3)
    assert snede.Mesh.read(writer.xdmf_path).is_surface


def test_a_series_that_does_not_say_its_dimension_is_read_as_before(tmp_path):
    """Series written before the steps said their dimension: triangles are 2D unless a step of
    the series leaves z = 0."""
    sheet = meshing.rectangle((2.0, 1.0), (4, 2))
    writer = SeriesWriter(tmp_path / "old")
    writer.write_mesh(sheet, 0.0)
    writer.write_mesh(flat_surface(sheet), 1.0)
    text = writer.xdmf_path.read_text()
    old = re.sub(r" *<Information Name=\"dimension\"[^>]*/>\n", "", text)
    assert old != text
    writer.xdmf_path.write_text(old)
    assert [s.mesh.dim for s in read_series(writer.xdmf_path)] == [2, 2]
    writer.write_mesh(meshing.boundary_surface(meshing.box((1.0, 1.0, 1.0), (1, 1, 1)))[0], 2.0)
    writer.xdmf_path.write_text(re.sub(r" *<Information Name=\"dimension\"[^>]*/>\n", "", writer.xdmf_path.read_text()))
    assert [s.mesh.dim for s in read_series(writer.xdmf_path)] == [3, 3, 3]


@pytest.mark.parametrize("value", ["4", "two", ""])
def test_a_step_with_a_bad_dimension(tmp_path, value):
    writer = small_series(tmp_path)
    text = writer.xdmf_path.read_text()
    writer.xdmf_path.write_text(text.replace('<Information Name="dimension" Value="2"/>',
                                             f'<Information Name="dimension" Value="{value}"/>', 1))
    with pytest.raises(ValueError, match=named(writer.xdmf_path, "step 0 says its dimension is")):
        read_series(writer.xdmf_path)
