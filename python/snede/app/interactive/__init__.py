"""The live window and what it stands on (issue 37): pointer events (``events``), the scenes'
fixed cameras (``view``), the tools the pointer drives (``tools``), the headless
``ToolSession`` (``session``), recordings (``recording``) and their replay (``replay``).

``python -m snede replay FILE [--check] [--out DIR]`` replays a recording headless.
"""
from snede.app.interactive.events import PointerEvent  # noqa: F401
from snede.app.interactive.replay import ReplayResult, replay  # noqa: F401
from snede.app.interactive.session import ToolSession  # noqa: F401
