"""XDMF field names are escaped, and names the series cannot hold are refused (issue 14)."""
import xml.etree.ElementTree as ElementTree

import meshio
import numpy as np
import pytest

import snede
from snede.output import SeriesWriter


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
