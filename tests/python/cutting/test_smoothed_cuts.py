"""The cutters on smoothed bodies (issue 35): the operators keep their invariants after every
move, the pieces a cut makes do not pull on each other, and solves agree for every
preconditioner."""
import numpy as np
import pytest

import snede
from smoothed_checks import (check_affine_state_carried, check_invariants, distorted_grid, min_altitude, p1_twin,
                             smoothed_body)
from snede.subdivision_cutting import SubdivisionCutter

pytestmark = pytest.mark.filterwarnings("ignore::snede.LockingWarning")  # the P1 twins at ν ≥ 0.45


def pieces_do_not_pull_on_each_other(body):
    """A random displacement of one piece leaves the vertices of the others without force."""
    mesh = body.mesh
    count, labels = mesh.connected_components()
    assert count >= 2
    vertex_piece = np.full(mesh.n_points, -1)
    vertex_piece[mesh.cells.ravel()] = np.repeat(labels, mesh.cells.shape[1])
    for piece in range(count):
        u = np.zeros((mesh.n_points, body.dim))
        mine = vertex_piece == piece
        u[mine] = 1e-3 * min_altitude(mesh) * np.random.default_rng(piece).standard_normal((mine.sum(), body.dim))
        f = body.internal_forces(u)
        assert np.abs(f[mine]).max() > 0
        assert np.abs(f[(vertex_piece >= 0) & ~mine]).max() == 0.0, piece


def solve_with_every_preconditioner(body, rtol=1e-8):
    """From the body's state, a Newton solve per preconditioner; all converge, to the same
    displacement as without one. Leaves the body at that displacement."""
    start = body.displacement
    answers = {}
    for preconditioner in ("none", "mg", "gamg", "jacobi"):
        body.displacement = start
        result = snede.StaticSolver(body, "newton", rtol=rtol, preconditioner=preconditioner).solve()
        assert result.converged, (preconditioner, result)
        answers[preconditioner] = body.displacement
    reference = answers["none"]
    for preconditioner, u in answers.items():
        assert np.abs(u - reference).max() <= 1e-6 * np.abs(reference).max(), preconditioner
    body.displacement = reference
    return reference


def test_tetrahedral_cutter_on_a_hanging_smoothed_body():
    """A box held at its bottom sags under gravity, then the scalpel (in deformed space) cuts it
    through: invariants after every move, two pieces that no patch joins, and solves that
    agree for every preconditioner."""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (5, 5, 5))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.49), density=10.0)
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "newton", rtol=1e-8).solve().converged
    cutter = snede.TetrahedralCutter(body)
    for step, y in enumerate((-0.5, 0.3, 0.7, 1.5)):
        report = cutter.move(np.array([[0.43, y, -1.0], [0.43, y, 2.0]]))
        mesh.validate()
        check_invariants(body, step, f"move {step}: {report}")
    assert report.components == 2
    assert len(cutter.incision_faces()) > 2 * 25  # both lips of at least the 5 × 5 faces of a plane
    pieces_do_not_pull_on_each_other(body)
    solve_with_every_preconditioner(body)
    check_invariants(body, 99, "solved after the cut")


@pytest.mark.parametrize("dim", [2, 3])
def test_cutters_carry_an_affine_state_exactly(dim):
    """Snapping, splitting, dissecting, collapsing and removing fragments all interpolate the
    displacement linearly: an affine state stays affine, and with it the smoothed body's
    energy is P1's after the cut."""
    rng = np.random.default_rng(dim)
    A = 0.01 * rng.standard_normal((dim, dim))
    if dim == 2:
        mesh = distorted_grid(2)
        body = smoothed_body(mesh, snede.StVenantKirchhoff(1e4, 0.45))
        body.displacement = mesh.points @ A.T
        cutter = snede.DelaunayCutter(body)
        cutter.cut(np.array([[-0.2, 0.42], [0.55, 0.6], [0.8, 0.3], [1.2, 0.35]]))
    else:
        mesh = snede.meshing.box((1.0, 1.0, 1.0), (4, 4, 4))
        body = smoothed_body(mesh, snede.StVenantKirchhoff(1e4, 0.45))
        body.displacement = mesh.points @ A.T
        cutter = snede.TetrahedralCutter(body, fix_free_pieces=False)
        for y in (-0.5, 0.4, 0.8, 1.5):  # the tilted plane x = 0.55 + 0.1 z through the whole box
            cutter.move(np.array([[0.45, y, -1.0], [0.75, y, 2.0]]))
    mesh.validate()
    assert mesh.connected_components()[0] == 2
    check_affine_state_carried(body, A, "cut")
    u = body.displacement
    assert body.energy(u) == pytest.approx(p1_twin(body).energy(u), rel=1e-10)
    check_invariants(body, dim, "cut")


def test_delaunay_and_subdivision_cutters_on_a_smoothed_sheet():
    mesh = snede.meshing.rectangle((1.0, 1.0), (10, 10))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.49), density=10.0)
    body.fix(np.isclose(mesh.points[:, 1], 0.0))
    body.add_gravity((0.0, -9.81))
    assert snede.StaticSolver(body, "newton", rtol=1e-8).solve().converged
    cutter = snede.DelaunayCutter(body)
    path = snede.planar_cutting.sample_path(np.array([[-0.2, 0.55], [0.5, 0.62], [0.7, 0.45], [1.3, 0.5]]),
                                            cutter.eps_edge)
    flips = 0
    for step, point in enumerate(path):
        report = cutter.move(point)
        flips += report.flips
        if step % 3 == 0 or step == len(path) - 1:
            mesh.validate()
            check_invariants(body, step, f"move {step} to {point}")
    assert flips > 0 and mesh.connected_components()[0] == 2
    pieces_do_not_pull_on_each_other(body)
    assert body.fix_free_pieces() == 1  # the upper part, cut free of the fixed bottom
    solve_with_every_preconditioner(body)
    # The subdivision baseline edits the same mesh under the body (splits and dissections).
    report = SubdivisionCutter(mesh).cut([np.array([0.3, -0.1]), np.array([0.45, 0.4])])
    assert report.nodes_inserted > 0
    mesh.validate()
    check_invariants(body, 5, "subdivision cut")
    solve_with_every_preconditioner(body)
