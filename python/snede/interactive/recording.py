"""Recordings of tool sessions (``python -m snede view SCENE --record FILE``; replayed by
``snede.interactive.replay``).

A recording is JSON: the scene's name (a scene file's path) and options, the method and
tolerance it relaxed with, the snede version, every tool move with its time
(``ToolSession.moves``) and a digest of the final state. After the window's reset (key r) it
holds the moves since the last reset only, and its ``resets`` and ``note`` say so.

A scene file's recording keeps the file's path and the sha256 of its bytes, not its text: the
file may name a mesh file beside it (``[mesh] surface``), which its text alone would not bring
along. A replay reads the file again and refuses, in one line, one that has changed.

The digest keeps, per array (the mesh's points and cells, the displacement), its size, sum,
norm and a weighted sum — not a hash of floats — so a replay matches it to a relative
tolerance (1e-12 of the array's norm) rather than bit for bit.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from snede.interactive import json_file

FORMAT = 1  # of the JSON; a newer one is refused
TOLERANCE = 1e-12  # relative, for the digest's sums


def _weights(n: int) -> np.ndarray:
    """Fixed weights in [-1, 1] for the weighted sum: a swap of two entries changes it."""
    return np.cos(0.7 * np.arange(n))


def _floats(array) -> dict:
    a = np.asarray(array, dtype=np.float64).ravel()
    return {"size": int(a.size), "sum": float(a.sum()), "norm": float(np.linalg.norm(a)),
            "weighted": float(a @ _weights(a.size))}


def digest(body) -> dict:
    """What a replay must reproduce: the mesh (points, cells) and the displacement."""
    cells = np.asarray(body.mesh.cells, dtype=np.int64).ravel()
    return {"points": _floats(body.mesh.points), "displacement": _floats(body.displacement),
            "cells": {"size": int(cells.size), "sum": int(cells.sum()),
                      "weighted": int(cells @ (np.arange(cells.size, dtype=np.int64) % 9973 + 1))}}


def compare(expected: dict, actual: dict, tolerance: float = TOLERANCE) -> list[str]:
    """The differences between two digests, one line each (none: they match). Sums of floats
    match within ``tolerance`` · their bound by Cauchy-Schwarz (√size · norm for the sum,
    ‖w‖ · norm for the weighted one); sizes and the cells' integer sums exactly."""
    problems = []
    for name in ("points", "displacement", "cells"):
        want, got = expected.get(name, {}), actual[name]
        if want.get("size") != got["size"]:
            problems.append(f"{name}: {got['size']} entries, the recording has {want.get('size')}")
            continue
        if name == "cells":
            problems += [f"cells: {key} {got[key]}, the recording has {want.get(key)}"
                         for key in ("sum", "weighted") if want.get(key) != got[key]]
            continue
        norm = max(abs(want.get("norm", 0.0)), abs(got["norm"]))
        bounds = {"norm": norm, "sum": math.sqrt(got["size"]) * norm,
                  "weighted": float(np.linalg.norm(_weights(got["size"]))) * norm}
        for key, bound in bounds.items():
            if not isinstance(want.get(key), (int, float)) or not abs(want[key] - got[key]) <= tolerance * bound:
                problems.append(f"{name}: {key} {got[key]!r}, the recording has {want.get(key)!r} "
                                f"(tolerance {tolerance * bound:.3g})")
    return problems


def make(session) -> dict:
    """The recording of a ``ToolSession`` as it is now."""
    import snede

    return {"format": FORMAT, "snede": snede.__version__, "scene": session.name, "options": session.options,
            "method": session.method, "rtol": session.rtol, "moves": list(session.moves),
            "digest": digest(session.body), **({"scene_file": session.scene_file} if session.scene_file else {}),
            **({"resets": session.resets, "note": f"the moves since the window's last reset (r, {session.resets} "
                "in all): the moves before it are not recorded, and the replay starts from the scene as built"}
               if session.resets else {})}


def save(recording: dict, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(recording, indent=1) + "\n")
    return path


def checked(recording, source: str) -> dict:
    if not isinstance(recording, dict):
        raise ValueError(f"{source}: a recording is a JSON object, got {type(recording).__name__}")
    missing = [key for key in ("format", "scene", "options", "moves", "digest") if key not in recording]
    if missing:
        raise ValueError(f"{source}: not a recording, it has no {', '.join(repr(m) for m in missing)}")
    if recording["format"] != FORMAT:
        raise ValueError(f"{source}: recording format {recording['format']!r}; this snede reads format {FORMAT}")
    scene_file = recording.get("scene_file")
    if scene_file is not None and not (isinstance(scene_file, dict) and isinstance(scene_file.get("path"), str)
                                       and isinstance(scene_file.get("sha256"), str)):
        raise ValueError(f"{source}: 'scene_file' must be an object with the file's 'path' and 'sha256'")
    if not isinstance(recording["options"], dict) or not isinstance(recording["moves"], list):
        raise ValueError(f"{source}: 'options' must be an object and 'moves' a list")
    for index, move in enumerate(recording["moves"]):
        if not isinstance(move, dict) or not {"t", "tool", "action"} <= set(move):
            raise ValueError(f"{source}: move {index} must be an object with 't', 'tool' and 'action', got {move!r}")
    return recording


def load(path) -> dict:
    """A recording from its JSON file, checked."""
    return checked(json_file.read(path, "recording"), f"recording {path}")
