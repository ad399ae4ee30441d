"""XDMF field names are escaped, and names the series cannot hold (issue 14) or that would replace
a field the writer makes itself (issue 48) are refused."""
import xml.etree.ElementTree as ElementTree

import meshio
import numpy as np
import pytest

import snede
from snede.output import SeriesWriter, read_series


def test_xdmf_field_names_are_escaped_and_bad_ones_refused(tmp_path):
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    writer = SeriesWriter(tmp_path / "names")
    odd = 'E<1&2 "x"'
    writer.write_mesh(mesh, 0.0, **{odd: np.arange(mesh.n_cells, dtype=float)})
    names = [a.get("Name") for a in ElementTree.parse(writer.xdmf_path).iter("Attribute")]
    assert odd in names
    with meshio.xdmf.TimeSeriesReader(str(writer.xdmf_path)) as reader:
        reader.read_points_cells()
        _, _, cell_data = reader.read_data(0)
    np.testing.assert_array_equal(cell_data[odd][0], np.arange(mesh.n_cells))
    for bad in ("a/b", ""):
        with pytest.raises(ValueError, match="not usable"):
            writer.write_mesh(mesh, 1.0, **{bad: np.zeros(mesh.n_cells)})
    with pytest.raises(ValueError, match="used twice"):
        writer.write_mesh(mesh, 1.0, point_fields={"aspect_ratio": np.zeros(mesh.n_points)})


@pytest.mark.parametrize("name", ["aspect_ratio", "min_angle", "inverted", "group:left"])
def test_a_field_named_as_a_built_in_one_is_refused(tmp_path, name):
    """A user field named as one the writer makes itself would replace it (aspect_ratio,
    min_angle, group:<name>) or clash with the writer's own keyword (inverted: a TypeError); it
    is a ValueError naming the field, nothing is written, and the writer goes on."""
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    mesh.add_cell_group("left", [0, 1])
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3), thickness=0.01)
    writer = SeriesWriter(tmp_path / "built_in")
    with pytest.raises(ValueError, match=f"'{name}' is taken"):
        writer.write(body, 0.0, **{name: np.full(mesh.n_cells, 7.0)})
    assert writer.n_steps == 0
    writer.write(body, 1.0)
    step = read_series(writer.xdmf_path)[0]
    np.testing.assert_array_equal(step.cell_fields["aspect_ratio"], mesh.quality().aspect_ratio)
    np.testing.assert_array_equal(step.cell_fields["inverted"], np.zeros(mesh.n_cells))
    np.testing.assert_array_equal(step.cell_fields["group:left"], [1, 1, 0, 0, 0, 0, 0, 0])


def test_a_point_field_named_as_a_boundary_group_is_refused(tmp_path):
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    mesh.add_boundary_group("bottom", mesh.boundary_faces()[:1])
    with pytest.raises(ValueError, match="point field name 'group:bottom' is taken"):
        SeriesWriter(tmp_path / "groups").write_mesh(mesh, point_fields={"group:bottom": np.zeros(mesh.n_points)})
