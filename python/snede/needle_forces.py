"""Needle forces and tissue stiffness of the size measured in liver, for snede.FrictionProfile.

The thesis's Figure 6.4 gives the shape of the force along the shaft (a bulge at the tip where
the needle cuts, then a plateau of shaft friction; §6.3.2) but no numbers. This module puts
published magnitudes on that shape. Sources, and what each gives (docs/results/needle3d.md,
"The scene's forces", has the derivation in full):

* Total axial force F = 0.45 N: the largest needle force of Kobayashi et al.'s in-vitro
  validation of a pig-liver needle-insertion model (Y. Kobayashi, A. Onishi, T. Hoshi,
  K. Kawamura, M. Hashizume, M. G. Fujie, "Development and validation of a viscoelastic and
  nonlinear liver model for needle insertion", Int. J. CARS 4:53–63, 2009: "for a force up
  to 0.45 N, the maximum error is below 1 mm").
* Its split: 61 % tearing and 18 % spreading at the tip (together 79 %: the cutting force),
  21 % shaft friction, on average over their ex-vivo insertions (A. C. Barnett, Y.-S. Lee,
  J. Z. Moore, "Fracture mechanics model of needle cutting tissue", J. Manuf. Sci. Eng.,
  doi:10.1115/1.4030374, 2015).
* Liver stiffness: shear modulus μ = 1.8 ± 0.4 kPa (the literature table of Phys. Med. Biol.
  64(22):225001, 2019, Table 1, after Bamber & Hill 1981 and Palmeri et al. 2008); a body
  given Poisson's ratio ν has E = 2μ(1 + ν) (``liver_young``).

The decomposition into a cutting force at the tip and friction along the shaft is that of
Okamura, Simone and O'Leary ("Force modeling for needle insertion into soft tissue", IEEE
Trans. Biomed. Eng. 51(10):1707–1716, 2004: bovine liver ex vivo, 18-gauge bevel needle,
3 mm/s); the search tools available here did not give that paper's fitted values, so none
of its numbers is used.
"""
from __future__ import annotations

import math

from snede.needle import FrictionProfile

INSERTION_FORCE = 0.45  # N, Kobayashi et al. 2009 (pig liver, in vitro)
CUTTING_SHARE = 0.61 + 0.18  # tearing + spreading at the tip, Barnett, Lee & Moore 2015
FRICTION_SHARE = 0.21  # shaft friction, the same source
LIVER_SHEAR_MODULUS = 1.8e3  # Pa, Phys. Med. Biol. 64:225001 (2019), Table 1
# The cutting force as a bulge over the tip's first millimetres (the shape of Figure 6.4):
# half its peak at the tip, the peak 1 mm behind it, the friction plateau 4 mm behind it.
BULGE = (0.0, 0.001, 0.004)  # m from the tip
BULGE_HEIGHTS = (0.5, 1.0, 0.0)  # of the peak


def liver_young(poisson: float) -> float:
    """Young's modulus (Pa) of liver's shear modulus at Poisson's ratio ``poisson``."""
    return 2.0 * LIVER_SHEAR_MODULUS * (1.0 + poisson)


def liver_profile(friction_length: float, radius: float | None = None,
                  insertion_force: float = INSERTION_FORCE) -> FrictionProfile:
    """The Figure 6.4 shape with liver's forces: over ``friction_length`` (m, the depth at
    which ``insertion_force`` is reached) the profile integrates to ``insertion_force``, of
    which ``CUTTING_SHARE`` in the bulge over the tip's first 4 mm and ``FRICTION_SHARE`` as a
    constant shaft friction per length. ``radius`` None: force per unit shaft length (N/m,
    2D: across the sheet's thickness); a radius (m, 3D): per unit shaft surface (N/m²), so
    that NeedleInsertion's 2πr times the integral gives the same forces."""
    if friction_length <= BULGE[-1]:
        raise ValueError(f"friction_length must exceed the {BULGE[-1] * 1e3:g} mm bulge at the tip, got {friction_length}")
    plateau = FRICTION_SHARE * insertion_force / friction_length  # N/m
    shape_area = sum((b - a) * (ha + hb) / 2 for a, b, ha, hb in zip(BULGE, BULGE[1:], BULGE_HEIGHTS, BULGE_HEIGHTS[1:]))
    peak = CUTTING_SHARE * insertion_force / shape_area  # N/m above the plateau
    per_length = [plateau + peak * height for height in BULGE_HEIGHTS]
    scale = 1.0 if radius is None else 1.0 / (2.0 * math.pi * radius)
    return FrictionProfile(BULGE, [scale * f for f in per_length])
