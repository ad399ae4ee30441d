"""Findings of a review of issue 36's changes (records bound once, cutting below solving, one
dynamic relaxation over a Problem), each as a test of what should hold, marked xfail(strict)
until fixed: remove the mark with the fix."""
import copy
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import snede
from snede._snede import NeedleOptions, NeedleStepReport

RECORDS = [snede.SolveResult, NeedleStepReport, NeedleOptions, snede.CutReport, snede.PlanarCutReport]
MPI_ROOT = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
            "OMPI_MCA_rmaps_base_oversubscribe": "1"}
MPI_TESTS = Path(__file__).resolve().parents[2] / "mpi"


@pytest.mark.xfail(strict=True, reason="pickle protocols 0 and 1 abort the interpreter (SIGABRT) on every engine "
                   "record: py::pickle (bindings/record_binding.hpp) only serves protocol >= 2; copyreg's "
                   "_reduce_ex then calls pybind11_object(self), whose C++ 'instance allocation failed' "
                   "exception escapes into C and std::terminate()s. The dataclasses these records replaced "
                   "pickled under every protocol.")
@pytest.mark.parametrize("protocol", [0, 1])
@pytest.mark.parametrize("record", RECORDS, ids=lambda cls: cls.__name__)
def test_records_pickle_under_every_protocol_without_killing_the_interpreter(record, protocol):
    code = (f"import pickle, snede._snede as m\n"
            f"r = m.{record.__name__}()\n"
            f"assert pickle.loads(pickle.dumps(r, {protocol})) == r\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, f"returncode {run.returncode}: {run.stderr[-400:]}"


@pytest.mark.xfail(strict=True, reason="record __eq__ (bindings/record_binding.hpp) compares fields with C++ ==, "
                   "so a record holding NaN is not equal to itself nor to its copy: a SolveResult of a "
                   "DIVERGED_NONFINITE_STATE solve has residual_norm NaN. The SolveResult dataclass it "
                   "replaced compared field tuples (identity first): r == r and deepcopy(r) == r held.")
def test_a_record_holding_nan_equals_itself_and_its_copy():
    result = snede.SolveResult(converged=False, reason="DIVERGED_NONFINITE_STATE", residual_norm=float("nan"))
    assert result == result
    assert copy.deepcopy(result) == result


RELAXATION_WITH_OPTIONS_PER_RANK = """
    import sys
    from mpi4py import MPI
    import snede
    sys.path.insert(0, {tests!r})
    from cantilever_problems import linear_cantilever_problem

    COMM = MPI.COMM_WORLD
    problem = linear_cantilever_problem(COMM)
    try:
        snede.DistributedRelaxation(problem, damping=1.5, petsc_options={options})
        outcome = "made"
    except Exception as error:
        outcome = type(error).__name__ + ": " + str(error)
    # No run(): with these ranks' options it would hang (different step counts) or meet an
    # MPI error; what is compared is whether the constructor refused them on every rank.
    with open(f"{out}/rank{{COMM.rank}}.txt", "w") as file:  # not stdout: mpirun interleaves lines
        file.write(outcome)
    """


@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
@pytest.mark.xfail(strict=True, reason="DistributedRelaxation's new petsc_options (b2d1c8b) are left out of the "
                   "rank agreement (DynamicRelaxation's constructor checks damping, dt and options_prefix, "
                   "snede.distributed.agreed only agrees on exceptions): options that differ between ranks "
                   "are taken, and run() then deadlocks (ts_max_steps) or fails with an MPI error on one rank "
                   "(ts_monitor on rank 0 only); a bad option on one rank raises there alone while the other "
                   "ranks go on into collectives. Differing damping raises ValueError on every rank.")
@pytest.mark.parametrize("options", ['{"ts_max_steps": 50 + 50 * COMM.rank}',
                                     '{"ts_monitor": None} if COMM.rank == 0 else None',
                                     '{"ts_max_steps": "many"} if COMM.rank == 1 else None'],
                         ids=["max-steps-differ", "monitor-on-rank-0", "bad-value-on-rank-1"])
def test_petsc_options_that_differ_between_ranks_are_refused_on_every_rank(tmp_path, options):
    script = tmp_path / "relaxation.py"
    script.write_text(textwrap.dedent(RELAXATION_WITH_OPTIONS_PER_RANK.format(tests=str(MPI_TESTS), options=options,
                                                                                  out=str(tmp_path))))
    run = subprocess.run(["mpirun", "-q", "-n", "2", sys.executable, str(script)], capture_output=True, text=True,
                         timeout=180, env={**os.environ, **MPI_ROOT})
    outcomes = {path.stem: path.read_text() for path in sorted(tmp_path.glob("rank*.txt"))}
    assert len(outcomes) == 2, (run.stdout, run.stderr[-800:])
    # Refused, and the same error on every rank (as for a damping that differs between ranks).
    assert "made" not in outcomes.values() and len(set(outcomes.values())) == 1, outcomes
