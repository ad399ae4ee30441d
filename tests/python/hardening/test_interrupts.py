"""Issue 14, item 5: Ctrl-C. A SIGINT stops a solve between iterations as a KeyboardInterrupt
(before: it waited for the solve to end), gmsh meshing no longer takes the signal over (before:
Ctrl-C afterwards killed the process without a word), and the command line stops with one
line and exit status 130, leaving the series written so far readable. The signals are sent
from this process to a child, as a terminal would."""
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from snede.output import read_series

# A process started with SIGINT ignored (nohup, or `cmd &` from a script) passes that on to its
# children, which then never see the Ctrl-C these tests send (issue 38): skip rather than fail.
needs_sigint = pytest.mark.skipif(signal.getsignal(signal.SIGINT) is signal.SIG_IGN,
                                  reason="SIGINT is ignored in this process (nohup or a background job of a "
                                         "script): its children inherit that and cannot be interrupted")

LONG_SOLVE = textwrap.dedent("""
    import numpy as np, snede
    mesh = snede.meshing.box((0.2, 0.05, 0.05), (64, 16, 16))
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0, 0, -9.81))
    # Below round-off, with no floor and no preconditioner: CG runs to its iteration limit (about
    # 20 s), far longer than the delay. (With the round-off floor multigrid got there in 0.3 s,
    # and the signal came after the solve.)
    solver = snede.StaticSolver(body, "cg", rtol=1e-17, round_tolerance=0.0, max_iterations=30000,
                                preconditioner="none")
    print("solving", flush=True)
    try:
        print("finished:", solver.solve(), flush=True)
    except KeyboardInterrupt:
        print("KeyboardInterrupt", flush=True)
    small = snede.meshing.box((0.1, 0.02, 0.02), (4, 2, 2))
    body = snede.Body(small, snede.LinearElastic(1e5, 0.3), density=1000.0)
    body.fix(np.isclose(small.points[:, 0], 0.0))
    body.add_gravity((0, 0, -9.81))
    print("afterwards:", snede.StaticSolver(body, "cg").solve().reason, flush=True)
""")


def interrupt_after(arguments, marker: str, delay: float = 0.3, timeout: float = 120):
    """Runs a child, sends it SIGINT `delay` s after it printed a line containing `marker`;
    returns (exit status, its stdout, its stderr)."""
    child = subprocess.Popen(arguments, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = []
    for line in child.stdout:
        lines.append(line)
        if marker in line:
            break
    time.sleep(delay)
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=timeout)
    return child.returncode, "".join(lines) + out, err


@needs_sigint
def test_ctrl_c_stops_a_solve_between_iterations_and_petsc_keeps_working():
    status, out, err = interrupt_after([sys.executable, "-c", LONG_SOLVE], "solving")
    assert "KeyboardInterrupt" in out and "finished" not in out, (out, err)
    assert "afterwards: CONVERGED" in out, (out, err)
    assert status == 0


@needs_sigint
def test_gmsh_meshing_leaves_ctrl_c_to_python():
    script = textwrap.dedent("""
        import os, signal, time, snede
        snede.meshing.cylinder(h=0.02)
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)
        except KeyboardInterrupt:
            print("caught")
    """)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "caught" in run.stdout, (run.returncode, run.stdout, run.stderr)


@needs_sigint
def test_the_command_line_stops_with_one_line_and_the_series_so_far_reads_back(tmp_path):
    status, out, err = interrupt_after(
        [sys.executable, "-m", "snede", "run", "sheet-cut", "--divisions", "20", "--out", str(tmp_path)],
        "sheet-cut: move   8/")
    assert status == 130, (out, err)
    assert err.strip().splitlines() == [f"interrupted (the files written so far in {tmp_path} are complete up to "
                                        "the last step)"], err
    steps = read_series(tmp_path / "sheet-cut" / "sheet-cut.xdmf")
    assert len(steps) >= 2  # the stretched sheet and at least one frame of the cut
    for step in steps:
        step.mesh.validate()
        assert step.displacement.shape == (step.mesh.n_points, 2)


def test_ctrl_c_while_a_gif_is_drawn_stays_a_keyboard_interrupt(tmp_path):
    # matplotlib's writer.saving() called finish() on the way out, which raised IndexError on a
    # GIF without frames and hid the KeyboardInterrupt (the command line then exited 1).
    from snede.plotting import animate

    def draw(ax, frame):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        animate([0, 1], tmp_path / "cut.gif", draw)
    assert not (tmp_path / "cut.gif").exists() or (tmp_path / "cut.gif").stat().st_size == 0
