"""PETSc initialisation: once per process, through petsc4py, before the engine loads.

Command-line options reach PETSc because the PETSc options of ``sys.argv`` are passed to
``petsc4py.init``: single-dash options (``-static_snes_monitor``, ``-log_view``) with their
values, split as ``snede._argv.split`` does; ``--options``, their values and other words (the
command line's ``run``, the scene name, ``--method cg``; a script's own arguments) are not
PETSc's and stay out of its options database. ``PETSC_OPTIONS`` is read by PETSc itself. A script that called ``petsc4py.init(...)``
before importing snede keeps its own arguments: petsc4py ignores a second ``init``.
"""
import sys

import petsc4py

from snede._argv import split


def _program() -> str:
    # While `python -m snede` imports the package, sys.argv[0] is "-m"; petsc4py would then
    # take "-m" for an option ("-m run" in the database), so give a program name.
    name = sys.argv[0] if sys.argv and sys.argv[0] not in ("", "-m", "-c") else "python"
    return name if not name.startswith("-") else "python"


petsc4py.init([_program(), *split(sys.argv[1:])[1]])
from petsc4py import PETSc  # noqa: E402  (must follow init)

__all__ = ["PETSc", "option_list"]


def option_list(options: dict | None) -> list[tuple[str, str]]:
    """``{name: value}`` (value None for a flag) as the engine's (name, value) strings; the
    engine puts them in the solver's own options database, under its prefix."""
    return [(str(name), "" if value is None else str(value)) for name, value in (options or {}).items()]


def unused_options(prefixes: tuple[str, ...]) -> list[tuple[str, str | None]]:
    """The options of the global database whose name starts with one of ``prefixes`` and that
    no PETSc object has read so far (``PetscOptionsUsed``, as ``-options_left`` reports at
    exit), as ``(name, value)``."""
    from snede import _snede

    return [(name, value) for name, value in PETSc.Options().getAll().items()
            if name.startswith(prefixes) and not _snede.option_used(name)]
