""""auto" chooses its preconditioner again when the mesh crosses the size where multigrid pays
(docs/results/needle3d.md): by cells, whatever the vertex rows do; an option the new choice
refuses leaves the solver as it was; and PETSc handles of the solver objects it replaced, or of
a deleted solver, raise instead of crashing (each in a child process, so a crash is an exit
status)."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import snede


def held_box(divisions):
    mesh = snede.meshing.box((1.0, 0.2, 0.2), divisions)
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3))
    body.fix(mesh.points[:, 0] < 1e-9)
    body.add_gravity((0.0, 0.0, -0.2))
    return mesh, body


def test_collapses_that_shrink_the_mesh_below_the_threshold_make_auto_choose_again():
    # A collapse frees a vertex id but keeps the rows: the choice follows the cells.
    mesh, body = held_box((7, 3, 8))
    assert mesh.n_cells >= 1000
    solver = snede.StaticSolver(body, "cg", rtol=1e-8)
    assert solver.solve().converged and solver.preconditioner == "mg"
    rows = mesh.n_points
    rng = np.random.default_rng(0)
    cells = mesh.cells
    edges = np.unique(np.sort(np.vstack([cells[:, [i, j]] for i in range(4) for j in range(i + 1, 4)]), axis=1), axis=0)
    for a, b in edges[rng.permutation(len(edges))]:
        if mesh.n_cells < 800:
            break
        mesh.collapse_edge(int(a), int(b))
    assert mesh.n_cells < 1000 and mesh.n_points == rows
    result = solver.solve()
    assert result.converged and solver.preconditioner == "none"
    assert snede.StaticSolver(body, "cg").preconditioner == "none"


def test_an_option_the_new_choice_refuses_is_refused_at_every_solve_and_the_solver_stays_as_it_was():
    mesh, body = held_box((10, 2, 2))
    solver = snede.StaticSolver(body, "cg", rtol=1e-8, petsc_options={"mg_grid_width": 0})
    assert solver.preconditioner == "none" and solver.solve().converged
    mesh.refine_uniform(3)
    for _ in range(2):
        with pytest.raises(ValueError, match="mg_grid_width must be at least 1"):
            solver.solve()
        assert solver.preconditioner == "none"


SCRIPT = """
    import gc
    import snede
    mesh = snede.meshing.box((1.0, 0.2, 0.2), {divisions})
    body = snede.Body(mesh, snede.{material}(1e5, 0.3))
    body.fix(mesh.points[:, 0] < 1e-9)
    body.add_gravity((0.0, 0.0, -0.2))
    solver = snede.StaticSolver(body, "{method}", 1e-8)
    solver.solve()
    ksp = solver.ksp
    {edit}
    A, P = ksp.getOperators()
    b, x = A.createVecs()
    b.set(1.0)
    del solver
    gc.collect()
    try:
        ksp.solve(b, x)
        print("solved")
    except Exception as e:
        print("raised:", type(e).__name__)
    print("end of script")
"""


@pytest.mark.parametrize("case", [
    dict(divisions=(10, 2, 2), material="LinearElastic", method="cg", edit="mesh.refine_uniform(3); solver.solve()"),
    dict(divisions=(7, 3, 8), material="NeoHookean", method="newton", edit="pass"),
], ids=["cg-handle-replaced-by-rechoice", "newton-inner-ksp"])
def test_a_handle_that_outlives_its_solver_raises_instead_of_crashing(case):
    script = textwrap.dedent(SCRIPT.format(**case))
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "raised: Error" in run.stdout and "end of script" in run.stdout
