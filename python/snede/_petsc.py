"""PETSc initialisation: once per process, through petsc4py, before the engine loads.

Command-line options reach PETSc because the PETSc options of ``sys.argv`` are passed to
``petsc4py.init``: single-dash options (``-static_snes_monitor``, ``-log_view``) with their
values, split as ``snede._argv.split`` does; ``--options``, their values and other words (the
command line's ``run``, the scene name, ``--method cg``; a script's own arguments) are not
PETSc's and stay out of its options database. ``PETSC_OPTIONS`` is read by PETSc itself. A script that called ``petsc4py.init(...)``
before importing snede keeps its own arguments: petsc4py ignores a second ``init``. If PETSc
cannot start (``-options_file`` names no file), its message replaces the error block it prints.
"""
import itertools
import os
import re
import sys
import tempfile

import petsc4py

from snede import _command_line
from snede._argv import split
from snede._errors import Error

if _command_line.is_loading():
    _command_line.on_ctrl_c(_command_line.stop_interrupted)


def _program() -> str:
    # While `python -m snede` imports the package, sys.argv[0] is "-m"; petsc4py would then
    # take "-m" for an option ("-m run" in the database), so give a program name.
    name = sys.argv[0] if sys.argv and sys.argv[0] not in ("", "-m", "-c") else "python"
    return name if not name.startswith("-") else "python"


def _capturing_stderr(call) -> tuple[Exception | None, str]:
    """Runs ``call()`` with file descriptor 2, where PETSc prints its errors, sent to a
    temporary file: the exception it raised (or None) and what was printed there. Ctrl-C or an
    exit meanwhile goes on, after what was printed (its own line among it)."""
    with tempfile.TemporaryFile() as sink:
        sys.stderr.flush()
        saved = os.dup(2)
        os.dup2(sink.fileno(), 2)
        try:
            call()
            failure = None
        except Exception as error:  # petsc4py's error has PETSc's code, not its message
            failure = error
        except BaseException:
            sys.stderr.write(_give_back_stderr(saved, sink))
            raise
        return failure, _give_back_stderr(saved, sink)


def _give_back_stderr(saved: int, sink) -> str:
    """Points file descriptor 2 back to ``saved``; what was printed to ``sink`` meanwhile."""
    sys.stderr.flush()
    os.dup2(saved, 2)
    os.close(saved)
    sink.seek(0)
    return sink.read().decode(errors="replace")


def petsc_error_message(printed: str) -> str:
    """The message of the error block PETSc printed (its lines after the "Error Message"
    header, up to "See https://petsc.org/..."), on one line."""
    lines = [line.split("PETSC ERROR: ", 1)[1].strip() for line in printed.splitlines() if "PETSC ERROR: " in line]
    start = next((i + 1 for i, line in enumerate(lines) if "Error Message" in line), len(lines))
    return ": ".join(itertools.takewhile(lambda line: not line.startswith("See "), lines[start:]))


def _initialise(arguments: list[str]) -> None:
    """``petsc4py.init(arguments)``. If PETSc cannot start (``-options_file`` names no file),
    its message, in place of the error block PETSc prints: one line and status 2 for the
    command line, a RuntimeError for a script."""
    failure, printed = _capturing_stderr(lambda: petsc4py.init(arguments))
    if failure is None:
        sys.stderr.write(printed)  # what MPI or PETSc said as they started, shown as it would have been
        return
    message = f"PETSc could not start: {petsc_error_message(printed) or failure}"
    if _command_line.is_loading():
        _command_line.fail(message)
    raise RuntimeError(message) from failure


_initialise([_program(), *split(sys.argv[1:])[1]])
from petsc4py import PETSc  # noqa: E402  (must follow init)

__all__ = ["PETSc", "option_list"]


def option_list(options: dict | None) -> list[tuple[str, str]]:
    """``{name: value}`` (value None for a flag) as the engine's (name, value) strings; the
    engine puts them in the solver's own options database, under its prefix."""
    return [(str(name), "" if value is None else str(value)) for name, value in (options or {}).items()]


# Read by PetscFinalize, after the command line has listed the options nothing read.
READ_AT_FINALIZE = frozenset({
    "citations", "get_total_flops", "log", "log_all", "log_mpe", "log_view", "malloc_debug", "malloc_dump",
    "malloc_test", "malloc_view", "memory_view", "mpi_linear_solver_server", "mpidump", "no_signal_handler", "nox",
    "nox_warning", "objects_dump", "options_left", "options_view", "saw_options", "x_virtual"})


def unused_options() -> list[tuple[str, str | None]]:
    """The options of the global database that nothing has read so far (``PetscOptionsUsed``,
    as ``-options_left`` reports at exit) and PETSc does not read as it finalizes, as
    ``(name, value)``."""
    from snede import _snede

    return [(name, value) for name, value in PETSc.Options().getAll().items()
            if name not in READ_AT_FINALIZE and not _snede.option_used(name)]


class OptionValueError(Error, ValueError):
    """A value PETSc refuses for one of its options."""


# The PETSc object that reads the options whose name has this word (after a prefix):
# -static_snes_rtol is a SNES's (prefix static_), -static_mg_levels_ksp_type a KSP's.
_READERS = {"snes": PETSc.SNES, "ksp": PETSc.KSP, "pc": PETSc.KSP, "ts": PETSc.TS}
_READER_WORD = re.compile(r"(?:^|_)(snes|ksp|pc|ts)_")
# Values only snede's solvers know (the preconditioner "auto", snede's line searches and
# integrator): PETSc's own objects refuse them.
SNEDE_VALUES = frozenset({"auto", "snede_newton", "snede_secant", "snede_ss22"})


def check_option_values() -> None:
    """Sets up a throwaway PETSc object of each kind and prefix the global options name (a
    SNES with prefix ``static_`` for ``-static_snes_rtol``), so that a value PETSc refuses is
    an error before the run, whether or not a solver of the run reads it; raises
    OptionValueError with PETSc's message. The options stay unread for ``unused_options``."""
    from snede import _snede

    options = PETSc.Options()
    given = options.getAll()
    if "help" in given:  # each throwaway object would print the help of its options
        return
    readers = {(name[:word.start(1)], word.group(1)) for name, value in given.items()
               if value not in SNEDE_VALUES and (word := _READER_WORD.search(name))}
    # Those with snede's values are left out while PETSc's objects read, and all are unread after.
    restore = {name: value for name, value in given.items()
               if value in SNEDE_VALUES or not _snede.option_used(name)}
    try:
        for name, value in restore.items():
            if value in SNEDE_VALUES:
                options.delValue(name)
        for prefix, word in sorted(readers):
            _read_options(_READERS[word](), prefix, f"-{prefix}{word}_*")
    finally:
        for name, value in restore.items():
            options.delValue(name)
            options.setValue(name, value)


def _read_options(reader, prefix: str, which: str) -> None:
    reader.create(PETSc.COMM_SELF)
    reader.setOptionsPrefix(prefix)
    PETSc.Sys.pushErrorHandler("traceback")  # PETSc prints its message, which petsc4py's error lacks
    try:
        failure, printed = _capturing_stderr(reader.setFromOptions)
    finally:
        PETSc.Sys.popErrorHandler()
        reader.destroy()
    if failure is not None:
        raise OptionValueError(f"PETSc options {which}: {petsc_error_message(printed)}")
    sys.stderr.write(printed)
