"""Which command-line tokens are PETSc's: used by ``snede._petsc`` (what ``petsc4py.init``
sees) and by the command line (``python -m snede``), so that both split argv the same way.

A PETSc option is a token ``-name`` (one dash, then a letter), with the token after it as its
value unless that token is itself an option (PETSc's own rule: ``-1e-8`` is a value). Tokens
starting with ``--`` (and their values) and other words are not PETSc's: they are snede's (or
the script's) and never reach PETSc's options database.
"""
from __future__ import annotations

import re

_PETSC_KEY = re.compile(r"^-[A-Za-z]")
_LONG_KEY = re.compile(r"^--[A-Za-z]")
NOT_PETSC = ("-h",)  # single-dash options of snede's own parser (argparse's -h)


def is_petsc_key(token: str) -> bool:
    return bool(_PETSC_KEY.match(token)) and token not in NOT_PETSC


def _is_key(token: str) -> bool:
    return bool(_PETSC_KEY.match(token) or _LONG_KEY.match(token))


def split(argv: list[str]) -> tuple[list[str], list[str]]:
    """``(others, petsc)``: the tokens of argv (without the program name) that are not PETSc's,
    in order, and the PETSc options with their values, in order."""
    others, petsc = [], []
    i = 0
    while i < len(argv):
        token = argv[i]
        if is_petsc_key(token):
            petsc.append(token)
            if i + 1 < len(argv) and not _is_key(argv[i + 1]) and argv[i + 1] not in NOT_PETSC:
                petsc.append(argv[i + 1])
                i += 1
        else:
            others.append(token)
        i += 1
    return others, petsc
