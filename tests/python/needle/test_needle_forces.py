"""Liver's needle forces (snede.needle_forces): the profile integrates to the cited insertion
force over the cited length, split between the cutting bulge at the tip and the shaft friction
as cited, per unit length in 2D and per unit shaft surface in 3D."""
import math

import pytest

from snede import needle_forces
from snede.needle_forces import (CUTTING_SHARE, FRICTION_SHARE, INSERTION_FORCE, LIVER_SHEAR_MODULUS, liver_profile,
                                 liver_young)

LENGTH = 0.07  # the needle3d scene's depth
BULGE = needle_forces.BULGE[-1]


def test_the_shares_are_the_whole_force():
    assert CUTTING_SHARE + FRICTION_SHARE == pytest.approx(1.0)


@pytest.mark.parametrize("radius", [None, 1e-3, 0.635e-3])
def test_the_profile_integrates_to_the_cited_force_split_as_cited(radius):
    profile = liver_profile(LENGTH, radius)
    around = 1.0 if radius is None else 2 * math.pi * radius  # NeedleInsertion's 2πr in 3D
    assert around * profile.integral(0.0, LENGTH) == pytest.approx(INSERTION_FORCE, rel=1e-12)
    friction_per_length = FRICTION_SHARE * INSERTION_FORCE / LENGTH
    assert around * profile(LENGTH) == pytest.approx(friction_per_length, rel=1e-12)  # the plateau behind the bulge
    bulge = around * profile.integral(0.0, BULGE) - friction_per_length * BULGE
    assert bulge == pytest.approx(CUTTING_SHARE * INSERTION_FORCE, rel=1e-12)
    assert profile(0.001) == max(profile.force_per_length)  # the peak a millimetre behind the tip (Figure 6.4's shape)


def test_a_longer_shaft_spreads_the_same_friction_thinner():
    assert liver_profile(0.14)(0.1) == pytest.approx(liver_profile(0.07)(0.05) / 2)
    assert liver_profile(0.07, insertion_force=0.9).integral(0.0, 0.07) == pytest.approx(0.9)


def test_a_shaft_no_longer_than_the_bulge_is_refused():
    with pytest.raises(ValueError, match="bulge"):
        liver_profile(0.004)


def test_liver_young_keeps_the_cited_shear_modulus():
    for poisson in (0.0, 0.4, 0.49):
        young = liver_young(poisson)
        assert young / (2 * (1 + poisson)) == pytest.approx(LIVER_SHEAR_MODULUS)
