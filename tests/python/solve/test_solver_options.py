"""Options belong to one solver: ``petsc_options=``, ``line_search=`` and ``ncg_type=`` reach
only the solver they were given to, never a later solver with the same prefix, while the
command line (PETSc's global options database) still wins over them."""
import gc
import subprocess
import sys

import pytest
from petsc4py import PETSc

import snede
from solve_scenes import soft_beam


def snes_view(solver, tmp_path) -> str:
    """-snes_view's text; petsc4py 3.18 has no handle to the SNES's line search."""
    path = tmp_path / "snes_view.txt"
    viewer = PETSc.Viewer().createASCII(str(path))
    solver.snes.view(viewer)
    viewer.destroy()
    return path.read_text()


def line_search_type(solver, tmp_path) -> str:
    text = snes_view(solver, tmp_path)
    block = text[text.index("SNESLineSearch Object"):]
    return block.split("type:", 1)[1].split()[0]


@pytest.fixture
def global_option():
    """Sets options in PETSc's global database (as the command line would) and removes them
    afterwards, so that no other test sees them."""
    database = PETSc.Options()
    names = []

    def set_option(name, value):
        database[name] = value
        names.append(name)

    yield set_option
    for name in names:
        database.delValue(name)


def test_line_search_reaches_only_its_own_solver(tmp_path):
    first = snede.StaticSolver(soft_beam(), "ncg", line_search="cp", ncg_type="fr", options_prefix="own_ls_")
    second = snede.StaticSolver(soft_beam(), "ncg", line_search="snede_newton", options_prefix="own_ls_")
    assert second.solve().iterations > 0
    assert line_search_type(first, tmp_path) == "cp"
    assert line_search_type(second, tmp_path) == "snede_newton"
    assert "type: FR" in snes_view(first, tmp_path) and "type: PRP" in snes_view(second, tmp_path)


def test_petsc_options_reach_only_their_own_solver():
    limited = snede.StaticSolver(soft_beam(), "newton", rtol=1e-6, options_prefix="own_max_it_",
                                 petsc_options={"snes_max_it": 1}).solve()
    assert limited.reason == "DIVERGED_MAX_IT" and limited.iterations == 1
    free = snede.StaticSolver(soft_beam(), "newton", rtol=1e-6, options_prefix="own_max_it_").solve()
    assert free.converged, free
    assert free.iterations > 1
    assert not PETSc.Options().hasName("own_max_it_snes_max_it")


def test_global_options_win_over_the_solvers_own(global_option, tmp_path):
    global_option("static_snes_linesearch_type", "bt")
    global_option("static_snes_max_it", "2")
    solver = snede.StaticSolver(soft_beam(), "ncg", line_search="cp", petsc_options={"snes_max_it": 50})
    assert line_search_type(solver, tmp_path) == "bt"
    assert solver.solve().iterations == 2


def test_petsc_options_reach_only_their_own_dynamic_relaxation():
    body = soft_beam()
    capped = snede.DynamicRelaxation(body, damping=5.0, options_prefix="own_ts_",
                                     petsc_options={"ts_max_steps": 3, "ts_dt": 1e-4})
    assert capped.dt == 1e-4 and capped.step(10).iterations == 3
    free = snede.DynamicRelaxation(soft_beam(), damping=5.0, options_prefix="own_ts_")
    assert free.dt == free.cfl_time_step
    assert free.step(10).iterations == 10


def test_global_options_win_over_the_dynamic_relaxations_own(global_option):
    global_option("dynamic_ts_max_steps", "2")
    dynamics = snede.DynamicRelaxation(soft_beam(), damping=5.0, petsc_options={"ts_max_steps": 50})
    assert dynamics.step(10).iterations == 2


def test_options_left_counts_options_read_by_a_solver_as_used():
    """-options_left lists the command-line options nothing read: a solver's reads count,
    a misspelt option does not."""
    script = (
        "import sys; sys.path.insert(0, 'tests/python/solve')\n"
        "import snede\n"
        "from solve_scenes import soft_beam\n"
        "snede.StaticSolver(soft_beam(), 'newton', petsc_options={'snes_rtol': 1e-3}).solve()\n"
    )
    out = subprocess.run([sys.executable, "-c", script, "-static_snes_max_it", "2", "-static_snes_mxa_it", "2",
                          "-options_left"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    unused = [line for line in out.stdout.splitlines() if line.startswith("Option left:")]
    assert any("-static_snes_mxa_it" in line for line in unused), out.stdout
    assert not any("-static_snes_max_it" in line or "-static_snes_rtol" in line for line in unused), out.stdout


def test_bad_option_names_are_rejected_with_the_name():
    for name in ("", "snes max_it"):
        with pytest.raises(ValueError, match=repr(name)):
            snede.StaticSolver(soft_beam(), "newton", options_prefix="bad_name_", petsc_options={name: 1})
        with pytest.raises(ValueError, match=repr(name)):
            snede.DynamicRelaxation(soft_beam(), damping=5.0, petsc_options={name: 1})


def test_a_handle_that_outlives_its_solver_still_reads_the_solvers_options():
    snes = snede.StaticSolver(soft_beam(), "newton", options_prefix="outlived_",
                              petsc_options={"snes_type": "ncg", "snes_ncg_type": "fr"}).snes
    gc.collect()
    snes.setType("newtonls")
    snes.setFromOptions()
    assert snes.getType() == "ncg"
