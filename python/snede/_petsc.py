"""PETSc initialisation: once per process, through petsc4py, before the engine loads.

Command-line options reach PETSc because ``sys.argv`` is passed to ``petsc4py.init``;
``PETSC_OPTIONS`` is read by PETSc itself. A script that called ``petsc4py.init(...)``
before importing snede keeps its own arguments: petsc4py ignores a second ``init``.
"""
import sys

import petsc4py

petsc4py.init(sys.argv)
from petsc4py import PETSc  # noqa: E402  (must follow init)

__all__ = ["PETSc", "set_prefixed_options"]


def set_prefixed_options(prefix: str, options: dict | None) -> None:
    """Put ``{name: value}`` into PETSc's options database under ``prefix`` (value None for a
    flag), unless the name is already set: the command line wins over a script's defaults."""
    database = PETSc.Options()
    for key, value in (options or {}).items():
        name = prefix + key.lstrip("-")
        if not database.hasName(name):
            database.setValue(name, "" if value is None else str(value))
