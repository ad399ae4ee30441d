"""Static relaxation through PETSc: the §3.3 cantilever, nonlinear agreement, constraints,
mesh changes during a simulation, honest failure."""
import subprocess
import sys

import numpy as np
import pytest

import snede
from solve_scenes import BEAM_DEFLECTION, cantilever, soft_beam


def test_cantilever_table_3_1_deflection_below_analytic_and_converging():
    errors = []
    for n in (16, 24):
        body, tip = cantilever((n, n // 4, n // 4))
        result = snede.StaticSolver(body, "cg", rtol=1e-8, options_prefix=f"t31_{n}_").solve()
        assert result.converged, result
        assert result.reason == "CONVERGED_ATOL"
        assert result.residual_norm <= result.tolerance
        deflection = -body.displacement[tip, 1]
        assert np.all(deflection < BEAM_DEFLECTION)  # FEM is stiffer than the beam formula
        errors.append(1 - deflection.mean() / BEAM_DEFLECTION)
    # Table 3.1: 29.0 % and 15.1 % on the thesis's tetrahedra; the error falls with refinement.
    assert 0 < errors[1] < 0.7 * errors[0] < 0.35


@pytest.mark.parametrize("method", ["newton", "ncg"])
def test_all_methods_agree_on_the_linear_cantilever(method):
    reference, tip = cantilever((12, 3, 3))
    snede.StaticSolver(reference, "cg", rtol=1e-10, options_prefix="ref_").solve()
    body, _ = cantilever((12, 3, 3))
    result = snede.StaticSolver(body, method, rtol=1e-10, options_prefix=f"agree_{method}_").solve()
    assert result.converged, result
    assert np.abs(body.displacement - reference.displacement).max() <= 1e-6 * np.abs(reference.displacement).max()


@pytest.mark.parametrize("line_search, ncg_type", [("cp", "prp"), ("cp", "fr"), ("snede_secant", "prp"),
                                                   ("snede_secant", "fr"), ("snede_newton", "prp")])
def test_nonlinear_cg_reaches_newtons_solution(line_search, ncg_type):
    reference = soft_beam()
    assert snede.StaticSolver(reference, "newton", rtol=1e-10, options_prefix="nl_ref_").solve().converged
    u_ref = reference.displacement
    assert np.abs(u_ref[:, 2]).max() > 0.03  # large deflection: a third of the length
    body = soft_beam()
    # cp is the scale-dependent secant: its first trial step (damping) must suit the problem
    scale = {"snes_linesearch_damping": 1e-3} if line_search == "cp" else {}
    result = snede.StaticSolver(body, "ncg", rtol=1e-7, line_search=line_search, ncg_type=ncg_type,
                                max_iterations=20000, options_prefix=f"nl_{line_search}_{ncg_type}_",
                                petsc_options=scale).solve()
    assert result.converged, result
    assert np.abs(body.displacement - u_ref).max() <= 1e-4 * np.abs(u_ref).max()
    assert result.energy == pytest.approx(
        snede.StaticSolver(reference, "newton", rtol=1e-10, options_prefix="nl_ref2_").solve().energy, rel=1e-8)


def test_prescribed_and_sliding_constraints_hold_and_reactions_balance():
    mesh = snede.meshing.box((0.1, 0.02, 0.02), (6, 2, 2))
    body = snede.Body(mesh, snede.NeoHookean(3e3, 0.3))
    x = mesh.points
    left, right = np.isclose(x[:, 0], 0.0), np.isclose(x[:, 0], 0.1)
    body.fix(left)
    body.fix(right, value=(0.02, 0.0, 0.0))  # stretch by 20 % with no external force
    bottom_middle = np.flatnonzero(np.isclose(x[:, 2], 0.0) & ~left & ~right)
    direction = np.array([1.0, 0.0, 0.0])
    body.slide(bottom_middle, direction)
    result = snede.StaticSolver(body, "newton", rtol=1e-9, options_prefix="cons_").solve()
    assert result.converged, result
    u = body.displacement
    assert np.all(u[left] == 0.0)
    assert np.all(u[right] == np.array([0.02, 0.0, 0.0]))
    assert np.abs(u[bottom_middle][:, 1:]).max() == 0.0  # only along x
    reactions = body.reaction_forces()
    assert np.abs(reactions.sum(axis=0) + body.external_forces().sum(axis=0)).max() <= 1e-8 * np.abs(reactions).max()
    assert reactions[right, 0].sum() > 0  # pulling the right end in +x


def test_gravity_reactions_balance_weight():
    body = soft_beam(snede.StVenantKirchhoff(3e3, 0.3))
    result = snede.StaticSolver(body, "newton", rtol=1e-9, options_prefix="weight_").solve()
    assert result.converged, result
    weight = body.lumped_mass().sum() * 9.81
    assert body.reaction_forces()[:, 2].sum() == pytest.approx(weight, rel=1e-7)


def test_solve_continues_after_a_cut_from_the_carried_over_state():
    body = soft_beam(divisions=(8, 2, 4))
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, options_prefix="cut_")
    first = solver.solve()
    assert first.converged, first
    n_before, generation = body.mesh.n_points, body._model.generation
    u_before = body.displacement
    split = body.mesh.dissect(body.mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.05) & (x[:, 2] <= 0.01 + 1e-12)))
    assert len(split) > 0 and body._model.generation == generation + 1
    u_carried = body.displacement
    assert u_carried.shape == (body.mesh.n_points, 3) and body.mesh.n_points > n_before
    assert np.array_equal(u_carried[:n_before], u_before)
    assert np.array_equal(u_carried[split[:, 1]], u_before[split[:, 0]])  # copies start where their originals are
    second = solver.solve()
    assert second.converged, second
    assert body.displacement[:, 2].min() < u_before[:, 2].min()  # the cut beam sags more
    u_cut = body.displacement
    # Starting over from zero on the cut mesh reaches the same state, but needs more work.
    body.displacement = np.zeros_like(u_cut)
    from_zero = solver.solve()
    assert from_zero.converged, from_zero
    assert np.abs(body.displacement - u_cut).max() <= 1e-6 * np.abs(u_cut).max()
    assert second.linear_iterations < from_zero.linear_iterations


def test_free_body_is_rejected_not_left_to_hang():
    mesh = snede.meshing.box((1, 1, 1), (2, 2, 2))
    body = snede.Body(mesh, snede.NeoHookean(1e3, 0.3))
    body.add_gravity()
    with pytest.raises(ValueError, match="not held"):
        snede.StaticSolver(body, "newton", options_prefix="free_").solve()


def test_bad_arguments_are_rejected():
    body = soft_beam()
    with pytest.raises(ValueError, match="method"):
        snede.StaticSolver(body, "gauss-seidel")
    with pytest.raises(ValueError, match="rtol"):
        snede.StaticSolver(body, "newton", rtol=0.0)
    with pytest.raises(ValueError, match="LinearElastic"):
        snede.StaticSolver(body, "cg")
    with pytest.raises(ValueError, match="0.5"):
        snede.NeoHookean(1e3, 0.5)


def test_iteration_limit_is_a_named_divergence():
    body = soft_beam()
    result = snede.StaticSolver(body, "ncg", rtol=1e-10, options_prefix="limit_",
                                petsc_options={"snes_max_it": 3}).solve()
    assert not result.converged
    assert result.reason == "DIVERGED_MAX_IT"
    assert result.iterations == 3


def test_inverting_load_is_never_reported_converged():
    body = soft_beam(snede.NeoHookean(30.0, 0.3))  # absurdly soft: gravity folds it
    body.add_gravity((0.0, 0.0, -9.81e3))
    result = snede.StaticSolver(body, "ncg", rtol=1e-8, max_iterations=200, options_prefix="invert_").solve()
    if result.converged:
        assert len(body.inverted_elements(body.displacement)) == 0
        assert np.all(np.isfinite(body.displacement))
    else:
        assert result.reason.startswith("DIVERGED")


def test_command_line_options_reach_the_solver():
    script = (
        "import numpy as np, snede\n"
        "import sys; sys.path.insert(0, 'tests/python/solve')\n"
        "from solve_scenes import soft_beam\n"
        "r = snede.StaticSolver(soft_beam(), 'newton', rtol=1e-6).solve()\n"
        "print('RESULT', r.converged, r.iterations)\n"
    )
    out = subprocess.run([sys.executable, "-c", script, "-static_snes_monitor", "-static_snes_max_it", "2"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "SNES Function norm" in out.stdout
    assert "RESULT False 2" in out.stdout


@pytest.mark.parametrize("line_search", ["snede_secant", "snede_newton"])
def test_line_search_halves_a_step_into_inverted_elements(line_search):
    """One edge shortened to 1/1000: a full secant step inverts its elements; the line search
    must shorten the step instead of failing (it used to stop at iteration 0)."""
    mesh = snede.meshing.box((0.1, 0.02, 0.02), (10, 2, 2))
    points = mesh.points.copy()
    at = lambda x, y, z: np.flatnonzero(np.all(np.isclose(points, (x, y, z)), axis=1))[0]  # noqa: E731
    moved, anchor = at(0.05, 0.01, 0.01), at(0.06, 0.01, 0.01)
    points[moved] = points[anchor] + 1e-3 * (points[moved] - points[anchor])
    mesh = snede.Mesh(points, mesh.cells)
    assert mesh.quality().aspect_ratio.min() < 1e-3
    body = snede.Body(mesh, snede.NeoHookean(3e4, 0.3))
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    result = snede.StaticSolver(body, "ncg", rtol=1e-3, line_search=line_search, max_iterations=50000,
                                options_prefix=f"halve_{line_search}_").solve()
    assert result.converged, result
    assert len(body.inverted_elements(body.displacement)) == 0


def test_converged_requires_the_criterion_at_the_final_state():
    """Newton with PETSc's cp line search and its own absolute tolerance (snede sets it to 0):
    cp declares CONVERGED_FNORM_ABS once the slope F·y is below it, while the residual
    recomputed at the final state is far above the tolerance. snede must not call that
    converged; with snede's default the same solve reaches the criterion. (At PETSc's default
    1e-15 snede's stall check now hands over to full Newton steps before cp's claim, and those
    meet the criterion honestly; 1e-12 still provokes the claim.)"""
    body = soft_beam()
    result = snede.StaticSolver(body, "newton", rtol=1e-12, criterion="6.8", options_prefix="cp_atol_",
                                petsc_options={"snes_linesearch_type": "cp", "snes_linesearch_atol": 1e-12}).solve()
    assert not result.converged
    assert result.reason.startswith("DIVERGED_RESIDUAL_ABOVE_TOLERANCE")
    assert result.residual_norm > 2 * result.tolerance
    body = soft_beam()
    result = snede.StaticSolver(body, "newton", rtol=1e-12, criterion="6.8", options_prefix="cp_default_",
                                petsc_options={"snes_linesearch_type": "cp"}).solve()
    assert result.converged and result.residual_norm <= result.tolerance, result


@pytest.mark.parametrize("young", [1e2, 1e9])
def test_newton_reaches_tight_tolerances_past_energy_round_off(young):
    """Near the solution a Newton step's energy decrease is below Π's round-off and the
    energy backtracking stops (DIVERGED_LINE_SEARCH); snede finishes with full Newton steps,
    so a reference solution to ‖r‖ ≤ 1e-8‖f‖ is reachable at any stiffness scale."""
    body, tip = cantilever((16, 4, 4), snede.NeoHookean(young, 0.3))
    body.clear_loads()
    body.add_nodal_force(tip, (0.0, -3e-4 * young / len(tip), 0.0))  # the same strain for every E
    result = snede.StaticSolver(body, "newton", rtol=1e-8, criterion="6.8", options_prefix=f"roundoff_{young:g}_").solve()
    assert result.converged, result
    assert result.residual_norm <= result.tolerance


@pytest.mark.parametrize("method", ["ncg", "newton"])
def test_a_solver_continues_after_the_mesh_is_refined_and_agrees_with_a_new_one(method):
    mesh = snede.meshing.rectangle((0.1, 0.1), (8, 8))
    body = snede.Body(mesh, snede.NeoHookean(34e3, 0.3), thickness=0.01)
    body.fix(np.isclose(mesh.points[:, 0], 0.1))
    body.add_nodal_force([0], [[0.01, 0.0]])
    solver = snede.StaticSolver(body, method, rtol=1e-8)
    assert solver.solve().converged
    body.refine_around((0.03, 0.05), 0.1 / 2**5)
    continued = solver.solve()
    assert continued.converged, continued
    fresh = snede.StaticSolver(body, method, rtol=1e-8).solve()
    assert fresh.energy == pytest.approx(continued.energy, rel=1e-8)
