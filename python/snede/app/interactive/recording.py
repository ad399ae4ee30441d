"""Recordings of tool sessions (``python -m snede view SCENE --record FILE``; replayed by
``snede.app.interactive.replay``).

A recording is JSON: the scene's name (a scene file's path) and options, the method and
tolerance it relaxed with, the snede version, every tool move with its time
(``ToolSession.moves``) and a digest of the final state. After the window's reset (key r) it
holds the moves since the last reset only, and its ``resets`` and ``note`` say so.

A scene file's recording keeps the file's path and the sha256 of its bytes, not its text: the
file may name a mesh file beside it (``[mesh] surface``), which its text alone would not bring
along. A replay reads the file again and refuses, in one line, one that has changed.

The digest keeps, per array (the mesh's points and cells, the displacement), its size, sum,
norm and a weighted sum — not a hash of floats — and a replay compares what the computation
determines: sizes and the cells' integer sums exactly, the float sums to a tolerance derived
from the recording's ``rtol`` (``compare``). The bits below that tolerance differ from one CPU to
another (another SIMD width, fused multiply-adds) and are not the session's result. A digest
value that is not a finite number (``Infinity`` would make the tolerance infinite) or an integer
where one is due is refused when the recording is read.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from snede.app.interactive import json_file

FORMAT = 1  # of the JSON; a newer one is refused
FLOAT_ARRAYS = ("points", "displacement")
FLOAT_KEYS = ("size", "sum", "norm", "weighted")
CELL_KEYS = ("size", "sum", "weighted")


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


def compare(expected: dict, actual: dict, rtol: float) -> list[str]:
    """The differences between a recording's digest and a replay's, one line each (none: they
    match); ``rtol`` is the tolerance the session's solves stopped at.

    Sizes and the cells' integer sums must be equal. The displacement comes from iterative
    solves stopped where ‖r‖ ≤ rtol·(the forces' scale): they stop anywhere in that set, and
    rounding that differs between CPUs moves where, so the displacement is determined to about
    δ = rtol·‖u‖ (‖u‖ the replay's), not to its last bits. The points inherit that much (the
    scalpel snaps vertices where it meets the deformed body). An array whose entries move by
    ‖δa‖ ≤ δ moves its norm by at most δ, its sum by √n·δ and its weighted sum by ‖w‖·δ
    (Cauchy-Schwarz); to each is added the round-off of the sums themselves, (n − 1)·ε·Σ|aᵢ| ≤
    n·ε·√n·‖a‖. A wrong move or a solve to another tolerance moves them by far more."""
    problems = []
    spread = rtol * actual["displacement"]["norm"]
    for name in (*FLOAT_ARRAYS, "cells"):
        want, got = expected[name], actual[name]
        if want["size"] != got["size"]:
            problems.append(f"{name}: {got['size']} entries, the recording has {want['size']}")
            continue
        if name == "cells":
            problems += [f"cells: {key} {got[key]}, the recording has {want[key]}"
                         for key in ("sum", "weighted") if want[key] != got[key]]
            continue
        n = got["size"]
        round_off = n * np.finfo(np.float64).eps * math.sqrt(n) * got["norm"]
        factors = {"norm": 1.0, "sum": math.sqrt(n), "weighted": float(np.linalg.norm(_weights(n)))}
        for key, factor in factors.items():
            tolerance = factor * spread + round_off
            if not abs(want[key] - got[key]) <= tolerance:
                problems.append(f"{name}: {key} {got[key]!r}, the recording has {want[key]!r} "
                                f"(tolerance {tolerance:.3g})")
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
    rtol = recording.get("rtol")
    if rtol is not None and not (_is_number(rtol) and 0 < rtol < 1):
        # the digest's tolerance grows with it (``compare``)
        raise ValueError(f"{source}: 'rtol' must be a number in (0, 1), got {json.dumps(rtol)}")
    _check_digest(recording["digest"], source)
    return recording


def _is_number(value) -> bool:
    """A finite JSON number (not a boolean; an integer too large for a float is not finite)."""
    try:
        return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    except OverflowError:
        return False


def _check_digest(values, source: str) -> None:
    """Every value a digest must have, of its type: integers for sizes and the cells' sums, finite
    numbers for the float sums (not Infinity or NaN, which no comparison would reject)."""
    for name in (*FLOAT_ARRAYS, "cells"):
        part = values.get(name) if isinstance(values, dict) else None
        keys = CELL_KEYS if name == "cells" else FLOAT_KEYS
        if not isinstance(part, dict):
            raise ValueError(f"{source}: digest.{name} must be an object with {', '.join(keys)}")
        for key in keys:
            value = part.get(key)
            integer = name == "cells" or key == "size"
            if not (_is_number(value) and (isinstance(value, int) or not integer)):
                shown = "missing" if key not in part else json.dumps(value)
                raise ValueError(f"{source}: digest.{name}.{key} must be "
                                 f"{'an integer' if integer else 'a finite number'}, got {shown}")


def load(path) -> dict:
    """A recording from its JSON file, checked."""
    return checked(json_file.read(path, "recording"), f"recording {path}")
