"""DistributedRelaxation's petsc_options (one DynamicRelaxation engine over a Problem, issue 36)
are part of the constructor's rank agreement: options that differ between the ranks are refused
with the same ValueError on every rank, instead of a deadlock in run() or an MPI error on one."""
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

MPI_ROOT = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
            "OMPI_MCA_rmaps_base_oversubscribe": "1"}
MPI_TESTS = Path(__file__).resolve().parents[2] / "mpi"


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
