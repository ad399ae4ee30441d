"""Pointer events (--events FILE.json): a bad event gives one line naming its index and field."""
import json

import pytest

from expected_errors import refused
from snede.app.interactive.events import drag, events, load

GOOD = {"t": 0.0, "type": "press", "x": 0.5, "y": 0.5, "tool": "scalpel"}


@pytest.mark.parametrize("change, fragments", [
    ({"t": -1.0}, ("event 0", "'t' must be at least 0")),
    ({"x": 1.5}, ("event 0", "'x' must be in [0, 1]")),
    ({"y": "top"}, ("event 0", "'y' must be a finite number")),
    ({"y": float("nan")}, ("event 0", "'y' must be a finite number")),
    ({"type": "click"}, ("event 0", "'type' must be one of press, move, release", "'click'")),
    ({"tool": "laser"}, ("event 0", "'tool' must be one of scalpel, needle", "'laser'")),
    ({"colour": "red"}, ("event 0", "unknown field(s) 'colour'")),
])
def test_a_bad_field_is_named(change, fragments):
    message = refused(lambda: events([{**GOOD, **change}]), *fragments)
    assert "\n" not in message


def test_a_missing_field_is_named():
    refused(lambda: events([{k: v for k, v in GOOD.items() if k != "x"}]), "event 0", "missing 'x'")


def test_the_sequence_is_checked():
    press, move = GOOD, {**GOOD, "type": "move", "t": 1.0}
    refused(lambda: events([press, {**move, "t": 0.5}, {**move, "t": 0.2}]),
            "event 2", "'t' goes back in time")
    refused(lambda: events([{**GOOD, "type": "release"}]), "event 0", "release without a press")
    refused(lambda: events([press, {**GOOD, "t": 1.0}]), "event 1", "press while the scalpel is still pressed")
    refused(lambda: events([press, {**move, "tool": "needle"}]), "event 1", "'tool' is needle while the scalpel")
    refused(lambda: events({"events": []}), "must be a list of events")


def test_a_drag_is_a_press_moves_and_a_release():
    entries = drag("needle", [(0.1, 0.5), (0.2, 0.5), (0.3, 0.5)])
    assert [e.type for e in events(entries)] == ["press", "move", "move", "release"]
    assert entries[-1]["x"] == 0.3


def test_files(tmp_path):
    path = tmp_path / "events.json"
    refused(lambda: load(path), f"events file {path} does not exist")
    path.write_text("[{")
    refused(lambda: load(path), f"events file {path} is not JSON")
    path.write_text(json.dumps([GOOD, {**GOOD, "type": "move", "x": 2}]))
    refused(lambda: load(path), f"events file {path}: event 1: 'x' must be in [0, 1]")
    path.write_text(json.dumps(drag("scalpel", [(0.1, 0.1), (0.2, 0.2)])))
    assert len(load(path)) == 3
