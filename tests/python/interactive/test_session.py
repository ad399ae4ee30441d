"""The headless tool session (issue 37): a scripted drag across the cut scene cuts it, a scripted
push of the needle inserts it, and both record moves a replay repeats to the digest."""
import numpy as np

from expected_errors import refused
from snede.app.interactive import ToolSession, replay
from snede.app.interactive.recording import compare, digest
from tool_scripts import cut_events, needle_events, play


def test_a_drag_across_the_beam_cuts_it(cut_session):
    faces_before, points_before = len(cut_session.body.mesh.boundary_faces()), cut_session.body.mesh.n_points
    play(cut_session, cut_events(cut_session))
    lips = cut_session.tool.lips()
    assert len(lips) > 0
    # Every dissected face became two boundary faces, one on each lip: the boundary grew by the
    # incision, and the lips' vertices were split in two.
    assert len(cut_session.body.mesh.boundary_faces()) == faces_before + len(lips)
    assert cut_session.body.mesh.n_points > points_before
    moves = cut_session.moves
    assert sum(m.get("faces_dissected", 0) for m in moves) > 0
    assert [m["action"] for m in moves][0] == "move" and moves[-1]["action"] == "lift"
    assert all(m["converged"] for m in moves if m["action"] == "move")
    times = [m["t"] for m in moves]
    assert times == sorted(times)


def test_the_scalpel_moves_in_steps_no_shorter_than_the_scenes(cut_session):
    play(cut_session, cut_events(cut_session))
    blades = np.array([m["blade"] for m in cut_session.moves if m["action"] == "move"])
    steps = np.linalg.norm(np.diff(blades[:, 0], axis=0), axis=1)
    assert (steps >= cut_session.tool.step * (1 - 1e-12)).all()


def test_the_recording_replays_to_its_digest(cut_session):
    play(cut_session, cut_events(cut_session))
    recording = cut_session.recording()
    result = replay(recording)
    assert result.matches, result.mismatches
    assert result.moves == len(recording["moves"])


def test_a_tampered_digest_does_not_match(cut_session):
    """A norm off by three times its tolerance (rtol·|u|, recording.compare) is a mismatch."""
    play(cut_session, cut_events(cut_session))
    recording = cut_session.recording()
    norm = recording["digest"]["displacement"]["norm"]
    recording["digest"]["displacement"]["norm"] = norm * (1 + 3 * recording["rtol"])
    mismatches = replay(recording).mismatches
    assert len(mismatches) == 1 and mismatches[0].startswith("displacement: norm")


def test_the_digest_tolerates_what_the_solve_leaves_open_but_not_more(cut_session):
    """The solves stop at rtol: a displacement off by half of rtol·|u| matches, one off by three
    times does not, and neither does one with its values in another order."""
    body, rtol = cut_session.body, cut_session.rtol
    reference = digest(body)
    u = body.displacement
    body.displacement = u * (1 + rtol / 2)
    assert compare(reference, digest(body), rtol) == []
    body.displacement = u * (1 + 3 * rtol)
    assert any(line.startswith("displacement: norm") for line in compare(reference, digest(body), rtol))
    body.displacement = u[::-1].copy()  # the same values, in another order: the weighted sum sees it
    assert any(line.startswith("displacement: weighted") for line in compare(reference, digest(body), rtol))


def test_a_push_inserts_the_needle(needle_session):
    push = 0.02
    play(needle_session, needle_events(needle_session, push))
    needle, step = needle_session.tool.needle, needle_session.tool.step
    # The needle went as far as the pointer, in whole updates.
    assert push - step < needle.depth <= push + 1e-12
    advances = [m for m in needle_session.moves if m["action"] == "advance"]
    assert len(advances) == round(needle.depth / step)
    assert len(needle.needle_nodes) > 0
    assert replay(needle_session.recording()).matches


def test_pulling_back_does_not_withdraw_the_needle(needle_session):
    events = needle_events(needle_session, 0.01)
    play(needle_session, events)
    depth = needle_session.tool.needle.depth
    back = [dict(e, t=e["t"] + 10) for e in needle_events(needle_session, -0.01)]
    play(needle_session, back)
    assert needle_session.tool.needle.depth == depth


def test_unknown_scenes_and_options_are_refused():
    refused(lambda: ToolSession("nope"), "unknown scene 'nope'", "cut, needle")
    refused(lambda: ToolSession("cantilever"), "the cantilever scene has no interactive tool")
    refused(lambda: ToolSession("cut", {"speed": 2.0}), "'speed' does not apply to the cut scene")
    refused(lambda: ToolSession("cut", {"colour": 1}), "unknown scene option(s) colour")


def test_a_tool_the_scene_has_not_is_refused(cut_session):
    from snede.app.interactive.events import PointerEvent

    refused(lambda: cut_session.handle(PointerEvent(0.0, "press", 0.5, 0.5, "needle")),
            "the cut scene's tool is the scalpel, not the needle")
