"""Reading the JSON files of the interactive commands (events, recordings) with one-line errors."""
from __future__ import annotations

import json
from pathlib import Path


def read(path, what: str):
    """The JSON content of ``path``; ValueError naming ``what`` (e.g. "events file") and the
    path when it does not exist or is not JSON."""
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise ValueError(f"{what} {path} does not exist") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"{what} {path} is not JSON: {error}") from None
