"""Issue 38, item 5: the command line's promise. Bad input gives one line on stderr,
``python -m snede: error: ...``, and exit status 2; Ctrl-C gives one line, ``interrupted ...``,
and status 130; never a traceback. The cases run ``python -m snede`` in a subprocess (all but the
picture of a failed state)."""
import os
import shutil
import subprocess
import sys
import textwrap

import pytest

import snede
from interrupts import needs_sigint

ERROR = "python -m snede: error: "
MPI_ROOT = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
            "OMPI_MCA_rmaps_base_oversubscribe": "1"}


def run_cli(*args, env=None, launcher=()) -> subprocess.CompletedProcess:
    return subprocess.run([*launcher, sys.executable, "-m", "snede", *args], capture_output=True, text=True,
                          timeout=300, env={**os.environ, **(env or {})})


def the_one_line(run: subprocess.CompletedProcess, status: int = 2) -> str:
    """The single line the command line wrote on stderr, after checking its exit status."""
    assert "Traceback" not in run.stderr, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    assert run.returncode == status, (run.returncode, run.stderr)
    return lines[0]


def test_a_missing_options_file_is_one_line_naming_it(tmp_path):
    # PETSc printed its error block (about 20 lines) and Python a traceback, status 1.
    missing = tmp_path / "nowhere" / "snede.opts"
    line = the_one_line(run_cli("run", "cantilever", "--divisions", "4", "--out", str(tmp_path),
                                "-options_file", str(missing)))
    assert line.startswith(ERROR) and str(missing) in line, line


INTERRUPT_ON_IMPORT = textwrap.dedent("""
    import os, signal, sys

    class InterruptOnImport:
        # Ctrl-C, as a terminal sends it, the moment the module named in SNEDE_TEST_INTERRUPT_ON starts loading.
        def find_spec(self, name, path=None, target=None):
            if name == os.environ.get("SNEDE_TEST_INTERRUPT_ON"):
                sys.meta_path.remove(self)
                os.kill(os.getpid(), signal.SIGINT)
            return None

    sys.meta_path.insert(0, InterruptOnImport())
""")


@needs_sigint
@pytest.mark.parametrize("module", ["numpy", "snede._snede", "snede.app.scenes", "matplotlib"])
def test_ctrl_c_while_modules_load_is_the_one_interrupted_line(tmp_path, module):
    # numpy and the engine load with `import snede` (before the command line's own code runs),
    # snede.app.scenes while the arguments are parsed, matplotlib for the picture: the first three
    # ended in a traceback (status -2).
    (tmp_path / "sitecustomize.py").write_text(INTERRUPT_ON_IMPORT)
    run = run_cli("run", "cantilever", "--divisions", "4", "--out", str(tmp_path / "out"),
                  env={"PYTHONPATH": str(tmp_path), "SNEDE_TEST_INTERRUPT_ON": module})
    assert the_one_line(run, status=130).startswith("interrupted"), run.stderr


def test_a_non_finite_state_is_reported_by_the_solvers_reason_and_not_drawn(tmp_path):
    # A line search's first step of 1e300 makes the state overflow: the picture failed with
    # "Singular matrix" (status 2) and hid the solver's reason (a NaN damping, the probe's way
    # to get there, is now refused as bad input: see the next test).
    run = run_cli("--quiet", "run", "cantilever", "--divisions", "4", "--method", "ncg", "--out", str(tmp_path),
                  "-static_snes_linesearch_type", "cp", "-static_snes_linesearch_damping", "1e300")
    line = the_one_line(run, status=1)  # not converged, as for any solve that fails
    assert "did not converge: DIVERGED_NONFINITE_STATE" in line, line
    assert "DIVERGED_NONFINITE_STATE" in run.stdout  # the table's reason column
    assert not (tmp_path / "cantilever" / "cantilever.png").exists()


def test_a_nan_line_search_damping_is_bad_input(tmp_path):
    run = run_cli("--quiet", "run", "cantilever", "--divisions", "4", "--method", "ncg", "--out", str(tmp_path),
                  "-static_snes_linesearch_type", "cp", "-static_snes_linesearch_damping", "nan")
    assert "snes_linesearch_damping must be positive and finite, got nan" in the_one_line(run, status=2)


def test_a_failed_but_finite_state_is_drawn_with_its_reason(tmp_path, monkeypatch):
    from snede.app import run_scene
    from snede.app.scenes import Parameters, cantilever

    drawn = {}
    monkeypatch.setattr(run_scene, "plot_body", lambda body, path, **arguments: drawn.update(arguments) or path)
    scene = cantilever.build(Parameters(divisions=4))
    files = run_scene.draw_picture(scene, "cg", tmp_path, {"converged": False, "reason": "DIVERGED_ITS"})
    assert files == {"png": str(tmp_path / "cantilever.png")}
    assert drawn["title"].endswith("NOT converged: DIVERGED_ITS"), drawn["title"]


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_a_serial_only_scene_under_mpirun_is_one_line_from_rank_0(tmp_path):
    # Every rank printed the NotImplementedError's traceback, and MPI_Abort ended the job.
    # (mpirun -q: without it, mpirun adds its own banner about the non-zero status.)
    run = run_cli("--quiet", "run", "sheet-cut", "--divisions", "10", "--out", str(tmp_path),
                  env=MPI_ROOT, launcher=("mpirun", "-q", "-n", "2"))
    line = the_one_line(run)
    assert line.startswith(ERROR) and "sheet-cut" in line and "one rank" in line, line


@pytest.mark.parametrize("scene", [("cantilever",), ("cantilever", "--method", "newton"), ("slab",)])
def test_a_bad_petsc_value_is_an_error_whether_or_not_the_scenes_solver_reads_it(tmp_path, scene):
    # The cantilever and the slab solve with linear CG, which has no SNES: the bad value was
    # only reported as an unused option (status 0), while Newton refused it (status 2).
    line = the_one_line(run_cli("--quiet", "run", *scene, "--divisions", "4", "--out", str(tmp_path),
                                "-static_snes_rtol", "abc"))
    assert line.startswith(ERROR) and "Input string abc has no numeric value" in line, line
    assert not (tmp_path / scene[0] / "summary.json").exists()  # refused before the run


def test_misspelled_global_petsc_options_are_reported_but_not_those_petsc_reads_itself(tmp_path):
    run = run_cli("--quiet", "run", "slab", "--divisions", "4", "--out", str(tmp_path), "-log_veiw",
                  "-log_view", f":{tmp_path / 'log.txt'}", "-options_left", "0", "-malloc_dump",
                  "-citations", str(tmp_path / "citations.txt"), "-nox")
    assert run.returncode == 0, run.stderr
    assert the_one_line(run, status=0) == ("WARNING: PETSc option -log_veiw was not used (misspelled, or not for "
                                           "this scene's solver?)")


@pytest.mark.parametrize("args, fragment", [
    (("frob",), "invalid choice: 'frob'"),  # argparse, the main parser
    (("run", "cantilever", "--divisions", "0"), "--divisions: must be positive, got 0"),  # argparse, `run`'s
    (("run", "nosuchscene"), "unknown scene 'nosuchscene'"),  # snede's own check
    (("run", "cantilever", "--divisions", "4", "-static_ksp_type", "foo"), "Unable to find requested KSP type foo"),
    (("run", "cylinder", "--method", "cg"), "needs LinearElastic"),  # the solver's ValueError
])
def test_every_error_is_one_line_with_one_prefix(tmp_path, args, fragment):
    # They were "python -m snede: error:", "python -m snede run: error:" (both after a usage
    # message of up to seven lines) and "error:".
    line = the_one_line(run_cli(*args, "--out", str(tmp_path)) if args[0] == "run" else run_cli(*args))
    assert line.startswith(ERROR) and fragment in line, line


DELETED_FOLDER_SCRIPT = """
import shutil
import sys
from pathlib import Path

import snede
from snede.output import SeriesWriter

out = Path(sys.argv[1])
mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3), thickness=0.01)
writer = SeriesWriter(out / "series")
writer.write(body, 0.0)
shutil.rmtree(out)  # the output folder goes away mid-run
writer.write(body, 1.0)
print("NOT REACHED")
"""


def test_an_output_folder_deleted_mid_run_stops_the_command_line_with_one_line(tmp_path):
    # Item 8: the writer's failure is a snede.FileError (an OSError) naming the file; the
    # command line prints it on one line and exits 2 instead of showing a traceback.
    script = tmp_path / "deleting.py"
    script.write_text(DELETED_FOLDER_SCRIPT)
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, "-m", "snede", "run", str(script), str(out)], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 2, (result.stdout, result.stderr)
    assert "NOT REACHED" not in result.stdout and "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("python -m snede: error: cannot open") and "series.h5" in lines[0], lines
    assert issubclass(snede.FileError, OSError)
