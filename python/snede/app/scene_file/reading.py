"""Checked reading of a scene file's TOML tables: each value is checked as it is read, against a
``Kind`` that says what it must be; the keys a table holds that its reader never asked for are
refused, with the nearest key it did ask for. Every error is a ``SceneFileError``, one line:
``<file>: <key> <what is wrong>``."""
from __future__ import annotations

import difflib
import json
import math
from dataclasses import dataclass
from typing import Callable, NoReturn

from snede._errors import Error


class SceneFileError(Error, ValueError):
    """A mistake in a scene file: one line naming the file and the key."""


REFUSED = object()  # what a Kind's convert returns for a value it does not take
REQUIRED = object()  # the default of a key that must be given


@dataclass(frozen=True)
class Kind:
    """What a value must be: ``what`` for the error message ("a positive number"), ``convert``
    the value as used, or REFUSED."""

    what: str
    convert: Callable[[object], object]


def is_number(value) -> bool:
    """A finite TOML integer or float (not a boolean)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def number_kind(what: str, accept: Callable[[float], bool]) -> Kind:
    return Kind(what, lambda v: float(v) if is_number(v) and accept(v) else REFUSED)


def integer_kind(what: str, low: int, high: int | None = None) -> Kind:
    return Kind(what, lambda v: v if isinstance(v, int) and not isinstance(v, bool) and v >= low
                and (high is None or v <= high) else REFUSED)


def vector_kind(what: str, length: int, item: Kind, accept: Callable[[list], bool] = lambda v: True) -> Kind:
    """A list of ``length`` values of kind ``item``."""
    def convert(value):
        if not isinstance(value, list) or len(value) != length:
            return REFUSED
        items = [item.convert(v) for v in value]
        return REFUSED if any(v is REFUSED for v in items) or not accept(items) else items
    return Kind(what, convert)


def choice(names) -> Kind:
    names = tuple(names)
    return Kind("one of " + ", ".join(f'"{n}"' for n in names), lambda v: v if v in names else REFUSED)


NUMBER = number_kind("a number", lambda v: True)
POSITIVE = number_kind("a positive number", lambda v: v > 0)
NON_NEGATIVE = number_kind("a number ≥ 0", lambda v: v >= 0)
COUNT = integer_kind("a positive integer", 1)
SEED = integer_kind("an integer ≥ 0", 0)
BOOLEAN = Kind("true or false", lambda v: v if isinstance(v, bool) else REFUSED)
TEXT = Kind("a string", lambda v: v if isinstance(v, str) and v.strip() else REFUSED)
POINT = vector_kind("3 numbers [x, y, z]", 3, NUMBER)
DIRECTION = vector_kind("3 numbers [x, y, z], not all 0", 3, NUMBER, lambda v: any(v))
POSITIVE_3 = vector_kind("3 positive numbers", 3, POSITIVE)
COUNTS_3 = vector_kind("3 positive integers", 3, COUNT)
SEGMENT = vector_kind("two points [[x, y, z], [x, y, z]]", 2, POINT, lambda v: v[0] != v[1])


def shown(value) -> str:
    """A value as TOML writes it (strings in double quotes, true/false, [a, b])."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(shown(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {shown(v)}" for k, v in value.items()) + "}"
    return str(value)


def _likeness(a: str, b: str) -> float:
    return difflib.SequenceMatcher(None, a.lower(), b.lower()).ratio()


def nearest(word: str, known) -> str | None:
    """The known word most like ``word`` (letter case aside), if it is like it at all."""
    best = max(known, key=lambda k: _likeness(word, k), default=None)
    return best if best is not None and _likeness(word, best) >= LIKE else None


LIKE = 0.5  # how alike (difflib's ratio, letter case aside) a misspelling and the key it suggests are


class Table:
    """A TOML table of the file ``source``, named ``name`` in messages ("material",
    "tool[2]", "" for the file itself). Every ``get``/``has``/``table``/``tables`` records the
    key as one the table may hold; ``close()`` refuses the others."""

    def __init__(self, values: dict, name: str, source: str):
        self.values, self.name, self.source = values, name, source
        self.asked: list[str] = []

    def key(self, key: str) -> str:
        return f"{self.name}.{key}" if self.name else key

    def fail(self, key: str | None, message: str) -> NoReturn:
        """Raise the one-line error about ``key`` (None: the table itself)."""
        raise SceneFileError(f"{self.source}: {self.key(key) if key else self.name} {message}")

    def _ask(self, key: str) -> None:
        if key not in self.asked:
            self.asked.append(key)

    def has(self, key: str) -> bool:
        self._ask(key)
        return key in self.values

    def get(self, key: str, kind: Kind, default=REQUIRED, meaning: str = ""):
        """The value of ``key`` as ``kind`` converts it; ``default`` when it is absent (REQUIRED:
        an error, which says what it means)."""
        if not self.has(key):
            if default is REQUIRED:
                for other in self.values:  # a misspelling of the key is named as such
                    if other not in self.asked and nearest(other, [key]):
                        self._unknown(other, [key])
                self.fail(key, f"is missing: {meaning or kind.what}")
            return default
        value = kind.convert(self.values[key])
        if value is REFUSED:
            self.fail(key, f"must be {kind.what}, got {shown(self.values[key])}")
        return value

    def table(self, key: str, required: str = "") -> "Table | None":
        """The sub-table ``key`` (``[key]`` or ``key = {...}``); None if absent, unless
        ``required`` says why it is needed."""
        if not self.has(key):
            if required:
                raise SceneFileError(f"{self.source}: [{self.key(key)}] is missing: {required}")
            return None
        value = self.values[key]
        if not isinstance(value, dict):
            self.fail(key, f"must be a table ([{self.key(key)}] or {{...}}), got {shown(value)}")
        return Table(value, self.key(key), self.source)

    def tables(self, key: str) -> list["Table"]:
        """The array of tables ``[[key]]``, each named ``key[1]``, ``key[2]``, ...; [] if absent."""
        if not self.has(key):
            return []
        value = self.values[key]
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            self.fail(key, f"must be an array of tables, each written [[{self.key(key)}]], got {shown(value)}")
        return [Table(v, f"{self.key(key)}[{k}]", self.source) for k, v in enumerate(value, start=1)]

    def one_of(self, keys) -> str:
        """The one key of ``keys`` the table holds (an error if none or several)."""
        given = [k for k in keys if self.has(k)]
        if len(given) != 1:
            listed = ", ".join(keys)
            self.fail(None, f"needs exactly one of {listed}, got {', '.join(given) if given else 'none'}")
        return given[0]

    def close(self) -> None:
        """Refuse the keys no reader asked for, suggesting the nearest one asked for."""
        for key in self.values:
            if key not in self.asked:
                self._unknown(key, self.asked)

    def _unknown(self, key: str, known: list[str]) -> NoReturn:
        """Refuse ``key``, suggesting the most like of ``known`` (all the table's keys, which are
        listed, or the one missing key it looks like)."""
        where = f"[{self.name}]" if self.name else "a scene file"
        like = nearest(key, known)
        hint = f"; did you mean {self.key(like)}?" if like else ""
        keys = "" if known is not self.asked else f" (its keys: {', '.join(known)})" if known else " (it takes no keys)"
        raise SceneFileError(f"{self.source}: {self.key(key)} is not a key of {where}{hint}{keys}")
