"""Issue 14, item 5: a SIGINT stops a solve between iterations as a KeyboardInterrupt (before:
it waited for the solve to end). The signal is sent from this process to a child, as a
terminal would."""
import sys
import textwrap

from interrupts import interrupt_after, needs_sigint

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


@needs_sigint
def test_ctrl_c_stops_a_solve_between_iterations_and_petsc_keeps_working():
    status, out, err = interrupt_after([sys.executable, "-c", LONG_SOLVE], "solving")
    assert "KeyboardInterrupt" in out and "finished" not in out, (out, err)
    assert "afterwards: CONVERGED" in out, (out, err)
    assert status == 0
