"""PETSc initialisation: once per process, through petsc4py, before the engine loads.

Command-line options reach PETSc because ``sys.argv`` is passed to ``petsc4py.init``;
``PETSC_OPTIONS`` is read by PETSc itself. A script that called ``petsc4py.init(...)``
before importing snede keeps its own arguments: petsc4py ignores a second ``init``.
"""
import sys

import petsc4py

petsc4py.init(sys.argv)
from petsc4py import PETSc  # noqa: E402  (must follow init)

__all__ = ["PETSc", "option_list"]


def option_list(options: dict | None) -> list[tuple[str, str]]:
    """``{name: value}`` (value None for a flag) as the engine's (name, value) strings; the
    engine puts them in the solver's own options database, under its prefix."""
    return [(str(name), "" if value is None else str(value)) for name, value in (options or {}).items()]
