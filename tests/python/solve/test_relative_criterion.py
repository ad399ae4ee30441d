"""Criterion "relative" (issue 36: the distributed solves had it, the serial ones now too, through
the one engine solver): ‖F‖ ≤ rtol·‖F(u₀)‖ plus (6.9)'s round-off floor, on the recomputed
residual; a start that already meets (6.9) is converged without an iteration."""
import numpy as np
import pytest

import snede
from solve_scenes import BEAM, cantilever, soft_beam


@pytest.mark.parametrize("method", ["cg", "newton", "ncg"])
def test_the_residual_falls_by_rtol_from_the_start(method):
    young = BEAM["E"] if method == "cg" else 3e3
    body, _ = cantilever((8, 2, 2)) if method == "cg" else (soft_beam(snede.NeoHookean(young, 0.3)), None)
    rtol = 1e-7
    result = snede.StaticSolver(body, method, rtol=rtol, criterion="relative").solve()
    assert result.converged, result
    # (6.9)'s round-off floor E·H²/√n·1e-12, H the body's diameter, n its unknowns.
    points = body.mesh.points
    floor = young * np.sum(np.ptp(points, axis=0) ** 2) / np.sqrt(points.size) * 1e-12
    assert result.tolerance == pytest.approx(rtol * result.initial_residual_norm + floor, rel=1e-9)
    assert result.residual_norm <= result.tolerance
    # ...and it is the true residual at the final state: the net force on the free vertices.
    u = body.displacement
    net = -body.internal_forces(u) - body.external_forces()
    fixed, _, _ = body._model.constraint_table()
    net[fixed] = 0.0
    assert result.residual_norm == pytest.approx(np.linalg.norm(net), rel=1e-6, abs=1e-3 * result.tolerance)


def test_a_start_in_equilibrium_is_converged_at_once():
    """rtol·‖F(u₀)‖ at a solved state would be below round-off: the start is judged by (6.9)."""
    body, _ = cantilever((8, 2, 2))
    assert snede.StaticSolver(body, "cg", rtol=1e-10).solve().converged
    again = snede.StaticSolver(body, "newton", rtol=1e-8, criterion="relative").solve()
    assert again.converged and again.iterations == 0, again
    assert again.tolerance >= again.initial_residual_norm


def test_a_relative_rtol_must_be_below_one():
    body, _ = cantilever((4, 1, 1))
    with pytest.raises(ValueError, match="relative rtol must be below 1"):
        snede.StaticSolver(body, "cg", rtol=1.0, criterion="relative")
