"""A needle into a mesh made by gmsh, with no bisection history, from outside the body (issue 33):
where the shaft meets the surface, the default preconditioner on the locally refined mesh, and
the same insertion as without a preconditioner."""
import numpy as np
import pytest

import snede


@pytest.fixture(scope="module")
def cylinder():
    # Its axis along x from 0 to 0.1: the end face x = 0 is planar.
    return snede.meshing.cylinder(length=0.1, radius=0.02, h=0.006, seed=3)


def needle_into(cylinder, entry, **options):
    mesh = snede.Mesh(cylinder.points, cylinder.cells)
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3))
    body.fix(np.isclose(mesh.points[:, 0], 0.1))
    needle = snede.NeedleInsertion(body, entry, (1.0, 0.0, 0.0), snede.FrictionProfile.uniform(50.0), radius=1e-3,
                                   h_ref=0.004, rtol=1e-8, **options)
    return body, needle


def test_a_needle_from_outside_reaches_the_surface_and_inserts_with_the_default_preconditioner(cylinder):
    body, needle = needle_into(cylinder, (-0.01, 0.001, 0.002))
    assert needle.surface_depth == pytest.approx(0.01, abs=1e-12)  # the end face x = 0
    reports = [needle.advance(needle.surface_depth)] + [needle.advance(0.004) for _ in range(4)]
    assert all(report.converged for report in reports)
    assert len(needle.needle_nodes) > 0 and body.mesh.n_cells > cylinder.n_cells
    # Refined along the shaft, the gmsh mesh is the root of a bisection hierarchy; its coarsest
    # level would be the gmsh mesh itself: the default takes grid levels, much coarser.
    assert needle.multigrid_source == "grid"
    coarse, fine = needle.multigrid_unknowns[0], needle.multigrid_unknowns[-1]
    assert coarse * 8 <= fine
    assert needle.preconditioner_fills > 0
    plain_body, plain = needle_into(cylinder, (-0.01, 0.001, 0.002), petsc_options={"pc_type": "none"})
    for distance in [plain.surface_depth] + [0.004] * 4:
        assert plain.advance(distance).converged
    assert plain_body.mesh.n_cells == body.mesh.n_cells
    assert np.linalg.norm(body.displacement - plain_body.displacement) <= 1e-5 * np.linalg.norm(plain_body.displacement)


def test_the_surface_depth_is_zero_from_inside_and_a_line_that_misses_is_refused(cylinder):
    _, inside = needle_into(cylinder, (0.02, 0.001, 0.002))
    assert inside.surface_depth == 0.0
    with pytest.raises(ValueError, match="never meets the body"):
        needle_into(cylinder, (-0.01, 0.05, 0.0))


@pytest.mark.parametrize("coarsening", [None, "bisection"])
def test_the_needle_takes_grid_levels_unless_told_otherwise(coarsening):
    # Its refinement changes the mesh at nearly every update: grid levels are rebuilt more
    # cheaply than bisection levels (studies/benchmarks/needle3d_rates.py --haptic).
    # 768 cells, past "auto"'s 1000 after the first refinement (which splits only what the
    # shaft's tube meets).
    mesh = snede.meshing.box((0.1, 0.1, 0.1), (2, 2, 2))
    mesh.refine_uniform(4)
    body = snede.Body(mesh, snede.LinearElastic(34e3, 0.34))
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    options = {"mg_coarsening": coarsening} if coarsening else {}
    needle = snede.NeedleInsertion(body, (-0.005, 0.0513, 0.0489), (1.0, 0.0, 0.0),
                                   snede.FrictionProfile.figure_6_4(), radius=1e-3, h_ref=0.1 / 16, petsc_options=options)
    for _ in range(3):
        assert needle.advance(0.01).converged
    assert needle.multigrid_source == (coarsening or "grid")
    # Grid levels after a refinement are made from the earlier ones (issue 49); bisection
    # levels are made anew.
    if coarsening is None:
        assert 0 < needle.multigrid_edits < needle.multigrid_builds
    else:
        assert needle.multigrid_edits == 0


def test_stick_slip_changes_refill_the_levels_instead_of_making_new_ones(cylinder):
    # Without refinement the mesh stays the same: each rearrangement changes constraints only,
    # and the Galerkin levels keep their interpolation (refilled at the new state) until they
    # show their age. The insertion is the one without a preconditioner.
    def insertion(options):
        mesh = snede.Mesh(cylinder.points, cylinder.cells)
        body = snede.Body(mesh, snede.NeoHookean(1e4, 0.3))
        body.fix(np.isclose(mesh.points[:, 0], 0.1))
        needle = snede.NeedleInsertion(body, (-0.01, 0.001, 0.002), (1.0, 0.0, 0.0), snede.FrictionProfile.uniform(200.0),
                                       radius=1e-3, method="newton", rtol=1e-8, petsc_options=options)
        reports = [needle.advance(needle.surface_depth)] + [needle.advance(0.005) for _ in range(8)]
        assert all(report.converged for report in reports)
        return body, needle, sum(report.rearrangements for report in reports)

    body, needle, solves = insertion({})
    plain_body, _, _ = insertion({"pc_type": "none"})
    assert needle.multigrid_source == "grid"
    assert solves >= 20 and needle.multigrid_builds <= solves // 4
    assert np.linalg.norm(body.displacement - plain_body.displacement) <= 1e-5 * np.linalg.norm(plain_body.displacement)
