"""A needle's move carried into the tissue instead of halved (issue 50): on a gmsh mesh, whose
bisected cells along the shaft are thin, a neo-Hookean insertion halves far fewer moves with the
extension, and the stick-slip thresholds hold after every update with and without it."""
import numpy as np
import pytest

import snede
from needle_checks import check_thresholds, threshold_tolerance

E, LENGTH = 5e3, 0.1


@pytest.fixture(scope="module")
def cylinder():
    return snede.meshing.cylinder(length=LENGTH, radius=0.02, h=0.006, seed=3)


def insertion(cylinder, rings):
    mesh = snede.Mesh(cylinder.points, cylinder.cells)
    body = snede.Body(mesh, snede.NeoHookean(E, 0.45))
    body.fix(np.isclose(mesh.points[:, 0], LENGTH))
    needle = snede.NeedleInsertion(body, (-0.01, 0.0013, -0.0007), (1.0, 0.0, 0.0),
                                   snede.FrictionProfile.figure_6_4(), radius=1e-3, h_ref=2.5e-3, method="newton",
                                   rtol=1e-7, extension_rings=rings)
    needle.advance(needle.surface_depth)
    return body, needle


def test_the_extension_replaces_halvings_and_thresholds_hold_after_every_update(cylinder):
    halvings = {}
    for rings in (3, 0):
        body, needle = insertion(cylinder, rings)
        halvings[rings] = extensions = 0
        for _ in range(12):
            step = needle.advance(1e-3)
            assert step.converged and step.settled, step
            assert len(body.inverted_elements(body.displacement)) == 0
            check_thresholds(body, needle, threshold_tolerance(body, needle, 1e-7, E, LENGTH))
            halvings[rings] += step.halvings
            extensions += step.extensions
        assert (extensions > 0) == (rings > 0)
    assert halvings[0] > 0, "the test should see moves that invert cells"
    assert halvings[3] < halvings[0]


def test_a_negative_ring_count_is_refused(cylinder):
    with pytest.raises(ValueError, match="extension_rings"):
        insertion(cylinder, -1)
