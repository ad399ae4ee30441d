"""``view`` and ``replay`` of a scene file (issue 37): the tool of its first ``[[tool]]`` table —
a scalpel cutting a tetrahedral beam, the 3D needle entering a cube — driven by scripted
events; the recording keeps the file's path and checksum, so a changed file is refused in one
line; and the built-in 3D needle scene (``needle3d``) pushed alike."""
import json
import subprocess
import sys

import numpy as np
import pytest

from snede.app.interactive import ToolSession, replay
from snede.app.interactive.recording import save
from tool_scripts import STEPS, play

SCALPEL_FILE = """name = "beam-cut"

[mesh]
shape = "box"
size = [0.2, 0.05, 0.05]
divisions = [12, 3, 3]

[material]
name = "neohookean"
E = 1e5
nu = 0.3

[[hold]]
side = "x = min"

[loads]
gravity = [0.0, 0.0, -9.81]

[[tool]]
kind = "scalpel"
start = [[0.056, -0.025, 0.06], [0.056, 0.075, 0.06]]   # a blade along y, wider than the beam
end = [[0.056, -0.025, 0.01], [0.056, 0.075, 0.01]]
moves = 8
"""

NEEDLE_FILE = """name = "cube-needle"

[mesh]
shape = "box"
size = [0.1, 0.1, 0.1]
divisions = [2, 2, 2]
target_cells = 384

[material]
name = "linear"
E = 5e3
nu = 0.4

[[hold]]
side = "z = min"

[solver]
method = "cg"
rtol = 1e-3

[[tool]]
kind = "needle"
entry = [-0.005, 0.0513, 0.0489]
direction = [1.0, 0.0, 0.0]
depth = 0.03
steps = 10
h_ref = 0.01
"""


def snede(*arguments):
    return subprocess.run([sys.executable, "-m", "snede", *map(str, arguments)], capture_output=True, text=True,
                          timeout=300)


def scene_file(tmp_path, text: str) -> str:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return str(path)


def straight_drag(session, start, end) -> list[dict]:
    """A drag from scene point ``start`` to ``end`` in window coordinates (the session's view)."""
    from snede.app.interactive.events import drag

    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    return drag(session.tool.name, [session.view.window(start + (end - start) * k / STEPS) for k in range(STEPS + 1)])


def blade_drag(session) -> list[dict]:
    """The blade's middle from the file's start down 5 cm, on the plane the pointer moves on."""
    middle = np.asarray(session.tool.plane[0])
    return straight_drag(session, middle, middle - [0.0, 0.0, 0.05])


def push(session, distance: float) -> list[dict]:
    return straight_drag(session, session.tool.entry, session.tool.entry + distance * session.tool.direction)


def test_a_drag_cuts_the_scene_files_beam_and_replays(tmp_path):
    session = ToolSession(scene_file(tmp_path, SCALPEL_FILE))
    faces_before = len(session.body.mesh.boundary_faces())
    play(session, blade_drag(session))
    lips = session.tool.lips()
    assert len(lips) > 0 and len(session.body.mesh.boundary_faces()) == faces_before + len(lips)
    blades = np.array([m["blade"] for m in session.moves if m["action"] == "move"])
    # The file's blade, moved: its span kept, its steps the file's (start to end over its moves).
    assert np.allclose(blades[:, 1] - blades[:, 0], [0.0, 0.1, 0.0])
    assert (np.linalg.norm(np.diff(blades[:, 0], axis=0), axis=1) >= 0.05 / 8 * (1 - 1e-12)).all()
    recording = session.recording()
    assert recording["scene_file"]["path"] == session.name and len(recording["scene_file"]["sha256"]) == 64
    recorded = save(recording, tmp_path / "cut.json")
    done = snede("replay", recorded, "--check", "--out", tmp_path / "out")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out" / "beam-cut" / "beam-cut.png").stat().st_size > 0


def test_a_changed_scene_file_is_refused_in_one_line(tmp_path):
    session = ToolSession(scene_file(tmp_path, SCALPEL_FILE))
    play(session, blade_drag(session))
    recorded = save(session.recording(), tmp_path / "cut.json")
    (tmp_path / "scene.toml").write_text(SCALPEL_FILE.replace("E = 1e5", "E = 2e5"))
    done = snede("replay", recorded, "--check")
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and "has changed since the recording was made" in lines[0]


def test_a_push_inserts_the_scene_files_needle_and_replays(tmp_path):
    session = ToolSession(scene_file(tmp_path, NEEDLE_FILE))
    assert session.tool.step == pytest.approx(0.03 / 10)
    play(session, push(session, 0.02))
    needle = session.tool.needle
    advances = [m for m in session.moves if m["action"] == "advance"]
    assert needle.depth == pytest.approx(sum(m["distance"] for m in advances)) and len(advances) >= 6
    assert len(needle.needle_nodes) > 0 and all(m["converged"] for m in advances)
    assert replay(session.recording()).matches


def test_the_needle3d_scene_is_pushed_along_its_axis():
    session = ToolSession("needle3d", {"divisions": 16})
    play(session, push(session, 0.02))
    needle = session.tool.needle
    assert needle.depth == pytest.approx(0.02 - 0.02 % session.tool.step, abs=1e-12) and len(needle.needle_nodes) > 0
    assert replay(session.recording()).matches


@pytest.mark.parametrize("text, options, fragment", [
    (SCALPEL_FILE.split("[[tool]]")[0], {}, "has no [[tool]] table"),
    (SCALPEL_FILE, {"divisions": 8}, "unknown scene file option(s) divisions"),
    (SCALPEL_FILE.replace("moves = 8", "moves = 0"), {}, "moves"),
])
def test_bad_scene_files_give_one_line(tmp_path, text, options, fragment):
    with pytest.raises(ValueError, match=None) as error:
        ToolSession(scene_file(tmp_path, text), options)
    assert fragment in str(error.value) and "\n" not in str(error.value)


def test_view_of_a_scene_file_records_a_cut_that_replays(display, tmp_path):
    pytest.importorskip("pyvista", reason="the window needs pyvista (tools/requirements.txt)")
    path = scene_file(tmp_path, SCALPEL_FILE)
    scripted, recording = tmp_path / "drag.json", tmp_path / "cut.json"
    scripted.write_text(json.dumps(blade_drag(ToolSession(path))))
    done = snede("view", path, "--events", scripted, "--exit", "--record", recording)
    assert done.returncode == 0, done.stderr
    assert sum(m.get("faces_dissected", 0) for m in json.loads(recording.read_text())["moves"]) > 0
    assert snede("replay", recording, "--check").returncode == 0
