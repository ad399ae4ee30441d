"""Issue 49: a scalpel's loop of 24 moves, one solve after each, makes nothing from scratch after
the first solve. The assembled tangent's sparsity, the grid levels and the pieces' labels follow
each cut (only what the cut touched is found again), and a linear material's tangent is made from
the earlier one; the reference (``-static_rebuild_after_edits``) makes all of them anew after
every cut. Both reach the same state. (Each structure against its rebuild, entry by entry, after
random edits: tests/cpp/problem/test_tangent_follows_edits.cpp, test_grid_levels_follow_edits.cpp,
test_piece_holding_follows_edits.cpp.)"""
import numpy as np
import pytest

import snede

MOVES = 24


def cut_loop(material, **options):
    """A block held at x = 0 sags under gravity; a blade taller than it crosses two thirds of its
    width at x ≈ 0.061 m in MOVES moves (no piece comes off). Returns (solver, results, state)."""
    mesh = snede.meshing.box((0.12, 0.03, 0.03), (16, 4, 4))
    body = snede.Body(mesh, material(E=3e4, nu=0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner="mg",
                                petsc_options={"mg_coarsening": "grid", **options})
    assert solver.solve().converged
    cutter = snede.TetrahedralCutter(body)
    x = 0.0611  # off the vertex layers
    blade = lambda y: [(x, y, -0.02), (x, y, 0.05)]
    cutter.move(blade(-0.004))
    results = []
    for y in np.linspace(-0.004, 0.018, MOVES + 1)[1:]:
        cutter.move(blade(y))
        results.append(solver.solve())
    return solver, results, body.displacement.copy()


@pytest.mark.parametrize("material", [snede.LinearElastic, snede.NeoHookean])
def test_a_cut_loop_makes_nothing_from_scratch_after_the_first_solve(material):
    followed, followed_results, followed_state = cut_loop(material)
    reference, reference_results, reference_state = cut_loop(material, rebuild_after_edits="true")
    assert all(r.converged for r in followed_results + reference_results)
    # The cut changed the mesh's elements several times: the reference made everything anew each time.
    assert reference.multigrid_builds >= 5 and reference.sparsity_builds >= 5 and reference.piece_labellings >= 5
    assert reference.multigrid_edits == reference.sparsity_edits == 0
    # Followed: one build from scratch (the first solve's), every later one an edit.
    assert followed.multigrid_edits >= 4 and followed.sparsity_edits >= 4
    assert followed.multigrid_builds - followed.multigrid_edits == 1
    assert followed.sparsity_builds - followed.sparsity_edits == 1
    assert followed.piece_labellings == 1
    if material is snede.LinearElastic:
        assert followed.tangent_assemblies == 1
        assert reference.tangent_assemblies >= 5
    # Both stop at rtol 1e-8 of the load: the states differ by the remaining error.
    scale = np.abs(reference_state).max()
    np.testing.assert_allclose(followed_state, reference_state, rtol=0, atol=1e-6 * scale)
