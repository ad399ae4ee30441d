"""Dynamic relaxation through PETSc TS (§2.5, §4.1, §4.4.1): the update is SS22 with θ₁ = ½,
θ₂ = 0; it settles in the static solution; the stability limit is 2/√λ_max(M⁻¹K); blow-up,
options and mesh changes."""
import subprocess
import sys

import numpy as np
import pytest

import snede

E, NU, RHO = 3e3, 0.3, 1000.0
GRAVITY = (0.0, 0.0, -9.81)


def hanging_beam(material, divisions=(10, 3, 3)):
    """0.1 × 0.03 × 0.03 m beam fixed at x = 0 under gravity."""
    mesh = snede.meshing.box((0.1, 0.03, 0.03), divisions)
    body = snede.Body(mesh, material, density=RHO)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity(GRAVITY)
    return body


def free_dofs(body):
    """Dofs of the vertices that are not fixed at x = 0, flattened (n_points·dim,)."""
    return np.repeat(~np.isclose(body.mesh.points[:, 0], 0.0), body.dim)


def stiffness(body):
    """K = ∂²Π_int/∂u² at u = 0, assembled column by column from the tangent action."""
    n = body.mesh.n_points * body.dim
    zero = np.zeros((body.mesh.n_points, body.dim))
    K = np.empty((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = 1.0
        K[:, j] = body.tangent_apply(zero, e.reshape(zero.shape)).ravel()
    return K


def modal_eigenvalues(body):
    """Eigenvalues of M⁻¹K on the free dofs (lumped M), ascending."""
    free = free_dofs(body)
    K = stiffness(body)[np.ix_(free, free)]
    m = np.repeat(body.lumped_mass(), body.dim)[free]
    return np.linalg.eigvalsh(K / np.sqrt(np.outer(m, m)))


def linear_static_solution(body):
    """u* with K_ff u_f = f_f (fixed dofs at zero), and the smallest eigenvalue of K_ff."""
    free = free_dofs(body)
    K = stiffness(body)[np.ix_(free, free)]
    u = np.zeros(body.mesh.n_points * body.dim)
    u[free] = np.linalg.solve(K, body.external_forces().ravel()[free])
    return u.reshape(-1, body.dim), np.linalg.eigvalsh(K)[0]


def ss22_step(body, u, v, dt, eta, theta1=0.5):
    """One step of SS22 (2.56)–(2.60) with θ₂ = 0, lumped M, C = ηM and the net force
    f(ū) = f_int(ū) + f_ext on the free dofs, written out as in the thesis."""
    free = free_dofs(body).reshape(u.shape)
    m = body.lumped_mass()[:, None]
    u_bar = u + theta1 * dt * v                                        # (2.56), (2.57)
    force = np.where(free, body.internal_forces(u_bar) + body.external_forces(), 0.0)
    acceleration = (force - eta * m * v) / (m + theta1 * dt * eta * m)  # (2.58)
    return u + dt * v + 0.5 * dt**2 * acceleration, v + dt * acceleration  # (2.59), (2.60)


def test_update_is_ss22_with_theta1_half_step_by_step():
    body = hanging_beam(snede.NeoHookean(E, NU), divisions=(4, 2, 2))  # nonlinear forces
    eta = 15.0
    dynamics = snede.DynamicRelaxation(body, damping=eta, options_prefix="ss22_equivalence_")
    dt = dynamics.dt
    free = free_dofs(body).reshape(-1, 3)
    v = np.where(free, np.random.default_rng(3).normal(scale=0.05, size=free.shape), 0.0)
    u = np.zeros_like(v)
    # The TS state is SS22's weighted average ū = u + ½Δt u̇ and its velocity.
    body.displacement = u + 0.5 * dt * v
    dynamics.velocity = v
    for _ in range(60):
        assert dynamics.step(1).converged
        u, v = ss22_step(body, u, v, dt, eta)
        scale = np.abs(u).max()
        assert np.abs(body.displacement - (u + 0.5 * dt * v)).max() <= 1e-12 * scale
        assert np.abs(dynamics.velocity - v).max() <= 1e-12 * np.abs(v).max()
    # and the TS's displacement is not SS22's u itself: the comparison above can fail
    assert np.abs(body.displacement - u).max() > 1e-3 * scale


def test_linear_beam_relaxes_to_the_static_solution_within_the_tolerance():
    body = hanging_beam(snede.LinearElastic(E, NU))
    eta = 2 * np.sqrt(modal_eigenvalues(body)[0])  # §4.1: critical damping of the lowest mode
    result = snede.DynamicRelaxation(body, damping=eta, options_prefix="linear_beam_").run(rtol=1e-6)
    assert result.converged, result
    assert result.reason == "CONVERGED_FNORM_ABS"
    assert result.residual_norm <= result.tolerance
    assert result.iterations == len(result.residual_history) > 0
    u_static, k_min = linear_static_solution(body)
    # F(u) = K(u − u*) on the free dofs, so ‖u − u*‖ ≤ ‖F‖/λ_min(K_ff).
    error = np.linalg.norm(body.displacement - u_static)
    assert error <= result.residual_norm / k_min
    assert error <= 1e-4 * np.linalg.norm(u_static)
    assert np.all(body.displacement[np.isclose(body.mesh.points[:, 0], 0.0)] == 0.0)


def test_lowest_mode_critical_damping_relaxes_fastest():
    # §4.1: error components decay like e^{−ηt/2} unless overdamped; η = 2√λ₁ is optimal.
    body = hanging_beam(snede.LinearElastic(E, NU), divisions=(6, 2, 2))
    eta_opt = 2 * np.sqrt(modal_eigenvalues(body)[0])
    steps = {}
    for factor in (1 / 3, 1.0, 3.0):
        body.displacement = np.zeros((body.mesh.n_points, 3))
        result = snede.DynamicRelaxation(body, damping=factor * eta_opt, options_prefix="eta_").run(rtol=1e-6)
        assert result.converged, result
        steps[factor] = result.iterations
    assert steps[1.0] < steps[1 / 3] and steps[1.0] < steps[3.0]


def test_neo_hookean_beam_relaxes_to_newtons_equilibrium():
    body = hanging_beam(snede.NeoHookean(E, NU))
    result = snede.DynamicRelaxation(body, damping=12.0, options_prefix="neo_beam_").run(rtol=1e-5)
    assert result.converged, result
    assert result.residual_norm <= result.tolerance
    assert len(body.inverted_elements(body.displacement)) == 0
    reference = hanging_beam(snede.NeoHookean(E, NU))
    newton = snede.StaticSolver(reference, "newton", rtol=1e-10, options_prefix="neo_beam_ref_").solve()
    assert newton.converged, newton
    u_ref = reference.displacement
    assert -u_ref[:, 2].min() > 0.01  # a visible sag: a tenth of the length
    assert np.abs(body.displacement - u_ref).max() <= 1e-3 * np.abs(u_ref).max()
    assert result.energy == pytest.approx(newton.energy, rel=1e-6)


def test_critical_step_search_brackets_the_stability_limit_and_above_it_blows_up():
    body = hanging_beam(snede.LinearElastic(E, NU))
    dt_limit = 2 / np.sqrt(modal_eigenvalues(body)[-1])  # Δt ≤ 2/√λ_max (§4.1)
    dynamics = snede.DynamicRelaxation(body, damping=11.0, options_prefix="critical_")
    assert dynamics.cfl_time_step < dt_limit  # the default step is stable on this mesh
    u_before = body.displacement
    found = dynamics.critical_time_step()
    assert 0.85 * dt_limit < found <= 1.01 * dt_limit
    # a budget of one step is stretched to min_steps; ten steps let steps far above the limit pass
    assert dynamics.critical_time_step(flop_budget=1e3) == found
    assert dynamics.critical_time_step(flop_budget=1e3, min_steps=10) > 2 * dt_limit
    assert np.array_equal(body.displacement, u_before) and np.all(dynamics.velocity == 0)  # restored
    assert dynamics.dt == dynamics.cfl_time_step
    # The limit is sharp: 2 % below it an undamped run from rest oscillates about u* within
    # ‖u‖ ≤ 2‖u*‖ (energy conservation), 2 % above it blows up.
    u_static, _ = linear_static_solution(body)
    undamped = snede.DynamicRelaxation(body, damping=0.0, dt=0.98 * dt_limit, options_prefix="undamped_")
    peak = 0.0
    for _ in range(30):
        assert undamped.step(100).converged
        peak = max(peak, np.linalg.norm(body.displacement))
    assert 1.5 * np.linalg.norm(u_static) < peak <= 2.0 * np.linalg.norm(u_static)
    body.displacement = np.zeros_like(u_before)
    undamped.velocity = np.zeros_like(u_before)
    undamped.dt = 1.02 * dt_limit
    assert undamped.step(3000).reason == "DIVERGED_BLOW_UP"
    # 1.5 × critical: a result, not an exception or a hang
    body.displacement = np.zeros_like(u_before)
    dynamics.dt = 1.5 * found
    result = dynamics.run(rtol=1e-3, max_steps=100000)
    assert not result.converged
    assert result.reason == "DIVERGED_BLOW_UP"
    assert result.iterations < 200


def test_bad_arguments_are_rejected_with_their_values():
    body = hanging_beam(snede.LinearElastic(E, NU), divisions=(2, 1, 1))
    with pytest.raises(ValueError, match="-0.5"):
        snede.DynamicRelaxation(body, damping=-0.5)
    with pytest.raises(ValueError, match="nan"):
        snede.DynamicRelaxation(body, damping=float("nan"))
    for dt in (0.0, -1e-3, float("inf"), float("nan")):
        with pytest.raises(ValueError, match="dt"):
            snede.DynamicRelaxation(body, damping=1.0, dt=dt)
    dynamics = snede.DynamicRelaxation(body, damping=1.0, options_prefix="bad_")
    with pytest.raises(ValueError, match="dt"):
        dynamics.dt = -1.0
    with pytest.raises(ValueError, match="rtol"):
        dynamics.run(rtol=0.0)
    with pytest.raises(ValueError, match="velocity"):
        dynamics.velocity = np.zeros((3, 3))


def test_petsc_options_reach_the_ts():
    body = hanging_beam(snede.LinearElastic(E, NU), divisions=(4, 2, 2))
    dynamics = snede.DynamicRelaxation(body, damping=5.0, options_prefix="tuned_",
                                       petsc_options={"ts_max_steps": 7, "ts_dt": 1e-3, "ts_ss22_damping": 20})
    assert dynamics.ts.getType() == "snede_ss22" and dynamics.ts.getOptionsPrefix() == "tuned_"
    assert dynamics.dt == 1e-3 and dynamics.damping == 20.0
    assert dynamics.step(100).iterations == 7  # -tuned_ts_max_steps caps the total
    capped = dynamics.run(rtol=1e-9)
    assert not capped.converged and capped.reason == "DIVERGED_MAX_IT" and capped.iterations == 0
    with pytest.raises(ValueError, match="snede_ss22"):
        snede.DynamicRelaxation(body, damping=5.0, options_prefix="wrong_type_", petsc_options={"ts_type": "euler"})


def test_command_line_monitor_and_step_cap():
    script = (
        "import numpy as np, snede\n"
        "mesh = snede.meshing.box((0.1, 0.03, 0.03), (4, 2, 2))\n"
        "body = snede.Body(mesh, snede.LinearElastic(3e3, 0.3))\n"
        "body.fix(np.isclose(mesh.points[:, 0], 0.0)); body.add_gravity()\n"
        "r = snede.DynamicRelaxation(body, damping=10.0).run()\n"
        "print('RESULT', r.converged, r.reason, r.iterations)\n"
    )
    out = subprocess.run([sys.executable, "-c", script, "-dynamic_ts_monitor", "-dynamic_ts_max_steps", "3"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "3 TS dt" in out.stdout and "4 TS dt" not in out.stdout
    assert "RESULT False DIVERGED_MAX_IT 3" in out.stdout


def test_stepping_continues_after_a_cut_with_the_velocity_carried_over():
    body = hanging_beam(snede.LinearElastic(E, NU))
    dynamics = snede.DynamicRelaxation(body, damping=11.0, options_prefix="cut_dynamics_")
    assert dynamics.step(40).converged
    v_before, n_before, generation = dynamics.velocity, body.mesh.n_points, body._model.generation
    split = body.mesh.dissect(body.mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.05) & (x[:, 2] >= 0.01 - 1e-12)))
    assert len(split) > 0 and body._model.generation == generation + 1
    v_carried = dynamics.velocity
    assert v_carried.shape == (body.mesh.n_points, 3) and body.mesh.n_points > n_before
    assert np.array_equal(v_carried[:n_before], v_before)
    assert np.array_equal(v_carried[split[:, 1]], v_before[split[:, 0]])  # copies move with their originals
    result = dynamics.run(rtol=1e-6)
    assert result.converged, result
    assert dynamics.ts.getSolution().getSize() == body.mesh.n_points * 3
    u_static, k_min = linear_static_solution(body)  # the cut beam's own static solution
    assert np.linalg.norm(body.displacement - u_static) <= result.residual_norm / k_min
    assert body.displacement[:, 2].min() < 0


def test_inverting_load_is_never_reported_converged():
    body = hanging_beam(snede.NeoHookean(30.0, 0.3), divisions=(6, 2, 2))  # absurdly soft
    body.add_gravity((0.0, 0.0, -9.81e3))
    result = snede.DynamicRelaxation(body, damping=5.0, options_prefix="invert_dynamics_").run(max_steps=3000)
    if result.converged:
        assert len(body.inverted_elements(body.displacement)) == 0
    else:
        assert result.reason.startswith("DIVERGED")

