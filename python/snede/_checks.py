"""Checks of the integers the Python front end hands to the engine: counts (iterations, steps,
levels, divisions) and ids (vertices, elements, rows), one at a time or as arrays.

The engine's ids are 32-bit (``VertexId``, ``ElementId``: ``std::int32_t``) and so are its
counts (C++ ``int``; ``PetscInt`` is 32-bit in Debian's PETSc). Without these checks an integer
beyond that range reaches pybind11 as an opaque "incompatible function arguments" TypeError,
and a uint64 beyond int64 wraps to a negative number on its way to int64. Every failure is a
``ValueError`` naming the argument, the offending value (and its position in an array) and
the allowed range.

Real numbers (lengths, tolerances) and coordinates are checked here too: finite, and in range
or of the right shape.
"""
from __future__ import annotations

import math
import operator

import numpy as np

INT32_MAX = 2**31 - 1  #: the largest C++ int / VertexId / ElementId / 32-bit PetscInt
ID_LIMIT = INT32_MAX + 1  #: ids are 0 .. ID_LIMIT − 1
_INT64_MAX = np.iinfo(np.int64).max


def _integer(value) -> int | None:
    """``value`` as a Python int if it is an integer (Python or numpy, not bool), else None."""
    if isinstance(value, (bool, np.bool_)):
        return None
    if isinstance(value, np.ndarray) and value.ndim == 0:  # a 0-d array from numpy arithmetic
        return _integer(value[()])
    try:
        return operator.index(value)
    except TypeError:
        return None


def _kind(low: int) -> str:
    return "a non-negative integer" if low == 0 else "a positive integer" if low == 1 else "an integer"


def count(value, name: str, low: int = 0, high: int | None = INT32_MAX, why: str = "") -> int:
    """``value`` as an int in ``low..high`` (both included; ``high`` defaults to the engine's
    32-bit limit; None: no upper bound, for a caller that checks what the value leads to).
    Refuses bools, floats (even integral ones) and anything else that is not an integer, with a
    ValueError naming ``name``, the value and the range; ``why`` (e.g. ": each level doubles the
    cells") explains a ``high`` below the engine's limit."""
    number = _integer(value)
    span = _kind(low) if high is None else f"{_kind(low)} in {low}..{high}{why}"
    if number is None:
        raise ValueError(f"{name} must be {span}, got {value!r} ({type(value).__name__})")
    if number < low:
        raise ValueError(f"{name} must be at least {low}, got {number} ({span})")
    if high is not None and number > high:
        raise ValueError(f"{name} must be at most {high}, got {number} ({span})")
    return number


def optional_count(value, name: str, low: int = 0) -> int | None:
    """None (a keyword not given: the options record's field stays) or :func:`count`."""
    return None if value is None else count(value, name, low)


def index(value, name: str, limit: int, ids: str = "ids") -> int:
    """``value`` as an id in ``0..limit − 1``: ``name {value} does not exist`` otherwise, with
    the range of ``ids`` (e.g. "vertex ids"). Refuses bools and non-integers."""
    number = _integer(value)
    if number is None:
        raise ValueError(f"{name} must be an integer index, got {value!r} ({type(value).__name__})")
    if not 0 <= number < limit:
        raise ValueError(f"{name} {number} does not exist ({ids} are 0..{limit - 1})")
    return number


def index_array(values, name: str, limit: int | None = None, what: str = "a valid index") -> np.ndarray:
    """``values`` as a C-contiguous int64 array of the same shape, every entry in
    ``0..limit − 1`` (``limit`` None: only that it fits in int64, the caller checks the
    range). Refuses non-integer dtypes (bool, float, object), uint64 entries beyond int64
    (which a cast would wrap to negative numbers), negatives and entries ≥ ``limit``, naming
    the first offending entry, its position and ``what`` it is not ("a vertex of the mesh")."""
    array = np.asarray(values)
    if array.dtype.kind not in "iu":
        raise ValueError(f"{name} must hold integer indices, got dtype {array.dtype}")
    if array.dtype.kind == "u" and array.dtype.itemsize == 8:
        beyond = array > _INT64_MAX
        if beyond.any():
            where = _first(beyond)
            raise ValueError(f"{name}{_brackets(where)} = {int(array[where])} is beyond int64: it is not {what}"
                             + ("" if limit is None else f" ({name} must hold 0..{limit - 1})"))
    array = np.ascontiguousarray(array, dtype=np.int64)
    if limit is not None:
        bad = (array < 0) | (array >= limit)
        if bad.any():
            where = _first(bad)
            raise ValueError(f"{name}{_brackets(where)} = {int(array[where])} is not {what} "
                             f"({name} must hold 0..{limit - 1})")
    return array


def _first(mask: np.ndarray) -> tuple:
    """The index tuple of the first True entry of ``mask`` (C order)."""
    return np.unravel_index(int(np.flatnonzero(mask)[0]), mask.shape)


def _brackets(where: tuple) -> str:
    return "[" + ", ".join(str(int(i)) for i in where) + "]"


def size(n_points: int, n_cells: int, given: str) -> None:
    """Refuse a mesh with more vertices or cells than the engine's 32-bit ids can number;
    ``given`` names the input that asks for it (e.g. "divisions (1099511627776, 2)")."""
    if n_points > INT32_MAX or n_cells > INT32_MAX:
        raise ValueError(f"{given} would make a mesh too large: {n_points} vertices and {n_cells} cells, but "
                         f"vertex and cell ids are 32-bit in the engine (at most 2**31 − 1 = {INT32_MAX} of each)")


def positive(value, name: str) -> float:
    """``value`` as a float, positive and finite; else a ValueError naming ``name`` and the value."""
    return _real(value, name, float(value) > 0, "positive")


def non_negative(value, name: str) -> float:
    """``value`` as a float, at least 0 and finite; else a ValueError naming ``name`` and the value."""
    return _real(value, name, float(value) >= 0, "non-negative")


def _real(value, name: str, in_range: bool, kind: str) -> float:
    if not (in_range and math.isfinite(float(value))):
        raise ValueError(f"{name} must be {kind} and finite, got {value}")
    return float(value)


def coordinates(value, shape: tuple, name: str) -> np.ndarray:
    """``value`` as a C-contiguous float64 array of ``shape`` with finite entries (a point, a
    segment's ends, a triangle's corners); else a ValueError naming ``name``."""
    array = np.asarray(value, dtype=np.float64)
    if array.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got non-finite coordinates {array.tolist()}")
    return np.ascontiguousarray(array)
