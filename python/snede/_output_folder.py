"""Where a scene writes its files: ``snede.output_folder(name)`` is ``<out>/<name>``, with
``<out>`` the ``--out`` of ``python -m snede run`` (which hands it to a scene script through
the environment variable ``SNEDE_OUT``), else ``out``."""
from __future__ import annotations

import os
from pathlib import Path

VARIABLE = "SNEDE_OUT"  # set by ``python -m snede run script.py --out DIR`` for the script
DEFAULT = Path("out")


def output_folder(name: str) -> Path:
    """The folder the scene ``name`` writes into, created: ``<out>/<name>``, where ``<out>`` is
    the ``--out`` given to ``python -m snede run`` (default ``out``, relative to the working
    directory). A script run directly (``python scene.py``) writes into ``out/<name>``."""
    name = str(name)
    if not name or Path(name).is_absolute() or ".." in Path(name).parts:
        raise ValueError(f"output_folder takes a scene's name (a folder inside the output folder), got {name!r}")
    folder = Path(os.environ.get(VARIABLE) or DEFAULT) / name
    folder.mkdir(parents=True, exist_ok=True)
    return folder
