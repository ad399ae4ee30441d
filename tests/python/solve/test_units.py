"""Convergence is never reported at overflow and does not depend on the units (issue 14)."""
import numpy as np
import pytest

import snede
from solve_scenes import sagging_sheet


# Every method runs on the system divided by the force scale (before, ncg and newton failed
# from E = 1e150 on: DIVERGED_LINE_SEARCH, DIVERGED_LINEAR_SOLVE). Below E = 1e-150 linear CG
# said CONVERGED after 0 iterations with u = 0: PETSc's norm of the forces (1e-158 N and less)
# underflowed to 0 and was cached through the right-hand side (issue 38 item 4).
@pytest.mark.parametrize("method", ["cg", "ncg", "newton"])
def test_the_displacement_does_not_depend_on_the_units_from_1e_minus300_to_1e160(method):
    reference = sagging_sheet(1e5)
    assert snede.StaticSolver(reference, "cg", rtol=1e-10).solve().converged
    for young in (1e-300, 1e-200, 1e-160, 1e-3, 1.0, 1e150, 1e155, 1e160):
        body = sagging_sheet(young)
        result = snede.StaticSolver(body, method, rtol=1e-10).solve()
        assert result.converged and np.isfinite(result.tolerance), (young, result)
        np.testing.assert_allclose(body.displacement, reference.displacement, rtol=1e-7,
                                   atol=1e-9 * np.abs(reference.displacement).max())


@pytest.mark.parametrize("method", ["cg", "ncg", "newton", "dynamic"])
def test_loads_beyond_double_range_are_never_converged(method):
    body = sagging_sheet(1e5)
    body.add_gravity((0.0, -1e300))
    if method == "dynamic":
        result = snede.DynamicRelaxation(body, 20.0).run(rtol=1e-6, max_steps=200)
    else:
        result = snede.StaticSolver(body, method, rtol=1e-6).solve()
    assert not result.converged


# 2D plane stress: the neo-Hookean thickness stretch squared λ (overflow from E = 1e155,
# DIVERGED_NONFINITE_STATE; underflow below 1e-160, a converged but wrong state).
@pytest.mark.parametrize("material", [snede.NeoHookean, snede.StVenantKirchhoff,
                                      lambda E, nu: snede.VerondaWestmann(E, nu, gamma=8.0)])
@pytest.mark.parametrize("method", ["ncg", "newton"])
def test_nonlinear_plane_stress_does_not_depend_on_the_units_from_1e_minus300_to_1e160(material, method):
    reference = sagging_sheet(1e5, material)
    assert snede.StaticSolver(reference, "newton", rtol=1e-10).solve().converged
    for young in (1e-300, 1e-200, 1e155, 1e160):
        body = sagging_sheet(young, material)
        result = snede.StaticSolver(body, method, rtol=1e-10).solve()
        assert result.converged, (young, result)
        np.testing.assert_allclose(body.displacement, reference.displacement, rtol=1e-7,
                                   atol=1e-8 * np.abs(reference.displacement).max())


def test_dynamic_relaxation_reaches_the_same_displacement_whatever_the_units():
    reference = sagging_sheet(1e5)
    assert snede.StaticSolver(reference, "cg", rtol=1e-10).solve().converged
    # 1e-200: the 2D wave speed's μ(λ + μ) underflowed to 0, the CFL step was inf (issue 38 item 4).
    for young in (1e-200, 1e-3, 1e5, 1e150):
        body = sagging_sheet(young)
        dynamics = snede.DynamicRelaxation(body, 2.0 * np.sqrt(young / 1e5) * 20.0)
        result = dynamics.run(rtol=1e-8, max_steps=200000)
        assert result.converged and np.isfinite(result.residual_norm), (young, result)
        np.testing.assert_allclose(body.displacement, reference.displacement, rtol=1e-5,
                                   atol=1e-6 * np.abs(reference.displacement).max())
