"""The command line's promise (``python -m snede``): bad input gives one line on stderr,
``python -m snede: error: ...``, and exit status 2; Ctrl-C gives one line, ``interrupted ...``,
and status 130; never a traceback. ``python -m snede`` imports the package before its
``__main__`` runs, so ``snede._petsc`` keeps the promise while the package loads (PETSc's
start-up, Ctrl-C) and ``snede.__main__`` afterwards, both through this module. Under ``mpirun``
a failure on one rank ends every rank (``end_every_rank``), also for a script run by
``python -m mpi4py`` (``abort_first_under_mpi4py``).
"""
from __future__ import annotations

import atexit
import os
import signal
import sys
import threading
from typing import Callable, NoReturn

PROGRAM = "python -m snede"
BAD_INPUT = 2  # exit status
INTERRUPTED = 130  # exit status after Ctrl-C: 128 + SIGINT, as a shell reports a process it interrupted


def error_line(message) -> str:
    return f"{PROGRAM}: error: {message}"


class AlikeOnEveryRank(SystemExit):
    """Status 2 after bad input that every MPI rank finds alike (they all have the same
    arguments, options and scene): the first rank has said why, and no rank needs MPI_Abort
    to end the others, which would race its line."""


def fail(message) -> NoReturn:
    """Bad input every rank finds alike: one line, from the first rank; status 2."""
    if _rank() == 0:
        print(error_line(message), file=sys.stderr)
    raise AlikeOnEveryRank(BAD_INPUT)


def end_every_rank(code: int) -> None:
    """Under ``mpirun -n N`` an error on one rank alone (a scene script's, an engine's) would
    leave the other ranks waiting in a collective call for ever (issue 18): with several ranks,
    a failed command ends the whole job with MPI_Abort, as ``python -m mpi4py`` does."""
    from mpi4py import MPI

    if MPI.Is_initialized() and not MPI.Is_finalized() and MPI.COMM_WORLD.size > 1:
        sys.stdout.flush()
        sys.stderr.flush()
        MPI.COMM_WORLD.Abort(code)


def abort_first_under_mpi4py() -> None:
    """Under ``python -m mpi4py script.py`` an exception (or a non-zero sys.exit) in the script
    makes mpi4py record its status and call MPI_Abort at the very end of Python's exit. But
    petsc4py's exit handler comes before that and frees PETSc's objects collectively
    (PetscGarbageCleanup duplicates a communicator): the failed rank waited there for the others,
    which waited for it, for ever (issue 48, item 4). Here mpi4py's runner's status is noted as it
    is set, and an exit handler that runs before petsc4py's (registered after it: atexit runs
    the last registered first) aborts at once. Nothing changes without mpi4py's runner."""
    runner = sys.modules.get("mpi4py.run")
    if runner is None or getattr(runner.set_abort_status, "_snede", False):
        return
    status = [0]
    record = runner.set_abort_status

    def set_abort_status(code):
        status[0] = code if isinstance(code, int) else 0 if code is None else 1
        return record(code)

    def abort_if_failed() -> None:
        if status[0]:
            end_every_rank(status[0])

    set_abort_status._snede = True
    runner.set_abort_status = set_abort_status  # the runner looks it up when the script has failed
    atexit.register(abort_if_failed)


def _rank() -> int:
    from mpi4py import MPI  # (PETSc started MPI, unless it failed before)

    return MPI.COMM_WORLD.rank if MPI.Is_initialized() else 0


def is_loading() -> bool:
    """Whether this process is ``python -m snede`` and is still importing the package: until
    runpy runs ``snede.__main__``, ``sys.argv[0]`` is ``-m``."""
    given = getattr(sys, "orig_argv", [])
    named = "-msnede" in given or any(a == "-m" and b == "snede" for a, b in zip(given, given[1:]))
    return named and sys.argv[:1] == ["-m"]


def stop_interrupted() -> NoReturn:
    """Ctrl-C before the command has begun (while modules load): nothing is written yet."""
    print("interrupted", file=sys.stderr)
    raise SystemExit(INTERRUPTED)


def raise_keyboard_interrupt() -> NoReturn:
    raise KeyboardInterrupt


def on_ctrl_c(react: Callable[[], None]) -> None:
    """From now on Ctrl-C calls ``react()``, except where an exception it raises would be
    mishandled; there the signal is sent again a moment later, once that code has returned:
    * inside a finalizer (a weakref callback or a ``__del__``, run whenever the garbage collector
      frees PETSc objects): Python prints and swallows an exception raised there, and the run
      went on to its end with status 0;
    * inside code compiled from a string (``eval``/``exec`` of source, as ``namedtuple`` does
      while matplotlib is imported for a GIF): CPython 3.11 marks a KeyboardInterrupt leaving such
      code as unhandled even when it is caught later, and under ``python -m`` the process then
      kills itself with SIGINT at exit (status −2 instead of 130);
    * inside an import: it leaves the module half made, and one with C++ state (matplotlib's
      ft2font) then aborted the process at exit (status −6).
    Where SIGINT is ignored (nohup) or handled by someone else, it stays so."""
    current = signal.getsignal(signal.SIGINT)
    if current is not signal.default_int_handler and getattr(current, "__module__", None) != __name__:
        return

    def handler(signum, frame) -> None:
        while frame is not None:
            code = frame.f_code
            if code.co_name == "__del__" or code.co_filename.endswith("weakref.py") or code.co_filename == "<string>" \
                    or code.co_filename.startswith("<frozen importlib._bootstrap"):
                threading.Timer(0.02, os.kill, (os.getpid(), signum)).start()
                return
            frame = frame.f_back
        react()

    signal.signal(signal.SIGINT, handler)
