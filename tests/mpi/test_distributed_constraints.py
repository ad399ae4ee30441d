"""Sliding constraints and membranes on MPI ranks (issue 36 item 1): a serial body solved with
``comm=`` equals the serial solve of the same body on 1, 2 or 3 ranks; a sliding vertex moves
only along its line (Body.slide: through where it was when the constraint was set)."""
import numpy as np
import pytest
from mpi4py import MPI

import snede
from cantilever_problems import cantilever, conditions
from membrane_sheets import pretensioned_sheet

COMM = MPI.COMM_WORLD
TIP_LINE = np.array([0.0, 0.6, -0.8])  # unit: the tip's vertices slide down and sideways
MID_LINE = np.array([1.0, 0.0, 1.0])  # not unit: Body.slide normalises it


def relative_difference(u, v):
    return np.abs(u - v).max() / np.abs(v).max()


def off_line(displacements, direction):
    """The largest part of the displacements across the line along `direction`."""
    t = direction / np.linalg.norm(direction)
    return np.abs(displacements - np.outer(displacements @ t, t)).max()


def sliding_cantilever(material):
    """The 3D cantilever held at x = 0 and pulled down at its tip, whose vertices slide along
    TIP_LINE, and the top vertices at x = 2 along MID_LINE."""
    mesh, _ = cantilever(3)
    fixed, tip, force = conditions(mesh)
    x = mesh.points
    middle = np.flatnonzero(np.isclose(x[:, 0], 2.0) & np.isclose(x[:, 2], 1.0))
    body = snede.Body(mesh, material)
    body.fix(fixed)
    body.slide(tip, TIP_LINE)
    body.slide(middle, MID_LINE)
    body.add_nodal_force(tip, force)
    return body, tip, middle


@pytest.mark.parametrize("method, preconditioner", [("cg", "none"), ("newton", "mg")])
def test_sliding_vertices_on_ranks_give_the_serial_displacement(method, preconditioner):
    material = snede.LinearElastic(1e5, 0.3) if method == "cg" else snede.NeoHookean(1e5, 0.3)
    (body, tip, middle), (reference, _, _) = sliding_cantilever(material), sliding_cantilever(material)
    result = snede.StaticSolver(body, method, rtol=1e-12, preconditioner=preconditioner, comm=COMM).solve()
    expected = snede.StaticSolver(reference, method, rtol=1e-12, preconditioner="none").solve()
    assert result.converged and expected.converged, (result, expected)
    assert relative_difference(body.displacement, reference.displacement) <= 1e-8
    scale = np.abs(body.displacement).max()
    assert np.abs(body.displacement[tip]).max() > 0.1 * scale  # they moved, along their lines only
    assert off_line(body.displacement[tip], TIP_LINE) <= 1e-12 * scale
    assert off_line(body.displacement[middle], MID_LINE) <= 1e-12 * scale
    assert len({u.tobytes() for u in COMM.allgather(body.displacement)}) == 1


def test_a_vertex_slides_through_where_it_was_when_the_constraint_was_set():
    """Solved once, the body's middle vertices are then set sliding sideways from where they
    are (the anchor of their lines) and the tip pushed sideways: on ranks as serially, they
    move on from there along y only."""
    def two_steps(comm):
        body, tip, middle = sliding_cantilever(snede.LinearElastic(1e5, 0.3))
        solver = snede.StaticSolver(body, "cg", rtol=1e-12, comm=comm)
        assert solver.solve().converged
        before = body.displacement[middle].copy()
        body.slide(middle, (0.0, 1.0, 0.0))
        body.add_nodal_force(tip, (0.0, 30.0, 0.0), channel="push")
        assert solver.solve().converged
        return body, middle, before

    (body, middle, before), (reference, _, _) = two_steps(COMM), two_steps(None)
    assert relative_difference(body.displacement, reference.displacement) <= 1e-8
    moved = body.displacement[middle] - before
    assert np.abs(moved).max() > 1e-3 * np.abs(body.displacement).max()
    assert off_line(moved, np.array([0.0, 1.0, 0.0])) <= 1e-12 * np.abs(body.displacement).max()


# Block Jacobi is left out: ILU(0) of a rank's block of this sheet's tangent (positive parts)
# made Newton stop with DIVERGED_LINE_SEARCH on 2 ranks (on 1 and 3 it converged), as GAMG does
# serially on other sheets (tests/python/fem/test_membrane.py).
@pytest.mark.parametrize("preconditioner", ["none", "jacobi", "lu"])
def test_a_membrane_on_ranks_gives_the_serial_displacement(preconditioner):
    body, reference = pretensioned_sheet(10), pretensioned_sheet(10)
    result = snede.StaticSolver(body, "newton", rtol=1e-12, preconditioner=preconditioner, comm=COMM).solve()
    expected = snede.StaticSolver(reference, "newton", rtol=1e-12, preconditioner="none").solve()
    assert result.converged and expected.converged, (result, expected)
    assert np.abs(reference.displacement[:, 2]).max() > 1e-4  # it deflected across its plane (6e-4)
    assert relative_difference(body.displacement, reference.displacement) <= 1e-8
    assert len({u.tobytes() for u in COMM.allgather(body.displacement)}) == 1


def test_auto_takes_no_multigrid_on_a_membrane_on_ranks():
    """"auto" chooses "mg" from 1 000 cells serially, membranes included; on ranks a membrane has
    no "mg" levels, so "auto" takes none there instead of refusing the solve."""
    body, reference = pretensioned_sheet(24), pretensioned_sheet(24)  # 1 152 triangles
    solver = snede.StaticSolver(body, "newton", rtol=1e-10, comm=COMM)
    result = solver.solve()
    assert result.converged and solver.preconditioner == "none", result
    assert snede.StaticSolver(reference, "newton", rtol=1e-10).preconditioner == "mg"
    assert snede.StaticSolver(reference, "newton", rtol=1e-12, preconditioner="none").solve().converged
    assert relative_difference(body.displacement, reference.displacement) <= 1e-7


def test_multigrid_on_a_membrane_on_ranks_is_refused_on_every_rank():
    with pytest.raises(ValueError, match="preconditioner 'mg' on MPI ranks .* not on a membrane"):
        snede.StaticSolver(pretensioned_sheet(10), "newton", preconditioner="mg", comm=COMM).solve()
    assert COMM.allreduce(1) == COMM.size  # every rank got here


def test_bad_sliding_conditions_are_refused_on_every_rank():
    mesh, _ = cantilever(3)
    part = snede.distribute(mesh if COMM.rank == 0 else None, COMM)
    material = snede.LinearElastic(1e5, 0.3)
    fixed, tip, _ = conditions(mesh)
    free = int(tip[0])
    cases = {"direction must be non-zero and finite": dict(sliding=[free], sliding_directions=[[0.0, 0.0, 0.0]]),
             "is both fixed and sliding": dict(sliding=[fixed[0]], sliding_directions=[[1.0, 0.0, 0.0]]),
             f"sliding vertex {free} is listed twice": dict(sliding=[free, free],
                                                            sliding_directions=[[1.0, 0, 0], [0, 1.0, 0]]),
             "need sliding_directions": dict(sliding=[free]),
             r"sliding_anchors must be \(1, 3\)": dict(sliding=[free], sliding_directions=[[1.0, 0, 0]],
                                                       sliding_anchors=[1.0])}
    for message, arguments in cases.items():
        with pytest.raises(ValueError, match=message):
            snede.DistributedStatic(part, material, fixed=fixed, **arguments)
    assert COMM.allreduce(1) == COMM.size
