"""Reading the JSON files of the interactive commands (events, recordings) with one-line errors."""
from __future__ import annotations

import json
from pathlib import Path

MAX_DEPTH = 32  # of nested lists and objects; an events file or a recording has 4 (a move's blade: a list of points)


def read(path, what: str):
    """The JSON content of ``path``; ValueError naming ``what`` (e.g. "events file") and the
    path when it does not exist, is not JSON or nests deeper than MAX_DEPTH (which Python's
    parser, and later every message that shows a value, meets as a RecursionError)."""
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise ValueError(f"{what} {path} does not exist") from None
    too_deep = ValueError(f"{what} {path} nests lists or objects more than {MAX_DEPTH} deep (no {what} does)")
    try:
        content = json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"{what} {path} is not JSON: {error}") from None
    except RecursionError:
        raise too_deep from None
    if depth(content) > MAX_DEPTH:
        raise too_deep
    return content


def depth(value) -> int:
    """How deeply lists and objects nest in ``value`` (a number or a string: 0), without recursion."""
    deepest, level = 0, [(value, 0)]
    while level:
        item, d = level.pop()
        children = item.values() if isinstance(item, dict) else item if isinstance(item, list) else None
        if children is not None:
            deepest = max(deepest, d + 1)
            level.extend((child, d + 1) for child in children)
    return deepest
