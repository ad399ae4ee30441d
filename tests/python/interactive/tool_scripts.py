"""The scripts the interactive tests play: small scenes (seconds), the drags that cut and push."""
from pathlib import Path

import numpy as np

from snede.app.interactive import ToolSession
from snede.app.interactive.events import drag, events

CUT_DIVISIONS = 12  # the smallest beam whose cut opens over several faces (8 leaves a notch of 4)
NEEDLE_OPTIONS = {"divisions": 8, "speed": 1.0}  # the slab at h3, one h_ref per update
STEPS = 20


def cut_session() -> ToolSession:
    return ToolSession("cut", {"divisions": CUT_DIVISIONS})


def needle_session() -> ToolSession:
    return ToolSession("needle", dict(NEEDLE_OPTIONS))


def top_at(session, x: float) -> float:
    """The sagging beam's deformed top (z) at x, on its front face: the vertices nearest x."""
    points = session.body.mesh.points
    front_top = np.isclose(points[:, 1], 0.0) & np.isclose(points[:, 2], points[:, 2].max())
    nearest = front_top & np.isclose(np.abs(points[:, 0] - x), np.abs(points[front_top, 0] - x).min())
    return float((points[nearest, 2] + session.body.displacement[nearest, 2]).mean())


def cut_events(session, x: float = 0.056, depth: float = 0.7) -> list[dict]:
    """A drag on the beam's front face from a centimetre above its top at x down to ``depth`` of
    its height below the top, in window coordinates (the session's view)."""
    from snede.app.scenes.cut import HEIGHT

    top = top_at(session, x)
    start, end = (x, 0.0, top + 0.01), (x, 0.0, top - depth * HEIGHT)
    path = [session.view.window(np.add(start, (np.subtract(end, start)) * k / STEPS)) for k in range(STEPS + 1)]
    return drag("scalpel", path)


def needle_events(session, push: float) -> list[dict]:
    """A drag of ``push`` metres along the needle's shaft (+x) at its entry."""
    from snede.app.scenes.needle_slab import ENTRY

    path = [session.view.window((ENTRY[0] + push * k / STEPS, ENTRY[1], 0.0)) for k in range(STEPS + 1)]
    return drag("needle", path)


def play(session, entries) -> None:
    for event in events(entries):
        session.handle(event)


RECORDINGS = Path(__file__).parent / "recordings"


def record_all() -> list[Path]:
    """(Re)write the stored recordings (tests/python/interactive/recordings/) from the scripted
    drag and push: run this file when a change of the solvers or cutters is meant to change them."""
    from snede.app.interactive.recording import save

    cut, needle = cut_session(), needle_session()
    play(cut, cut_events(cut))
    play(needle, needle_events(needle, 0.02))
    return [save(cut.recording(), RECORDINGS / "cut_drag.json"), save(needle.recording(), RECORDINGS / "needle_push.json")]


if __name__ == "__main__":
    for path in record_all():
        print(f"wrote {path}")
