"""Pointer events: what the mouse does in the window, or a script does in its place
(``python -m snede view SCENE --events FILE.json``).

An event is ``{"t": seconds, "type": "press" | "move" | "release", "x": 0..1, "y": 0..1,
"tool": "scalpel" | "needle"}`` in window coordinates: x from the left, y from the top, as a
window reports them. A press takes up a tool and a release puts it down; moves in between drag
it (moves while nothing is pressed only hover). Bad events raise ``ValueError`` with one line
naming the event's index and the field.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from snede.app.interactive import json_file

TYPES = ("press", "move", "release")
TOOLS = ("scalpel", "needle")
FIELDS = ("t", "type", "x", "y", "tool")


@dataclass(frozen=True)
class PointerEvent:
    t: float
    type: str
    x: float
    y: float
    tool: str

    def as_dict(self) -> dict:
        return {name: getattr(self, name) for name in FIELDS}


def _number(entry: dict, name: str, where: str) -> float:
    value = entry[name]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where}: {name!r} must be a finite number, got {value!r}")
    return float(value)


def _choice(entry: dict, name: str, choices: tuple, where: str) -> str:
    value = entry[name]
    if value not in choices:
        raise ValueError(f"{where}: {name!r} must be one of {', '.join(choices)}, got {value!r}")
    return value


def event(entry, index: int) -> PointerEvent:
    """One event from its dictionary, checked (``index`` names it in errors)."""
    where = f"event {index}"
    if not isinstance(entry, dict):
        raise ValueError(f"{where}: must be an object with {', '.join(FIELDS)}, got {type(entry).__name__}")
    missing = [name for name in FIELDS if name not in entry]
    if missing:
        raise ValueError(f"{where}: missing {', '.join(repr(m) for m in missing)}")
    unknown = sorted(set(entry) - set(FIELDS))
    if unknown:
        raise ValueError(f"{where}: unknown field(s) {', '.join(repr(u) for u in unknown)} (the fields: "
                         f"{', '.join(FIELDS)})")
    t = _number(entry, "t", where)
    if t < 0:
        raise ValueError(f"{where}: 't' must be at least 0 (seconds from the start), got {t}")
    x, y = _number(entry, "x", where), _number(entry, "y", where)
    for name, value in (("x", x), ("y", y)):
        if not 0.0 <= value <= 1.0:
            raise ValueError(f"{where}: {name!r} must be in [0, 1] (window coordinates), got {value}")
    return PointerEvent(t, _choice(entry, "type", TYPES, where), x, y, _choice(entry, "tool", TOOLS, where))


def events(entries) -> list[PointerEvent]:
    """The events of a list of dictionaries, checked one by one and as a sequence: times do not
    go back, a release or a drag follows a press of the same tool, no press while one is held."""
    if not isinstance(entries, list):
        raise ValueError(f"pointer events must be a list of events, got {type(entries).__name__}")
    checked, held, last = [], None, 0.0
    for index, entry in enumerate(entries):
        e = event(entry, index)
        if e.t < last:
            raise ValueError(f"event {index}: 't' goes back in time ({e.t} after {last})")
        if e.type == "press" and held is not None:
            raise ValueError(f"event {index}: 'type' press while the {held} is still pressed (release it first)")
        if e.type == "release" and held is None:
            raise ValueError(f"event {index}: 'type' release without a press")
        if e.type != "press" and held is not None and e.tool != held:
            raise ValueError(f"event {index}: 'tool' is {e.tool} while the {held} is pressed")
        held = e.tool if e.type == "press" else None if e.type == "release" else held
        checked.append(e)
        last = e.t
    return checked


def load(path) -> list[PointerEvent]:
    """The events of a JSON file (a list of events), checked."""
    entries = json_file.read(path, "events file")
    try:
        return events(entries)
    except ValueError as error:
        raise ValueError(f"events file {path}: {error}") from None


def drag(tool: str, path, start: float = 0.0, interval: float = 0.05) -> list[dict]:
    """The events of a drag along ``path`` ((x, y) window points): a press at the first, moves
    through the rest, a release at the last, ``interval`` seconds apart."""
    points = [(float(x), float(y)) for x, y in path]
    kinds = ["press"] + ["move"] * (len(points) - 1) + ["release"]
    points = points + points[-1:]
    return [{"t": start + k * interval, "type": kind, "x": x, "y": y, "tool": tool}
            for k, (kind, (x, y)) in enumerate(zip(kinds, points))]
