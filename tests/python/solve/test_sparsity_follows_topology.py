"""Issue 49's first step: the assembled tangent's sparsity follows the mesh's elements, not its
vertices' positions. Half of a cut's moves only snap a vertex or two onto the blade (no element
added or removed); the solver kept rebuilding its sparsity for those. Now it keeps it, fills the
values for the new shapes, and solves exactly as a solver made afresh on the same state."""
import numpy as np
import pytest

import snede


def sagging_box():
    mesh = snede.meshing.box((4.0, 1.0, 1.0), (8, 2, 2))
    body = snede.Body(mesh, snede.NeoHookean(E=1e4, nu=0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


def interior_vertex(mesh):
    inside = np.all((mesh.points > 1e-9) & (mesh.points < np.array([4.0, 1.0, 1.0]) - 1e-9), axis=1)
    return int(np.flatnonzero(inside)[len(np.flatnonzero(inside)) // 2])


def snap(body, vertex):
    """Moves `vertex` by a tenth of an edge in the reference configuration, as a cut's snap does."""
    body.mesh.move_vertex(vertex, point=body.mesh.points[vertex] + [0.05, 0.02, -0.03])


@pytest.mark.parametrize("preconditioner", ["gamg", "mg"])
def test_a_moved_vertex_keeps_the_sparsity_and_a_new_element_does_not(preconditioner):
    body = sagging_box()
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner=preconditioner)
    assert solver.solve().converged
    assert solver.sparsity_builds == 1
    snap(body, interior_vertex(body.mesh))
    assert solver.solve().converged
    assert solver.sparsity_builds == 1
    a, b = body.mesh.cells[0][:2]
    body.mesh.split_edge(a, b)
    assert solver.solve().converged
    assert solver.sparsity_builds == 2


def test_after_a_moved_vertex_the_kept_sparsity_solves_as_a_new_solver():
    """Two identical bodies, the same vertex moved in both: the solver that kept its sparsity and
    a solver made after the move take the same Newton and CG iterations to the same state (GAMG
    is set up afresh on the same matrix in both; stale values would change the CG counts)."""
    kept, fresh = sagging_box(), sagging_box()
    options = dict(method="newton", rtol=1e-8, preconditioner="gamg")
    kept_solver = snede.StaticSolver(kept, **options)
    assert kept_solver.solve().converged
    assert snede.StaticSolver(fresh, **options).solve().converged
    np.testing.assert_array_equal(kept.displacement, fresh.displacement)
    vertex = interior_vertex(kept.mesh)
    snap(kept, vertex)
    snap(fresh, vertex)
    after_kept = kept_solver.solve()
    after_fresh = snede.StaticSolver(fresh, **options).solve()
    assert kept_solver.sparsity_builds == 1
    assert after_kept.converged and after_fresh.converged
    assert (after_kept.iterations, after_kept.linear_iterations) == (after_fresh.iterations,
                                                                      after_fresh.linear_iterations)
    np.testing.assert_allclose(kept.displacement, fresh.displacement, rtol=0,
                               atol=1e-12 * np.abs(fresh.displacement).max())
