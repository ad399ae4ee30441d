"""An exception raised in a PETSc monitor reaches the caller as it was raised."""
import pytest

import snede
from solve_scenes import sagging_sheet


class MonitorError(Exception):
    pass


def raise_from_monitor(exception):
    def monitor(*args):
        raise exception
    return monitor


@pytest.mark.parametrize("handle", ["snes (newton)", "ksp (cg)", "ts (dynamic)"])
@pytest.mark.parametrize("exception", [MonitorError("from my monitor"), KeyboardInterrupt()])
def test_an_exception_inside_a_petsc_monitor_keeps_its_type_and_message(handle, exception):
    # PETSc runs the petsc4py monitor, which raises: the caller gets that exception (before:
    # "PetscError: PETSc error -1"), a Ctrl-C in a monitor is a KeyboardInterrupt, and the
    # solver still works once the monitor is gone.
    body = sagging_sheet(1e5)
    if handle == "ts (dynamic)":
        solver = snede.DynamicRelaxation(body, damping=20.0)
        petsc_object, run = solver.ts, lambda: solver.run(1e-2)
    else:
        solver = snede.StaticSolver(body, "newton" if handle.startswith("snes") else "cg")
        petsc_object, run = (solver.snes if handle.startswith("snes") else solver.ksp), solver.solve
    petsc_object.setMonitor(raise_from_monitor(exception))
    with pytest.raises(type(exception)) as raised:
        run()
    assert str(raised.value) == str(exception)
    petsc_object.cancelMonitor()
    assert run().converged
