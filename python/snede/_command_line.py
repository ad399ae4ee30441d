"""The command line's promise (``python -m snede``): bad input gives one line on stderr,
``python -m snede: error: ...``, and exit status 2; Ctrl-C gives one line, ``interrupted ...``,
and status 130; never a traceback. ``python -m snede`` imports the package before its
``__main__`` runs, so ``snede._petsc`` keeps the promise while the package loads (PETSc's
start-up, Ctrl-C) and ``snede.__main__`` afterwards, both through this module.
"""
from __future__ import annotations

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
    """From now on Ctrl-C calls ``react()``, except inside a finalizer (a weakref callback or a
    ``__del__``, run whenever the garbage collector frees PETSc objects): Python prints and
    swallows an exception raised there, and the run went on to its end with status 0. There the
    signal is sent again a moment later, once the finalizer has returned. Where SIGINT is
    ignored (nohup) or handled by someone else, it stays so."""
    current = signal.getsignal(signal.SIGINT)
    if current is not signal.default_int_handler and getattr(current, "__module__", None) != __name__:
        return

    def handler(signum, frame) -> None:
        while frame is not None:
            code = frame.f_code
            if code.co_name == "__del__" or code.co_filename.endswith("weakref.py"):
                threading.Timer(0.02, os.kill, (os.getpid(), signum)).start()
                return
            frame = frame.f_back
        react()

    signal.signal(signal.SIGINT, handler)
