"""Multigrid for any mesh (preconditioner "mg" without a usable bisection hierarchy, issue 31):
a background grid with virtual nodes (the default) or aggregation.

Checked against independent facts: the interpolation's range holds the body's rigid motions as
the constraints allow them (what a coarse space must carry for elasticity; aggregation's columns
are moreover orthonormal); separated pieces share no coarse unknown, so one V-cycle applied to
a load on one piece leaves the other exactly still; every preconditioned solve reaches the
unpreconditioned answer, on meshes made by gmsh and after random sequences of cuts, flips,
collapses, splits and refinements, in fewer iterations; misuse raises ValueError naming it."""
import numpy as np
import pytest

import snede
from solve_scenes import as_dense, relative_difference
from solve_scenes import solve_from_rest as solve


def held_body(mesh, material=None, thickness=None):
    body = snede.Body(mesh, material or snede.LinearElastic(1e5, 0.3), density=1000.0, thickness=thickness)
    x = mesh.points
    body.fix(np.isclose(x[:, 0], x[:, 0].min()))
    body.add_gravity((0.0, -9.81) if mesh.dim == 2 else (0.0, 0.0, -9.81))
    return body


def rigid_modes(points):
    """(n_points · dim, 3 or 6) translations and rotations about the origin."""
    n, dim = points.shape
    modes = []
    for k in range(dim):
        mode = np.zeros((n, dim))
        mode[:, k] = 1.0
        modes.append(mode.ravel())
    rotations = [(0, 1)] if dim == 2 else [(1, 2), (2, 0), (0, 1)]
    for i, j in rotations:
        mode = np.zeros((n, dim))
        mode[:, i], mode[:, j] = -points[:, j], points[:, i]
        modes.append(mode.ravel())
    return np.array(modes).T


@pytest.fixture(scope="module")
def gmsh_cylinder():
    return snede.meshing.cylinder(length=0.1, radius=0.02, h=0.006, seed=3)


COARSENINGS = ["grid", "aggregation"]


@pytest.mark.parametrize("coarsening", COARSENINGS)
@pytest.mark.parametrize("dim", [2, 3])
def test_a_mesh_without_bisection_history_gets_levels_and_the_plain_answer(dim, coarsening, gmsh_cylinder):
    mesh = snede.meshing.rectangle((0.4, 0.1), (40, 10)) if dim == 2 else gmsh_cylinder
    body = held_body(mesh, thickness=0.01 if dim == 2 else None)
    options = {} if coarsening == "grid" else {"mg_coarsening": coarsening}  # grid: the default
    solver, result, u = solve(body, preconditioner="mg", petsc_options=options)
    assert result.converged, result.reason
    assert solver.multigrid_source == coarsening
    unknowns = solver.multigrid_unknowns
    assert unknowns[-1] == body.displacement.size and unknowns == sorted(unknowns) and len(unknowns) >= 2
    _, plain, reference = solve(body)
    assert plain.converged
    assert relative_difference(u, reference) < 1e-6
    assert result.iterations < plain.iterations / 3, (result.iterations, plain.iterations)


def test_newton_on_a_gmsh_mesh_reaches_the_plain_answer(gmsh_cylinder):
    body = held_body(gmsh_cylinder, snede.NeoHookean(2e4, 0.4))
    _, plain, reference = solve(body, "newton", rtol=1e-9)
    solver, result, u = solve(body, "newton", rtol=1e-9, preconditioner="mg")
    assert plain.converged and result.converged, (plain.reason, result.reason)
    assert np.abs(reference).max() > 1e-3  # a large deflection: the state matters
    assert relative_difference(u, reference) < 1e-6
    assert result.linear_iterations < plain.linear_iterations / 3


@pytest.mark.parametrize("coarsening", COARSENINGS)
@pytest.mark.parametrize("dim", [2, 3])
def test_interpolation_carries_the_allowed_rigid_motions(dim, coarsening, gmsh_cylinder):
    mesh = snede.meshing.rectangle((0.4, 0.1), (16, 4)) if dim == 2 else gmsh_cylinder
    body = held_body(mesh, thickness=0.01 if dim == 2 else None)
    x = mesh.points
    body.slide(np.flatnonzero(np.isclose(x[:, 0], x[:, 0].max())), (0.0, 1.0) if dim == 2 else (0.0, 0.0, 1.0))
    solver = snede.StaticSolver(body, "cg", preconditioner="mg", petsc_options={"mg_coarsening": coarsening,
                                                                                "pc_mg_levels": 2})
    pc = solver.ksp.getPC()
    P = as_dense(pc.getMGInterpolation(pc.getMGLevels() - 1))
    assert P.shape == (body.displacement.size, solver.multigrid_unknowns[-2])
    assert np.linalg.matrix_rank(P) == P.shape[1]  # no dependent (or empty) coarse unknown
    if coarsening == "aggregation":
        np.testing.assert_allclose(P.T @ P, np.eye(P.shape[1]), atol=1e-12)
    # The rigid motions, projected vertex by vertex on what the constraints allow (fixed: no
    # motion, sliding: along the direction), lie in the coarse space: P Pᵀ m = m.
    modes = rigid_modes(x - x.mean(axis=0))
    fixed = np.isclose(x[:, 0], x[:, 0].min())
    sliding = np.isclose(x[:, 0], x[:, 0].max())
    direction = np.zeros(dim)
    direction[-1] = 1.0
    projection = np.tile(np.eye(dim), (len(x), 1, 1))
    projection[fixed] = 0.0
    projection[sliding] = np.outer(direction, direction)
    for mode in modes.T:
        allowed = np.einsum("nij,nj->ni", projection, mode.reshape(-1, dim)).ravel()
        coefficients = np.linalg.lstsq(P, allowed, rcond=None)[0]
        np.testing.assert_allclose(P @ coefficients, allowed, atol=1e-9 * np.abs(allowed).max())


def two_pieces():
    """A box cut in two through x = 0.5 (§7.3 dissection), each half fixed at its far end; the
    vertex masks of the two halves."""
    mesh = snede.meshing.box((1.0, 0.3, 0.3), (10, 3, 3))
    pairs = mesh.dissect(mesh.faces_where(lambda c: np.isclose(c[:, 0], 0.5)))
    assert len(pairs) > 0
    count, labels = mesh.connected_components()
    assert count == 2
    cells = mesh.cells
    left = np.zeros(mesh.n_points, dtype=bool)
    left[np.unique(cells[labels == labels[np.argmin(mesh.points[cells[:, 0], 0])]])] = True
    right = np.zeros(mesh.n_points, dtype=bool)
    right[np.unique(cells)] = True
    right &= ~left
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3))
    x = mesh.points
    body.fix(np.isclose(x[:, 0], 0.0) | np.isclose(x[:, 0], 1.0))
    return body, left, right


@pytest.mark.parametrize("options", [{"mg_coarsening": "grid"}, {"mg_coarsening": "aggregation"},
                                     {"mg_coarsening": "aggregation", "mg_aggregation_smoothing": "true"}])
def test_separated_pieces_share_no_coarse_unknown(options):
    body, left, right = two_pieces()
    x = body.mesh.points
    loaded = np.flatnonzero(left & np.isclose(x[:, 0], 0.5))
    body.add_nodal_force(loaded, (0.0, 0.0, -1.0))
    solver, result, u = solve(body, preconditioner="mg", petsc_options=options)
    assert result.converged, result.reason
    assert np.abs(u[left]).max() > 0
    assert not u[right].any()  # the solution: the unloaded piece does not move
    pc = solver.ksp.getPC()
    for level in range(1, pc.getMGLevels()):
        P = as_dense(pc.getMGInterpolation(level))
        if level == pc.getMGLevels() - 1:
            rows_left = np.repeat(left, 3)
            rows_right = np.repeat(right, 3)
            touches_left = np.abs(P[rows_left]).sum(axis=0) > 0
            touches_right = np.abs(P[rows_right]).sum(axis=0) > 0
            assert touches_left.any() and touches_right.any()
            assert not (touches_left & touches_right).any()  # no coarse function spans the cut
    # One V-cycle applied to a load on the left piece leaves the right one exactly still.
    b, y = solver.ksp.getOperators()[0].createVecs()
    load = np.zeros_like(u)
    load[left] = np.random.default_rng(1).standard_normal((left.sum(), 3))
    load[np.isclose(x[:, 0], 0.0)] = 0.0
    b.setArray(load.ravel())
    pc.apply(b, y)
    correction = y.getArray().reshape(-1, 3)
    assert np.abs(correction[left]).max() > 0
    assert not correction[right].any()


def random_edit(mesh, rng):
    """One random local edit of the mesh (flip, split, collapse or refinement); whether it was done."""
    cells = mesh.cells
    cell = cells[rng.integers(len(cells))]
    a, b = rng.choice(cell, 2, replace=False)
    kind = rng.integers(4)
    try:
        if kind == 0:
            result = mesh.flip_edge(int(a), int(b))
        elif kind == 1:
            result = mesh.split_edge(int(a), int(b), 0.5)
        elif kind == 2:
            result = mesh.collapse_edge(int(a), int(b), 0.5)
        else:
            return mesh.refine_around(mesh.points[a], 0.5 * np.linalg.norm(mesh.points[a] - mesh.points[b])) > 0
    except ValueError:
        return False
    return result.done


def assert_mg_keeps_the_plain_answer(solver, body, coarsening, step, fraction):
    """After an edit: the solver's mg solve from rest converges on levels of `coarsening`, equals
    the unpreconditioned solve to 1e-6 and takes under `fraction` of its CG iterations."""
    body.mesh.validate()
    body.displacement = np.zeros_like(body.displacement)
    result = solver.solve()
    assert result.converged, (step, result.reason)
    assert solver.multigrid_source == coarsening
    u = body.displacement.copy()
    _, plain, reference = solve(body)
    assert plain.converged
    assert relative_difference(u, reference) < 1e-6, step
    assert result.iterations < fraction * plain.iterations, (step, result.iterations, plain.iterations)


@pytest.mark.parametrize("coarsening", COARSENINGS)
def test_random_edits_and_cuts_keep_the_plain_answer_in_bounded_iterations(coarsening, gmsh_cylinder):
    rng = np.random.default_rng(7)
    mesh = snede.Mesh(gmsh_cylinder.points, gmsh_cylinder.cells)
    body = held_body(mesh)
    solver = snede.StaticSolver(body, "cg", rtol=1e-8, preconditioner="mg", petsc_options={"mg_coarsening": coarsening})
    cutter = snede.TetrahedralCutter(body)
    edits = 0
    for step in range(8):
        if step % 2:
            x = 0.02 + 0.06 * rng.random()
            y = -0.03 + 0.03 * rng.random()
            cutter.lift()
            cutter.move([(x, y, -0.03), (x, y, 0.03)])
            cutter.move([(x + 0.002, y + 0.02, -0.03), (x + 0.002, y + 0.02, 0.03)])
        else:
            edits += sum(random_edit(mesh, rng) for _ in range(5))
        # The edits make the problem harder (plain CG: 363 → 797 iterations here); multigrid
        # keeps its advantage at every step (measured 1/17 to 1/14).
        assert_mg_keeps_the_plain_answer(solver, body, coarsening, step, 1 / 8)
    assert edits > 0


def test_mg_continues_through_a_cut_of_a_bisected_mesh():
    # Bisection levels before the cut; the cut takes elements out of the refinement tree, and
    # the next solve coarsens on a grid instead of refusing.
    mesh = snede.meshing.box((0.4, 0.1, 0.1), (4, 1, 1))
    mesh.refine_uniform(6)
    body = held_body(mesh)
    solver, first, _ = solve(body, preconditioner="mg")
    assert first.converged and solver.multigrid_source == "bisection"
    body.displacement = np.zeros_like(body.displacement)  # the blade is placed in the reference
    cutter = snede.TetrahedralCutter(body)
    report = cutter.cut_triangle([[0.2, -0.5, 0.6], [0.2, 0.6, 0.6], [0.2, 0.05, 0.05]])
    assert report.faces_dissected > 0
    body.displacement = np.zeros_like(body.displacement)
    result = solver.solve()
    assert result.converged, result.reason
    assert solver.multigrid_source == "grid"
    u = body.displacement.copy()
    _, plain, reference = solve(body)
    assert relative_difference(u, reference) < 1e-6
    assert result.iterations < plain.iterations / 3


def test_the_grid_width_set_on_a_bisected_mesh_applies_to_the_grid_levels_after_a_cut():
    """With "auto", grid levels take over from bisection levels after the first cut: their width
    may be set from the start (and is checked at once); a narrower grid has more coarse unknowns."""
    coarse_unknowns = {}
    for width in (2.0, 4.0):
        mesh = snede.meshing.box((0.4, 0.1, 0.1), (4, 1, 1))
        mesh.refine_uniform(6)
        body = held_body(mesh)
        solver, first, _ = solve(body, preconditioner="mg", petsc_options={"mg_grid_width": width})
        assert first.converged and solver.multigrid_source == "bisection"
        body.displacement = np.zeros_like(body.displacement)
        snede.TetrahedralCutter(body).cut_triangle([[0.2, -0.5, 0.6], [0.2, 0.6, 0.6], [0.2, 0.05, 0.05]])
        body.displacement = np.zeros_like(body.displacement)
        assert solver.solve().converged
        assert solver.multigrid_source == "grid"
        coarse_unknowns[width] = solver.multigrid_unknowns[0]
    assert coarse_unknowns[2.0] > 2 * coarse_unknowns[4.0], coarse_unknowns
    mesh = snede.meshing.box((0.4, 0.1, 0.1), (4, 1, 1))
    mesh.refine_uniform(6)
    with pytest.raises(ValueError, match="mg_grid_width must be at least 1"):
        snede.StaticSolver(held_body(mesh), "cg", preconditioner="mg", petsc_options={"mg_grid_width": -1})
    with pytest.raises(ValueError, match="mg_grid_width applies to grid levels; these are bisection"):
        snede.StaticSolver(held_body(mesh), "cg", preconditioner="mg",
                           petsc_options={"mg_coarsening": "bisection", "mg_grid_width": 2})


@pytest.mark.parametrize("options", [{"mg_coarsening": "aggregation", "mg_aggregation_smoothing": "true"},
                                     {"mg_coarsening": "aggregation", "mg_aggregate_width": 4.0},
                                     {"mg_grid_width": 2.0}])
def test_smoothed_or_wider_aggregates_reach_the_plain_answer(options, gmsh_cylinder):
    body = held_body(gmsh_cylinder)
    solver, result, u = solve(body, preconditioner="mg", petsc_options=options)
    _, plain, reference = solve(body)
    assert result.converged and plain.converged
    assert relative_difference(u, reference) < 1e-6
    assert result.iterations < plain.iterations / 3
    # Fixed vertices stay fixed under every coarse correction: their rows of P are zero.
    P = as_dense(solver.ksp.getPC().getMGInterpolation(solver.ksp.getPC().getMGLevels() - 1))
    fixed = np.repeat(np.isclose(gmsh_cylinder.points[:, 0], 0.0), 3)
    assert fixed.any() and not P[fixed].any()


def test_auto_takes_multigrid_where_it_pays():
    def body_of(divisions):
        return held_body(snede.meshing.box((0.4, 0.1, 0.1), divisions))
    small, large = body_of((8, 2, 2)), body_of((16, 4, 4))
    assert small.mesh.n_cells < 1000 <= large.mesh.n_cells
    assert snede.StaticSolver(small, "cg").preconditioner == "none"
    assert snede.StaticSolver(large, "cg").preconditioner == "mg"
    assert snede.StaticSolver(large, "newton", preconditioner="auto").preconditioner == "mg"
    assert snede.StaticSolver(large, "ncg").preconditioner == "none"
    surface, _ = snede.meshing.boundary_surface(snede.meshing.box((0.4, 0.1, 0.1), (24, 6, 6)))
    assert surface.n_cells >= 1000
    membrane = snede.Body(surface, snede.NeoHookean(1e5, 0.3), thickness=0.001)
    assert snede.StaticSolver(membrane, "newton").preconditioner == "mg"
    small_membrane = snede.Body(snede.meshing.boundary_surface(snede.meshing.box((0.4, 0.1, 0.1), (8, 2, 2)))[0],
                                snede.NeoHookean(1e5, 0.3), thickness=0.001)
    assert small_membrane.mesh.n_cells < 1000
    assert snede.StaticSolver(small_membrane, "newton").preconditioner == "none"


@pytest.mark.parametrize("method", ["cg", "newton"])
def test_auto_chooses_again_when_the_mesh_grows_past_where_multigrid_pays(method):
    # A needle refines a mesh of a few hundred cells to tens of thousands: "auto" chose no
    # preconditioner for the first and must not keep that choice for the second.
    material = snede.LinearElastic(1e5, 0.3) if method == "cg" else snede.NeoHookean(1e5, 0.3)
    mesh = snede.meshing.box((0.4, 0.1, 0.1), (4, 1, 1))
    body = held_body(mesh, material)
    solver = snede.StaticSolver(body, method, rtol=1e-8)
    assert solver.preconditioner == "none" and solver.solve().converged
    mesh.refine_uniform(6)
    assert mesh.n_cells >= 1000
    result = solver.solve()
    assert result.converged
    assert solver.preconditioner == "mg" and solver.multigrid_source == "bisection"
    u = body.displacement.copy()
    assert relative_difference(u, solve(body, method)[2]) < 1e-6


def test_bad_coarsening_options_are_refused_naming_them(gmsh_cylinder):
    body = held_body(gmsh_cylinder)
    with pytest.raises(ValueError, match="mg_coarsening must be auto, bisection, aggregation or grid, got 'tree'"):
        snede.StaticSolver(body, "cg", preconditioner="mg", petsc_options={"mg_coarsening": "tree"})
    with pytest.raises(ValueError, match="no bisection hierarchy"):
        snede.StaticSolver(body, "cg", preconditioner="mg", petsc_options={"mg_coarsening": "bisection"})
    aggregation = {"mg_coarsening": "aggregation"}
    for options, message in (({**aggregation, "mg_aggregation_smoothing": "maybe"},
                              "mg_aggregation_smoothing must be true or false"),
                             ({**aggregation, "mg_aggregate_width": "wide"}, "mg_aggregate_width must be a number, got 'wide'"),
                             ({**aggregation, "mg_aggregate_width": -1}, "mg_aggregate_width must be positive"),
                             ({"mg_aggregate_width": 3}, "mg_aggregate_width applies to aggregation levels; these are grid"),
                             ({**aggregation, "mg_grid_width": 3}, "mg_grid_width applies to grid levels; these are aggregation"),
                             ({"mg_grid_width": 0}, "mg_grid_width must be at least 1"),
                             ({"mg_grid_width": 0.5}, "mg_grid_width must be at least 1"),
                             ({"mg_coarsening": "grid", "pc_mg_levels": 3}, "grid coarsening gives 2 levels")):
        with pytest.raises(ValueError, match=message):
            snede.StaticSolver(body, "cg", preconditioner="mg", petsc_options=options)
    with pytest.raises(ValueError, match="gives [0-9]+ levels"):
        snede.StaticSolver(body, "cg", preconditioner="mg", petsc_options={"pc_mg_levels": 12})


@pytest.mark.parametrize("coarsening", COARSENINGS)
def test_random_edits_and_delaunay_cuts_in_2d_keep_the_plain_answer(coarsening):
    rng = np.random.default_rng(11)
    mesh = snede.meshing.rectangle((0.4, 0.1), (40, 10))
    body = held_body(mesh, thickness=0.01)
    solver = snede.StaticSolver(body, "cg", rtol=1e-8, preconditioner="mg", petsc_options={"mg_coarsening": coarsening})
    cutter = snede.DelaunayCutter(body)
    edits = 0
    for step in range(6):
        if step % 2:
            x = 0.05 + 0.3 * rng.random()
            cutter.lift()
            cutter.cut([(x, -0.01), (x + 0.01, 0.04 + 0.03 * rng.random())])
        else:
            edits += sum(random_edit(mesh, rng) for _ in range(8))
        assert_mg_keeps_the_plain_answer(solver, body, coarsening, step, 1 / 4)
    assert edits > 0


def test_a_needle_into_a_gmsh_mesh_with_mg_gives_the_plain_insertion(gmsh_cylinder):
    # The needle's stick-slip changes constraints between solves and its refinement changes the
    # mesh: mg (grid levels: the cylinder has no bisection levels) follows both.
    def insertion(preconditioner):
        mesh = snede.Mesh(gmsh_cylinder.points, gmsh_cylinder.cells)
        body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3))
        body.fix(np.isclose(mesh.points[:, 0], 0.1))
        needle = snede.NeedleInsertion(body, (0.0, 0.001, 0.002), (1.0, 0.0, 0.0),
                                       snede.FrictionProfile.uniform(50.0), radius=1e-3, h_ref=0.004,
                                       rtol=1e-8, petsc_options={"pc_type": preconditioner})
        reports = [needle.advance(0.004) for _ in range(5)]
        return body, reports

    plain_body, plain = insertion("none")
    body, reports = insertion("mg")
    assert all(report.converged for report in plain + reports)
    assert body.mesh.n_cells == plain_body.mesh.n_cells > gmsh_cylinder.n_cells  # refined alike
    assert relative_difference(body.displacement, plain_body.displacement) < 1e-5


def test_auto_does_not_take_bisection_levels_whose_coarsest_is_the_file_mesh(gmsh_cylinder):
    # Refined locally (as a needle does), a mesh read from a file gets a bisection hierarchy whose
    # coarsest level is that mesh: a direct solve on it would cost more than the whole grid
    # levels. A mesh bisected from a small box keeps its bisection levels.
    mesh = snede.Mesh(gmsh_cylinder.points, gmsh_cylinder.cells)
    mesh.refine_around((0.05, 0.0, 0.0), 0.002)
    body = held_body(mesh)
    solver, result, _ = solve(body, preconditioner="mg")
    assert result.converged
    assert solver.multigrid_source == "grid"
    assert solver.multigrid_unknowns[0] <= max(1000, solver.multigrid_unknowns[-1] // 16)
    box = snede.meshing.box((0.1, 0.1, 0.1), (2, 2, 2))
    box.refine_uniform(2)
    box.refine_around((0.05, 0.05, 0.05), 0.01)
    assert solve(held_body(box), preconditioner="mg")[0].multigrid_source == "bisection"


def test_grid_levels_on_a_mesh_refined_along_a_line_stay_much_coarser_than_it():
    # A needle's refinement puts most edges in a thin tube: a grid sized by the mean edge length
    # (the old rule: 3 of them) had a fifth as many unknowns as the mesh; sized by the vertex
    # spacing, it has about as few per fine unknown as on a uniform mesh (4 spacings: a 64th of
    # the vertices), and the solve still reaches the plain answer.
    mesh = snede.meshing.box((0.1, 0.1, 0.1), (3, 3, 3))
    mesh.refine_uniform(2)
    mesh.refine_near_segment((0.0, 0.0513, 0.0489), (0.07, 0.0513, 0.0489), 0.1 / 64, 1e-3)
    uniform = snede.meshing.box((0.1, 0.1, 0.1), (3, 3, 3))
    uniform.refine_uniform(5)
    ratios = []
    for m in (mesh, uniform):
        body = held_body(m)
        solver, result, u = solve(body, preconditioner="mg", petsc_options={"mg_coarsening": "grid"})
        assert result.converged
        assert relative_difference(u, solve(body)[2]) < 1e-6
        ratios.append(solver.multigrid_unknowns[-1] / solver.multigrid_unknowns[0])
    assert ratios[0] >= 16 and ratios[1] >= 16
    assert 0.5 < ratios[0] / ratios[1] < 2
