"""The live window under Xvfb (issue 37): scripted pointer events drive the scene's tool through
the mouse's path, the screenshot shows the incision's lips, and the window keeps rendering while
the worker solves (the engine releases the GIL)."""
import time

import numpy as np
import pytest

import snede
from snede.app.interactive.events import events
from tool_scripts import cut_events, cut_session, needle_events, needle_session

pytest.importorskip("pyvista", reason="the window needs pyvista (tools/requirements.txt)")


def red_pixels(path) -> int:
    """Pixels of the lips' red (snede.app.plotting.HIGHLIGHT, green and blue under a fifth of red,
    shaded): viridis, the body's colour map, the black edges and the loads' orange
    (snede.app.plotting.LOAD, green half of red) have none."""
    from PIL import Image

    rgb = np.asarray(Image.open(path).convert("RGB"), dtype=float) / 255
    return int(((rgb[..., 0] > 0.4) & (rgb[..., 1] < 0.3 * rgb[..., 0]) & (rgb[..., 2] < 0.3 * rgb[..., 0])).sum())


def show(make_session, scripted, screenshot=None, tick=None):
    from snede.app.interactive.window import Window

    window = Window(make_session)
    window.run(events(scripted), screenshot, close=True, tick=tick)
    return window


def test_a_scripted_drag_in_the_window_cuts_the_beam_and_shows_the_lips(display, tmp_path):
    untouched = show(cut_session, [], tmp_path / "before.png")
    window = show(cut_session, cut_events(cut_session()), tmp_path / "cut.png")
    session = window.worker.session
    assert window.worker.error is None
    assert len(session.tool.lips()) > 0
    assert sum(m.get("faces_dissected", 0) for m in session.moves) > 0
    assert session.moves[-1]["action"] == "lift"
    picture = np.asarray(__import__("PIL.Image").Image.open(tmp_path / "cut.png").convert("RGB"))
    assert picture.shape == (600, 800, 3) and len(np.unique(picture.reshape(-1, 3), axis=0)) > 50  # not blank
    assert red_pixels(tmp_path / "before.png") == 0 and untouched.worker.session.moves == []
    assert red_pixels(tmp_path / "cut.png") > 100


def test_the_window_and_the_headless_session_make_the_same_cut(display):
    """The window's pointer goes through pixels; the cut it records replays to its digest."""
    from snede.app.interactive import replay

    window = show(cut_session, cut_events(cut_session()))
    assert replay(window.worker.session.recording()).matches


def test_a_scripted_push_in_the_window_inserts_the_needle(display):
    window = show(needle_session, needle_events(needle_session(), 0.02))
    needle = window.worker.session.tool.needle
    assert needle.depth > 0.015 and len(needle.needle_nodes) > 0


def slow_static_solve():
    """A neo-Hookean beam of 12 288 tetrahedra by Newton with unpreconditioned CG to ε = 1e-10."""
    body = beam((32, 8, 8), snede.NeoHookean(1e4, 0.3))
    return snede.StaticSolver(body, "newton", rtol=1e-10, preconditioner="none").solve


def slow_dynamic_relaxation():
    """A linear beam of 384 tetrahedra by explicit damped dynamics to ε = 1e-6 (some 20 000 steps)."""
    body = beam((16, 4, 4), snede.LinearElastic(1e5, 0.3))
    return lambda: snede.DynamicRelaxation(body, damping=20.0).run(1e-6)


def slow_needle_push():
    """One update pushing the needle3d scene's needle 5 cm into a neo-Hookean cube of 24 576
    tetrahedra sagging under gravity, by Newton with unpreconditioned CG to ε = 1e-10."""
    from snede.needle_forces import liver_profile
    from snede.app.scenes import needle3d

    body = snede.Body(snede.meshing.box((needle3d.SIZE,) * 3, (16, 16, 16)),
                      snede.NeoHookean(needle3d.YOUNG, needle3d.POISSON))
    body.fix(needle3d.held(body.mesh.points))
    body.add_gravity((0.0, 0.0, -9.81))
    needle = snede.NeedleInsertion(body, needle3d.ENTRY, needle3d.DIRECTION,
                                   liver_profile(needle3d.DEPTH, needle3d.RADIUS), radius=needle3d.RADIUS,
                                   method="newton", rtol=1e-10, petsc_options={"pc_type": "none"})
    return lambda: needle.advance(0.05)


def beam(divisions, material):
    body = snede.Body(snede.meshing.box((1.0, 0.2, 0.2), divisions), material)
    body.fix(np.isclose(body.mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


@pytest.mark.parametrize("slow", [slow_static_solve, slow_dynamic_relaxation, slow_needle_push])
def test_the_window_renders_while_the_worker_solves(display, slow):
    """A deliberately slow solve (or needle update) in the worker: the window's loop keeps
    turning meanwhile — it could not if the engine held the GIL."""
    from snede.app.interactive.window import Window

    solve, frames = {}, []

    def in_the_worker(session):
        run = slow()
        solve["start"] = time.perf_counter()
        solve["result"] = run()
        solve["end"] = time.perf_counter()

    window = Window(needle_session)
    window.worker.inbox.put(in_the_worker)
    window.run([], close=True, tick=lambda: frames.append(time.perf_counter()))
    assert solve["result"].converged
    assert solve["end"] - solve["start"] > 0.3, "the solve was too quick to tell"
    during = [t for t in frames if solve["start"] < t < solve["end"]]
    assert len(during) >= 3, f"{len(during)} frames in a {solve['end'] - solve['start']:.2f} s solve"


def press_keys(window, keys, on_frame: int = 1):
    """A tick that types ``keys`` through the interactor at frame ``on_frame``."""
    frames = []

    def tick():
        frames.append(None)
        if len(frames) == on_frame:
            interactor = window.plotter.iren.interactor
            for key in keys:
                interactor.SetKeySym(key)
                interactor.InvokeEvent("KeyPressEvent")
    return tick


def test_keys_save_a_screenshot_and_write_the_series(display, tmp_path, monkeypatch):
    from snede.app.interactive.window import Window

    monkeypatch.chdir(tmp_path)
    window = Window(cut_session)
    window.run(events(cut_events(cut_session())), close=True, tick=press_keys(window, "cw"))
    assert (tmp_path / "snede_view.png").stat().st_size > 0
    for name in ("cut.xdmf", "cut.h5", "cut.png"):
        assert (tmp_path / "out" / "view" / "cut" / name).stat().st_size > 0


def test_pause_holds_the_events_and_reset_starts_again(display):
    from snede.app.interactive.window import Window

    scripted = cut_events(cut_session())
    window = Window(cut_session)
    window.key("p")  # what the interactor's p calls (the keys above come through it)
    window.run(events(scripted), close=True)
    assert window.paused and window.worker.session.moves == [] and len(window.waiting) == len(scripted)

    window = Window(cut_session)
    reset, lips = press_keys(window, "r"), []

    def reset_after_the_cut():
        moves = window.worker.session.moves
        if moves and moves[-1]["action"] == "lift" and window.worker.idle() and not lips:
            lips.append(len(window.worker.session.tool.lips()))
            reset()
    window.run(events(scripted), close=True, tick=reset_after_the_cut)
    assert lips[0] > 0  # the drag had cut when r was pressed
    assert window.worker.session.moves == [] and len(window.worker.session.tool.lips()) == 0
    recording = window.worker.session.recording()
    assert recording["resets"] == 1 and "since the window's last reset" in recording["note"]
    assert "resets" not in cut_session().recording()  # without a reset the recording has every move


def test_q_closes_the_window(display):
    from snede.app.interactive.window import Window

    window = Window(needle_session)
    window.run([], close=False, tick=press_keys(window, "q", on_frame=3))  # returns: q closed it
    assert window.closed and window.frames >= 3


def test_the_window_draws_gravity_and_the_held_vertices(display):
    from snede.app.interactive.snapshot import Snapshot
    from snede.app.interactive.window import Window

    session = cut_session()
    snapshot = Snapshot.of(session)
    assert np.allclose(snapshot.gravity, (0.0, 0.0, -9.81))  # the cut scene's beam hangs under gravity alone
    assert len(snapshot.loads) == 0
    held = session.scene.fixed(session.body.mesh.points)
    assert len(snapshot.held) == held.sum() > 0
    window, drawn = Window(cut_session), set()
    window.run([], close=True, tick=lambda: drawn.update(window.plotter.actors))
    assert {"held", "gravity"} <= drawn and "loads" not in drawn
