"""The needle3d scene with liver's forces (issue 33): the tissue at the entry is dragged by
millimetres, as a hand estimate from the cited force and stiffness says, and the pictures
(the cube with the needle, the section through the needle's axis) are written."""
from pathlib import Path

import numpy as np
import pytest

from snede.needle_forces import INSERTION_FORCE, LIVER_SHEAR_MODULUS
from snede.app.scenes import needle3d

from test_scenes import built_and_run, not_blank


@pytest.fixture(scope="module")
def inserted(tmp_path_factory):
    """h_ref = 0.1 m / 32, one h_ref per update: about 25 updates, a few seconds."""
    return built_and_run(needle3d, "needle3d_drag", tmp_path_factory, 32, speed=1.0)[:2]


def test_the_scene_is_liver():
    assert needle3d.YOUNG / (2 * (1 + needle3d.POISSON)) == pytest.approx(LIVER_SHEAR_MODULUS)


def test_the_entry_is_dragged_by_millimetres(inserted):
    scene, summary = inserted
    assert summary["converged"], summary
    # Hand estimate: the insertion force shears the cube above its fixed bottom, the shear
    # stress F / side² over the shear modulus times the entry's height: 1.25 mm.
    estimate = INSERTION_FORCE / needle3d.SIZE ** 2 / LIVER_SHEAR_MODULUS * needle3d.ENTRY[2]
    assert estimate / 3 < summary["entry_drag_m"] < 3 * estimate
    assert summary["entry_drag_m"] > 5e-4  # millimetres, not the 6 µm of the stand-in profile
    assert summary["max_displacement_m"] > 2 * summary["entry_drag_m"]  # the tissue at the tip moves most
    # The shaft pulls with about the cited force: the dynamic thresholds sum to it, the static to twice it.
    assert 0.2 * INSERTION_FORCE < summary["value"] < 2 * INSERTION_FORCE


def test_the_pictures_show_the_needle_and_the_section(inserted):
    _, summary = inserted
    for kind in ("png", "section"):
        path = Path(summary["files"][kind])
        assert path.exists() and not_blank(path)


def test_the_section_cuts_every_crossed_tetrahedron_once():
    # One tetrahedron, the plane through its middle: a quadrilateral (two vertices on each side)
    # or a triangle (one on one side), with the displacement interpolated along the cut edges.
    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1.0]])
    cells = np.array([[0, 1, 2, 3]])
    u = points * 0.1
    positions, displacements = needle3d.section(points, cells, u, 0.5)
    assert len(positions) == 1 and len(positions[0]) == 4
    assert np.allclose(positions[0][:, 1], 0.5) and np.allclose(displacements[0], 0.1 * positions[0])
    positions, _ = needle3d.section(points, cells, u, 0.99)
    assert len(positions[0]) == 4
    points[3, 1] = 0.0
    positions, _ = needle3d.section(points, cells, u, 0.5)
    assert len(positions[0]) == 3
    assert needle3d.section(points, cells, u, 2.0)[0] == []
