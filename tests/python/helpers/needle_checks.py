"""Checks of a needle's stick-slip state (§6.3.2) shared by the 3D needle tests."""
import numpy as np


def threshold_tolerance(body, needle, rtol: float, stiffness: float, size: float) -> float:
    """What stopping test (6.9) leaves in the forces: rtol times the loads and reactions, plus the
    round-off floor E·H²/√n·ε_round."""
    u = body.displacement
    reactions = body.reaction_forces()
    reactions[needle.needle_nodes] = needle.needle_forces()
    floor = stiffness * size ** 2 * np.sqrt(3) / np.sqrt(u.size) * 1e-8
    return 2 * (rtol * np.sqrt(np.sum(body.external_forces() ** 2) + np.sum(reactions ** 2)) + floor)


def check_thresholds(body, needle, tolerance: float) -> int:
    """Sticking nodes hold at most their static thresholds along the shaft; slipping ones are
    pulled by exactly their dynamic thresholds. Returns how many nodes slip."""
    g = -body.internal_forces(body.displacement) - body.external_forces()
    along = g[needle.needle_nodes] @ needle.direction
    elastic = -along - needle.friction
    stick = needle.sticking
    assert np.all(np.abs(along[stick]) <= needle.static_thresholds[stick] + tolerance)
    np.testing.assert_allclose(np.abs(elastic[~stick]), needle.dynamic_thresholds[~stick], atol=tolerance)
    return int((~stick).sum())
