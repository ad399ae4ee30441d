"""``snede.Error``: the base class of every snede exception.

Each snede exception also keeps the built-in base callers caught before there was one
(``InvalidMesh`` is a ``ValueError``, ``FileError`` an ``OSError``...): ``except snede.Error``
catches any of them, ``except ValueError`` still catches a bad mesh. The engine's exceptions
(registered in bindings/) take this class as a base too; this module imports nothing, so
``snede._petsc`` can use it before the engine loads.
"""


class Error(Exception):
    """Base class of every snede exception (each also keeps its built-in base)."""
