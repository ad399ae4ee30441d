"""``python -m snede replay FILE [--check] [--out DIR]``: status 0 only when the replay matches the
digest, 1 when it does not, 2 with one line for a missing or bad file or an unknown scene."""
import json
import math
import subprocess
import sys

import pytest

from snede.interactive.recording import save
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
    digest["points"]["sum"] += 2 * math.sqrt(digest["points"]["size"]) * recording["rtol"] * digest["displacement"]["norm"]
    cut_recording.write_text(json.dumps(recording))
    done = snede("replay", cut_recording, "--check")
    assert done.returncode == 1
    assert "replay --check: points: sum" in done.stderr
    assert snede("replay", cut_recording).returncode == 0  # without --check it only says so


def test_a_recorded_needle_push_replays(needle_session, tmp_path):
    play(needle_session, needle_events(needle_session, 0.01))
    path = save(needle_session.recording(), tmp_path / "needle.json")
    assert snede("replay", path, "--check").returncode == 0


@pytest.mark.parametrize("content, fragment", [
    (None, "does not exist"),
    ("{", "is not JSON"),
    ('{"format": 1}', "not a recording, it has no 'scene', 'options', 'moves', 'digest'"),
    ('{"format": 1, "scene": "nope", "options": {}, "moves": [], "digest": {}}', "unknown scene 'nope'"),
    ('{"format": 1, "scene": "cut", "options": {"divisions": 12}, "moves": [{"t": 0, "tool": "needle", '
     '"action": "advance", "distance": 0.01}], "digest": {}}', "move 0: tool 'needle'"),
])
def test_bad_recordings_give_one_line(tmp_path, content, fragment):
    path = tmp_path / "recording.json"
    if content is not None:
        path.write_text(content)
    done = snede("replay", path, "--check")
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("python -m snede: error:") and fragment in lines[0], done.stderr
