"""Arguments of a solve are checked, and refused with the value (issue 14)."""
import numpy as np
import pytest

import snede
from solve_scenes import sagging_sheet


@pytest.mark.parametrize("kwargs, fragment", [
    ({"round_tolerance": -1.0}, "round_tolerance must be finite and non-negative"),
    ({"round_tolerance": float("nan")}, "round_tolerance"),
    ({"max_iterations": -1}, "max_iterations must be at least 1, got -1"),
])
def test_solver_arguments_are_checked_with_the_value(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        snede.StaticSolver(sagging_sheet(1e5), "cg", **kwargs)


def test_fixing_one_vertex_twice_with_different_values_is_refused_and_changes_nothing():
    body = sagging_sheet(1e5)
    with pytest.raises(ValueError, match="vertex 3 is listed twice .* different values"):
        body.fix([3, 5, 3], [[0.0, 0.0], [0.0, 0.0], [0.1, 0.0]])
    assert np.abs(body.reaction_forces()[3]).max() == 0.0 and np.all(body.displacement[3] == 0)
    body.fix([3, 3], [[0.1, 0.0], [0.1, 0.0]])  # the same value twice is harmless
    assert body.displacement[3, 0] == 0.1
