"""Needle insertion (§6.3–§6.7): friction limits, equilibrium, stick-slip thresholds after every
update, release of nodes off the needle, refinement at the tip, bad input, honest reports."""
import numpy as np
import pytest

import snede
from snede.app.scenes.needle_slab import SIZE, h, needle_for, slab_body

H_START, H_REF = 3, 5


def fixed_mask(body):
    return np.isclose(body.mesh.points[:, 0], SIZE)


def shaft_components(body, needle):
    """Per needle node: ∇Π along the shaft (the needle's holding force for a sticking node)
    and the elastic force along the shaft without friction (for a slipping node)."""
    u = body.displacement
    g = -body.internal_forces(u) - body.external_forces()
    along = g[needle.needle_nodes] @ needle.direction
    return along, -along - needle.friction


def test_friction_profile_integral_is_exact_for_the_piecewise_linear_profile():
    profile = snede.FrictionProfile([0.0, 0.002, 0.005, 0.01], [40.0, 60.0, 45.0, 20.0])
    s = np.linspace(0.001, 0.03, 200001)
    numeric = np.trapz(profile(s), s)
    assert profile.integral(0.001, 0.03) == pytest.approx(numeric, rel=1e-9)
    assert profile(0.0035) == pytest.approx(52.5)
    assert profile(1.0) == 20.0


@pytest.mark.parametrize("distances, forces, fragment", [
    ([0.0, 0.01], [1.0, -2.0], "non-negative; entry 1"),
    ([0.0, 0.01, 0.005], [1.0, 1.0, 1.0], "increasing; entry 2"),
    ([0.001], [1.0], "first distance must be 0"),
    ([0.0, 0.01], [1.0], "as many force values"),
])
def test_bad_friction_profiles_name_the_entry(distances, forces, fragment):
    with pytest.raises(ValueError, match=fragment):
        snede.FrictionProfile(distances, forces)


def test_with_friction_far_above_any_force_every_needle_node_moves_with_the_needle():
    body = slab_body(H_START)
    needle = needle_for(body, H_REF, friction=snede.FrictionProfile.uniform(1e9), rtol=1e-8)
    needle.insert(0.03, h(H_REF))
    nodes = needle.needle_nodes
    before = body.displacement[nodes]
    step = needle.advance(0.004)
    assert step.converged and step.slipped == 0
    assert needle.sticking.all() and len(nodes) >= 0.03 / h(H_REF) - 1
    moved = body.displacement[needle.needle_nodes[: len(nodes)]] - before
    np.testing.assert_allclose(moved, np.tile([0.004, 0.0], (len(nodes), 1)), atol=1e-15)


def test_without_friction_the_slab_does_not_move():
    body = slab_body(H_START)
    needle = needle_for(body, H_REF, friction=snede.FrictionProfile.uniform(0.0), rtol=1e-10)
    report = needle.insert(0.05, 2 * h(H_REF))
    assert report.converged
    assert len(needle.needle_nodes) > 0 and not needle.sticking.any()
    # Zero up to the round-off floor of (6.9), ε_round·E·t·H/√n in force, i.e. about ε_round·H
    # in displacement (the loaded slab moves by millimetres).
    assert np.abs(body.displacement).max() < 1e-8 * SIZE * np.sqrt(2)


# A Krylov initial guess from earlier solves (PETSc's KSPGuess) must follow the refinement at the
# tip: one made for the vectors of the mesh before failed the first solve after it (error 75).
FISCHER_GUESS = {"ksp_guess_type": "fischer", "ksp_guess_fischer_model": "1,10"}


@pytest.mark.parametrize("material, method, rtol, petsc_options",
                         [(snede.LinearElastic(34e3, 0.34), "cg", 1e-8, None),
                          (snede.NeoHookean(34e3, 0.34), "newton", 1e-7, None),
                          (snede.LinearElastic(34e3, 0.34), "cg", 1e-8, FISCHER_GUESS),
                          (snede.NeoHookean(34e3, 0.34), "newton", 1e-7, FISCHER_GUESS)])
def test_after_every_update_thresholds_hold_and_the_needle_balances_the_support(material, method, rtol, petsc_options):
    body = slab_body(H_START, material)
    needle = needle_for(body, H_REF, rtol=rtol, method=method, petsc_options=petsc_options)
    cells = body.mesh.n_cells
    n_slipping = 0
    for _ in range(24):
        step = needle.advance(0.5 * h(H_REF))
        assert step.converged, step
        along, elastic = shaft_components(body, needle)
        stick = needle.sticking
        # The solver's residual bound (6.9), doubled as the solver's own verdict allows.
        reactions = body.reaction_forces()
        reactions[needle.needle_nodes] = needle.needle_forces()
        floor = 34e3 * 0.01 * SIZE * np.sqrt(2) / np.sqrt(body.displacement.size) * 1e-8  # E·t·H/√n·ε_round
        tolerance = 2 * (rtol * np.sqrt(np.sum(body.external_forces() ** 2) + np.sum(reactions ** 2)) + floor)
        assert np.all(np.abs(along[stick]) <= needle.static_thresholds[stick] + tolerance)
        np.testing.assert_allclose(np.abs(elastic[~stick]), needle.dynamic_thresholds[~stick], atol=tolerance)
        n_slipping += (~stick).sum()
        # Friction along the needle balances the reactions at the fixed side (and the residual).
        # The free vertices' residuals (each within the bound) add up to at most √n times it.
        total = needle.needle_forces().sum(axis=0) + body.reaction_forces()[fixed_mask(body)].sum(axis=0)
        assert np.abs(total).max() <= np.sqrt(body.displacement.size) * tolerance
    assert n_slipping > 0, "the test should see slipping nodes"
    assert np.abs(body.displacement).max() > 1e-4  # the needle drags the slab
    assert body.mesh.n_cells > cells, "the test should see the mesh refined at the tip"


def test_refinement_reaches_h_ref_at_the_tip_and_needle_nodes_lie_along_the_shaft():
    body = slab_body(H_START)
    needle = needle_for(body, H_REF)
    needle.insert(0.04, h(H_REF))
    mesh = body.mesh
    assert mesh.n_cells > 2 * 4 ** H_START
    x = mesh.points + body.displacement
    tip = needle.tip
    near = np.flatnonzero(np.linalg.norm(x - tip, axis=1) < 0.5 * h(H_REF))
    assert len(near) > 0
    # Needle nodes stay within one h_ref of the shaft (d_perp is held), and cover it.
    assert np.abs(needle.d_perp).max() <= h(H_REF) * 0.75
    s = np.sort(needle.d_needle)
    assert s[-1] > 0.04 - 1.5 * h(H_REF) and np.diff(s).max() <= 1.5 * h(H_REF)


@pytest.mark.parametrize("push, where", [(-1.0, "out of the body"), (1.0, "past the tip")])
def test_needle_nodes_that_slide_off_the_needle_are_released(push, where):
    body = slab_body(H_START)
    needle = needle_for(body, H_REF, friction=snede.FrictionProfile.uniform(0.5), rtol=1e-8)
    needle.insert(0.03, h(H_REF))
    nodes = set(needle.needle_nodes.tolist())
    # A body force along the shaft drags the slab over the needle.
    body.add_nodal_force(np.arange(body.mesh.n_points), (push * 0.02, 0.0))
    report = needle.settle()
    assert report.converged and report.released > 0, where
    released = nodes - set(needle.needle_nodes.tolist())
    assert released
    s = (body.mesh.points + body.displacement)[sorted(released)] @ needle.direction - needle.entry @ needle.direction
    assert np.all(s < 0) if push < 0 else np.all(s > needle.depth)
    # A released node is free again: no reaction.
    assert np.abs(body.reaction_forces()[sorted(released)]).max() == 0.0


def test_an_unconverged_solve_is_reported_not_hidden():
    body = slab_body(H_START)
    needle = needle_for(body, H_REF, max_iterations=1, rtol=1e-10)
    report = needle.insert(0.02, h(H_REF))
    assert not report.converged and report.reason.startswith("SOLVE_")


def test_bad_input_names_the_value():
    body = slab_body(H_START)
    profile = snede.FrictionProfile.figure_6_4()
    with pytest.raises(ValueError, match="never meets the body"):
        snede.NeedleInsertion(body, (0.0, 0.2), (1.0, 0.0), profile)
    with pytest.raises(ValueError, match="non-zero"):
        snede.NeedleInsertion(body, (0.0, 0.05), (0.0, 0.0), profile)
    with pytest.raises(ValueError, match="static_factor"):
        snede.NeedleInsertion(body, (0.0, 0.05), (1.0, 0.0), profile, static_factor=0.5)
    needle = snede.NeedleInsertion(body, (0.0, 0.05), (1.0, 0.0), profile)
    with pytest.raises(ValueError, match="-0.001"):
        needle.advance(-0.001)
    with pytest.raises(ValueError, match="step"):
        needle.insert(0.01, -0.001)
    box = snede.meshing.box((1, 1, 1), (2, 2, 2))
    body3 = snede.Body(box, snede.LinearElastic(1e3, 0.3))
    with pytest.raises(ValueError, match="3 components for this 3-D body"):  # 3D needles: test_needle3d.py
        snede.NeedleInsertion(body3, (0.0, 0.5), (1.0, 0.0), profile)


@pytest.mark.parametrize("extrapolate", [False, True])
def test_one_solve_per_update_carries_rearrangements_over_and_ends_settled(extrapolate):
    body = slab_body(H_START)
    needle = needle_for(body, H_REF, rtol=1e-6, solves_per_update=1, extrapolate=extrapolate)
    report = needle.insert(0.04, h(H_REF))
    assert report.converged
    assert all(step.rearrangements == 1 for step in report.steps)
    assert any(not step.settled for step in report.steps)  # pending changes were carried over
    assert report.steps[-1].settled and report.updates > 0.04 / h(H_REF)
    # The settled end state meets the thresholds like a fully rearranged insertion.
    along, elastic = shaft_components(body, needle)
    stick = needle.sticking
    assert np.all(np.abs(along[stick]) <= needle.static_thresholds[stick] * (1 + 1e-6))


@pytest.mark.parametrize("material", [snede.StVenantKirchhoff(34e3, 0.34), snede.NeoHookean(34e3, 0.34),
                                      snede.VerondaWestmann(34e3, 0.34, 2.0)], ids=lambda m: type(m).__name__)
def test_every_nonlinear_material_inserts_with_newton_and_keeps_the_thresholds(material):
    body = slab_body(H_START, material)
    needle = needle_for(body, H_REF, rtol=1e-6, method="newton")
    report = needle.insert(0.03, h(H_REF))
    assert report.converged, report.reason
    along, _ = shaft_components(body, needle)
    stick = needle.sticking
    assert np.all(np.abs(along[stick]) <= needle.static_thresholds[stick] * (1 + 1e-4))
    assert len(body.inverted_elements(body.displacement)) == 0


def test_a_planar_needle_by_linear_cg_takes_no_multigrid_below_ten_thousand_triangles():
    # Its small corrections per update were faster without multigrid's levels, made again at
    # nearly every update, up to 4 000 triangles (studies/benchmarks/needle_rates.py --crossover);
    # Newton keeps its levels across stick-slip and a solve from rest gains from them: both
    # take multigrid on the same 2 048 triangles.
    sources = {}
    for method, material in (("cg", None), ("newton", snede.NeoHookean(34e3, 0.34))):
        body = slab_body(5, material)
        assert 1000 < body.mesh.n_cells < 10000
        needle = needle_for(body, 6, method=method)
        for _ in range(3):
            assert needle.advance(h(6)).converged
        sources[method] = needle.multigrid_source
    body = slab_body(5)
    body.add_gravity((0.0, -9.81))
    solver = snede.StaticSolver(body, "cg")
    assert solver.solve().converged
    assert sources == {"cg": "", "newton": "grid"} and solver.multigrid_source == "grid"


def test_a_move_of_one_node_spacing_never_starts_a_solve_from_flat_cells():
    # The shaft runs on a grid line of the h7 mesh and each update moves it by h_ref, the spacing
    # of the needle nodes: a sticking node moved by one step landed exactly on the next needle
    # node, its cells flat to round-off (det F ≈ 1e-13, which no inversion test counts), and
    # Newton stopped at the third update (DIVERGED_LINE_SEARCH, forces of 4e14 N). The move is
    # carried into the tissue or halved instead, and every update converges.
    body = slab_body(3, snede.NeoHookean(34e3, 0.34))
    needle = needle_for(body, 7, method="newton", rtol=1e-3, solves_per_update=1)
    helped = 0
    for _ in range(12):
        step = needle.advance(h(7))
        assert step.converged, step
        helped += step.extensions + step.halvings
        x = body.mesh.points + body.displacement
        a, b, c = (x[body.mesh.cells[:, k]] for k in range(3))
        deformed = np.cross(b - a, c - a)
        reference = np.cross(*(body.mesh.points[body.mesh.cells[:, k]] - body.mesh.points[body.mesh.cells[:, 0]]
                               for k in (1, 2)))
        assert (deformed / reference).min() > 1e-3  # J of every cell, far from flat
    assert helped > 0, "the test should see a move that needed help"
