"""``python -m snede replay FILE [--check] [--out DIR]``: status 0 only when the replay matches the
digest, 1 when it does not, 2 with one line for a missing or bad file (a digest value that is not
a finite number among them) or an unknown scene."""
import json
import math
import subprocess
import sys

import pytest

from snede.app.interactive.recording import save
from tool_scripts import cut_events, needle_events, play


def snede(*arguments):
    return subprocess.run([sys.executable, "-m", "snede", *map(str, arguments)], capture_output=True, text=True,
                          timeout=300)


@pytest.fixture
def cut_recording(cut_session, tmp_path):
    play(cut_session, cut_events(cut_session))
    return save(cut_session.recording(), tmp_path / "cut.json")


def test_a_recorded_cut_replays_and_checks(cut_recording, tmp_path):
    done = snede("replay", cut_recording, "--check", "--out", tmp_path / "out")
    assert done.returncode == 0, done.stderr
    assert "matches the recording's digest" in done.stdout
    for name in ("cut.xdmf", "cut.h5", "cut.png"):
        assert (tmp_path / "out" / "cut" / name).stat().st_size > 0


def test_a_tampered_digest_fails_the_check(cut_recording):
    recording = json.loads(cut_recording.read_text())
    digest = recording["digest"]
    # twice the sum's tolerance, √n·rtol·|u| (recording.compare)
    digest["points"]["sum"] += 2 * math.sqrt(digest["points"]["size"]) * recording["rtol"] * \
        digest["displacement"]["norm"]
    cut_recording.write_text(json.dumps(recording))
    done = snede("replay", cut_recording, "--check")
    assert done.returncode == 1
    assert "replay --check: points: sum" in done.stderr
    assert snede("replay", cut_recording).returncode == 0  # without --check it only says so


@pytest.mark.parametrize("value, shown", [(math.inf, "Infinity"), ("0.89", '"0.89"')])
def test_a_digest_value_that_is_no_finite_number_fails_in_one_line(cut_recording, value, shown):
    """Infinity made the tolerance infinite and the check pass; a string was a TypeError."""
    recording = json.loads(cut_recording.read_text())
    recording["digest"]["displacement"]["norm"] = value
    cut_recording.write_text(json.dumps(recording))
    done = snede("replay", cut_recording, "--check")
    assert done.returncode == 2
    assert done.stderr == (f"python -m snede: error: recording {cut_recording}: digest.displacement.norm must be a "
                           f"finite number, got {shown}\n")


def test_a_recorded_needle_push_replays(needle_session, tmp_path):
    play(needle_session, needle_events(needle_session, 0.01))
    path = save(needle_session.recording(), tmp_path / "needle.json")
    assert snede("replay", path, "--check").returncode == 0


GOOD_DIGEST = {"points": {"size": 3, "sum": 1.0, "norm": 1.0, "weighted": 1.0},
               "displacement": {"size": 3, "sum": 0.0, "norm": 0.0, "weighted": 0.0},
               "cells": {"size": 4, "sum": 6, "weighted": 10}}


def a_recording(**changes) -> str:
    recording = {"format": 1, "scene": "cut", "options": {"divisions": 12}, "moves": [], "digest": GOOD_DIGEST}
    return json.dumps({**recording, **changes})


def tampered(name, key, value) -> str:
    """A recording whose digest has ``value`` for ``name``.``key``."""
    return a_recording(digest={**GOOD_DIGEST, name: {**GOOD_DIGEST[name], key: value}})


@pytest.mark.parametrize("content, fragment", [
    (None, "does not exist"),
    ("{", "is not JSON"),
    ('{"format": 1}', "not a recording, it has no 'scene', 'options', 'moves', 'digest'"),
    (a_recording(scene="nope"), "unknown scene 'nope'"),
    (a_recording(moves=[{"t": 0, "tool": "needle", "action": "advance", "distance": 0.01}]), "move 0: tool 'needle'"),
    # A digest value that no comparison could reject, or none could accept (issue 48, item 2)
    (tampered("displacement", "norm", math.inf), "digest.displacement.norm must be a finite number, got Infinity"),
    (tampered("displacement", "sum", math.nan), "digest.displacement.sum must be a finite number, got NaN"),
    (tampered("points", "norm", -math.inf), "digest.points.norm must be a finite number, got -Infinity"),
    (tampered("points", "sum", "32.2"), 'digest.points.sum must be a finite number, got "32.2"'),
    (tampered("points", "weighted", json.loads("1e999")),
     "digest.points.weighted must be a finite number, got Infinity"),
    (tampered("points", "weighted", 10**400), "digest.points.weighted must be a finite number"),
    (tampered("points", "size", 3.0), "digest.points.size must be an integer, got 3.0"),
    (tampered("cells", "sum", True), "digest.cells.sum must be an integer, got true"),
    (a_recording(digest={"points": GOOD_DIGEST["points"], "cells": GOOD_DIGEST["cells"]}),
     "digest.displacement must be an object"),
    (a_recording(digest={**GOOD_DIGEST, "cells": {"size": 4, "sum": 6}}), "digest.cells.weighted must be an integer, "
                                                                           "got missing"),
    (a_recording(rtol=1e300), "'rtol' must be a number in (0, 1), got 1e+300"),
    # tracebacks with status 1 before (issue 48, item 11)
    ("[" * 5000 + "]" * 5000, "nests lists or objects more than 32 deep (no recording does)"),
    (a_recording(moves=[{"t": 0, "tool": "scalpel", "action": "move", "blade": json.loads("[" * 100 + "]" * 100)}]),
     "nests lists or objects more than 32 deep"),
    (a_recording(options={"divisions": "12"}), 'scene option \'divisions\' must be a positive integer, got "12"'),
])
def test_bad_recordings_give_one_line(tmp_path, content, fragment):
    path = tmp_path / "recording.json"
    if content is not None:
        path.write_text(content)
    done = snede("replay", path, "--check")
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("python -m snede: error:") and fragment in lines[0], done.stderr
