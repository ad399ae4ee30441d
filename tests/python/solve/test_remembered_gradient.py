"""The model remembers the gradient ∇Π of its last residual (the solver's final one) for the
needle's rearrangement (issue 33): it must not outlive a change of the state, the loads or the
mesh."""
import numpy as np
import pytest

import snede
from snede.app.scenes.needle_slab import slab_body


def fixed_vertices(body) -> np.ndarray:
    return np.flatnonzero(np.isclose(np.asarray(body.mesh.points)[:, 0], 0.1))  # slab_body holds x = 0.1


def fresh_reactions(body) -> np.ndarray:
    """The reactions computed from scratch: ∇Π at the fixed vertices."""
    g = -body.internal_forces(body.displacement) - body.external_forces()
    reactions = np.zeros_like(g)
    reactions[fixed_vertices(body)] = g[fixed_vertices(body)]
    return reactions


@pytest.fixture
def solved():
    body = slab_body(2)
    body.add_nodal_force([0], (1.0, 0.5))
    snede.StaticSolver(body, "cg", rtol=1e-8).solve()
    return body


def test_after_a_solve_the_reactions_balance_the_load(solved):
    assert solved.reaction_forces().sum(axis=0) == pytest.approx((-1.0, -0.5), abs=1e-6)
    assert solved.reaction_forces() == pytest.approx(fresh_reactions(solved))


def test_a_new_load_is_seen_without_a_solve(solved):
    before = solved.reaction_forces()
    held = fixed_vertices(solved)[0]
    solved.add_nodal_force([held], (2.0, 0.0))
    after = solved.reaction_forces()
    assert after[held] == pytest.approx(before[held] - (2.0, 0.0))
    assert after == pytest.approx(fresh_reactions(solved))


def test_a_new_state_is_seen_without_a_solve(solved):
    solved.displacement = 2 * solved.displacement
    assert solved.reaction_forces() == pytest.approx(fresh_reactions(solved))


def test_a_refined_mesh_is_seen_without_a_solve(solved):
    solved.refine_around((0.09, 0.05), 0.01)
    assert solved.reaction_forces() == pytest.approx(fresh_reactions(solved))
