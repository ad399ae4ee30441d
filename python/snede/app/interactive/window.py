"""``python -m snede view SCENE``: the live window — the mouse drives the scene's tool while the
body relaxes in a worker thread.

Why pyvista (VTK) in a desktop window rather than a trame page in a browser: VTK gives the 3D
camera, rendering of changing meshes with edges and scalar bars, and the mouse's window
positions for free; it renders off-screen under Xvfb, so ``make test`` drives the same window
with scripted events; trame would need a browser (and a server) for the same.

The window's thread renders and reads the mouse and the keys; the worker thread
(``Worker``) owns the ``ToolSession``: it carries out each pointer event's moves, relaxing the
body after each — the engine releases the GIL during solves and cuts, so the window keeps
rendering — and leaves a ``Snapshot`` of what to draw. The camera is the scene's fixed view
(``snede.app.interactive.view``), so a window point means the same place as in a headless session.

Keys: s scalpel, n needle (each scene has one of them), p pause (events wait), r reset,
c screenshot (``--screenshot``, else ``snede_view.png``), w write the series so far (the
session's moves replayed headless into ``out/view/SCENE/``, as ``replay --out`` does), q quit.
"""
from __future__ import annotations

import queue
import threading
import time
from pathlib import Path

import numpy as np

from snede.app.interactive.events import PointerEvent
from snede.app.interactive.snapshot import Snapshot
from snede.app._extras import need
from snede.app.plotting import HIGHLIGHT, LOAD

pyvista = need("pyvista", "the live window (python -m snede view)")

WINDOW = (800, 600)  # pixels; the scenes' views have this aspect (4:3)
MAGNITUDE = "displacement [m]"  # |u|: VTK's default font has no '|'
COLOURS = {"blade": (0.0, 0.0, 0.0), "needle": (0.35, 0.35, 0.35), "stick": (0.12, 0.47, 0.71), "slip": HIGHLIGHT}


def display_answers(display: str) -> bool:
    """Whether an X client can open ``display`` now (Xlib's XOpenDisplay, as VTK calls it); True
    where Xlib is not found (VTK then says what it finds). VTK itself, given a display that does
    not answer, renders off-screen (EGL) and its interactor fails at the first event."""
    import ctypes
    import ctypes.util

    library = ctypes.util.find_library("X11")
    if library is None:
        return True
    xlib = ctypes.CDLL(library)
    xlib.XOpenDisplay.restype = ctypes.c_void_p
    xlib.XCloseDisplay.argtypes = [ctypes.c_void_p]
    connection = xlib.XOpenDisplay(display.encode())
    if connection:
        xlib.XCloseDisplay(connection)
    return bool(connection)


class Worker(threading.Thread):
    """Owns the session: takes pointer events (and resets) from ``inbox``, carries them out,
    and publishes a ``Snapshot`` after each; counts the relaxations and their seconds."""

    def __init__(self, make_session):
        super().__init__(daemon=True, name="snede-view-worker")
        self.make_session = make_session
        self.session = make_session()
        self.inbox: queue.Queue = queue.Queue()
        self.lock = threading.Lock()
        self.snapshot, self.version = Snapshot.of(self.session), 0
        self.relaxations, self.solve_seconds = 0, 0.0
        self.error: str | None = None

    def run(self) -> None:
        while (item := self.inbox.get()) is not None:
            try:
                moves = len(self.session.moves)
                if callable(item):  # a task on the worker's thread (tests: a slow solve)
                    item(self.session)
                elif item == "reset":  # a new session: its recording says how many resets came before
                    resets = self.session.resets + 1
                    self.session = self.make_session()
                    self.session.resets = resets
                else:
                    for relaxation in self.session.handle(item):
                        self.relaxations += 1
                        self.solve_seconds += relaxation.seconds
                if not isinstance(item, PointerEvent) or len(self.session.moves) != moves:  # else nothing moved
                    snapshot = Snapshot.of(self.session)
                    with self.lock:
                        self.snapshot, self.version = snapshot, self.version + 1
            except ValueError as error:
                self.error = str(error)
            finally:
                self.inbox.task_done()

    def idle(self) -> bool:
        return self.inbox.unfinished_tasks == 0

    def stop(self) -> None:
        self.inbox.put(None)
        self.join()


def write_series(session) -> None:
    """The session so far as the usual series and picture: its moves replayed headless into
    ``out/view/SCENE/`` (on the worker's thread: the window goes on meanwhile)."""
    from snede.app.interactive.replay import replay

    replay(session.recording(), Path("out") / "view")


class Window:
    """The window over a ``Worker``: ``run(events, screenshot, close)`` shows it until closed
    (or, with ``close``, until the scripted ``events`` are done and the body relaxed)."""

    def __init__(self, make_session, off_screen: bool = False):
        self.worker = Worker(make_session)
        self.tool = self.worker.session.tool.name
        self.paused, self.waiting, self.closed = False, [], False
        self.frames, self.start, self.shown = 0, time.perf_counter(), -1
        self.surface = self.body_actor = None
        self.screenshot = Path("snede_view.png")  # the c key's
        self.frame_times: list[float] = []
        self.plotter = pyvista.Plotter(window_size=WINDOW, off_screen=off_screen, title=f"snede: {self.scene}")
        self.plotter.enable_parallel_projection()
        camera = self.worker.session.view.camera()
        self.plotter.camera.position, self.plotter.camera.focal_point = camera["position"], camera["focal_point"]
        self.plotter.camera.up, self.plotter.camera.parallel_scale = camera["up"], camera["parallel_scale"]
        # At a pixel position pyvista makes a vtkTextActor, whose text is set each frame (a new
        # text actor per frame would cost more than the frame).
        self.text = self.plotter.add_text(" ", position=(6, WINDOW[1] - 22), font_size=7)

    @property
    def scene(self) -> str:
        return self.worker.session.name

    # -- input -------------------------------------------------------------------------------
    def pointer(self, kind: str) -> None:
        """A mouse button or move, at the interactor's event position, as a pointer event."""
        px, py = self.plotter.iren.get_event_position()
        width, height = self.plotter.window_size
        x, y = min(max(px / width, 0.0), 1.0), min(max(1.0 - py / height, 0.0), 1.0)
        self.send(PointerEvent(time.perf_counter() - self.start, kind, x, y, self.tool))

    def send(self, event) -> None:
        if self.paused:
            self.waiting.append(event)
        else:
            self.worker.inbox.put(event)

    def key(self, name: str) -> None:
        if name in ("s", "n"):
            self.tool = {"s": "scalpel", "n": "needle"}[name]
        elif name == "p":
            self.paused = not self.paused
            while not self.paused and self.waiting:
                self.worker.inbox.put(self.waiting.pop(0))
        elif name == "r":
            self.send("reset")
        elif name == "c":
            self.save_screenshot(self.screenshot)
        elif name == "w":
            self.worker.inbox.put(write_series)
        elif name == "q":
            self.closed = True

    def play(self, event: PointerEvent) -> None:
        """A scripted event as if from the mouse: its tool taken up, the pointer put at its
        pixel and the button or move reported through the interactor."""
        self.tool = event.tool
        width, height = self.plotter.window_size
        interactor = self.plotter.iren.interactor
        interactor.SetEventPosition(round(event.x * width), round((1.0 - event.y) * height))
        {"press": interactor.LeftButtonPressEvent, "move": interactor.MouseMoveEvent,
         "release": interactor.LeftButtonReleaseEvent}[event.type]()

    def _listen(self) -> None:
        iren = self.plotter.iren
        iren.clear_key_event_callbacks()  # pyvista's keys (v, b, C, ...) are not the window's
        iren.interactor.SetInteractorStyle(None)  # the camera is the scene's: the mouse drives the tool
        held = {"down": False}

        def press(*_):
            held["down"] = True
            self.pointer("press")

        def move(*_):
            if held["down"]:
                self.pointer("move")

        def release(*_):
            if held["down"]:
                held["down"] = False
                self.pointer("release")

        for name, call in (("LeftButtonPressEvent", press), ("MouseMoveEvent", move),
                           ("LeftButtonReleaseEvent", release)):
            iren.interactor.AddObserver(name, call)
        iren.interactor.AddObserver("KeyPressEvent", lambda caller, _: self.key(caller.GetKeySym()))
        iren.interactor.AddObserver("ExitEvent", lambda *_: setattr(self, "closed", True))

    # -- drawing -----------------------------------------------------------------------------
    def draw(self) -> None:
        with self.worker.lock:
            snapshot, version = self.worker.snapshot, self.worker.version
        if version != self.shown:
            self.shown = version
            faces = np.column_stack([np.full(len(snapshot.faces), 3), snapshot.faces]).ravel()
            surface = pyvista.PolyData(snapshot.points, faces)
            surface.point_data[MAGNITUDE] = snapshot.magnitude
            largest = max(float(snapshot.magnitude.max(initial=0.0)), 1e-12)
            if self.surface is None:
                self.surface = surface
                self.body_actor = self.plotter.add_mesh(surface, scalars=MAGNITUDE, cmap="viridis", show_edges=True,
                                                        edge_color="black", line_width=0.5, render=False,
                                                        scalar_bar_args={"title": MAGNITUDE})
            else:  # in place: a new actor and scalar bar each time would cost more than the frame
                self.surface.copy_from(surface)
            self.body_actor.mapper.scalar_range = (0.0, largest)
            self._optional("lips", snapshot.lips, lambda: pyvista.PolyData(
                snapshot.points, np.column_stack([np.full(len(snapshot.lips), 3), snapshot.lips]).ravel()),
                color=HIGHLIGHT, show_edges=False)
            self._optional("held", snapshot.held, lambda: pyvista.PolyData(snapshot.held), color="black",
                           point_size=6, render_points_as_spheres=True)
            self._loads(snapshot)
            for name in COLOURS:
                marks = snapshot.marks.get(name, np.zeros((0, 3)))
                line = name in ("blade", "needle")
                self._optional(name, marks, lambda: pyvista.lines_from_points(marks) if line else pyvista.PolyData(marks),
                               color=COLOURS[name], line_width=4 if line else 1, point_size=8,
                               render_points_as_spheres=not line)
        self.text.SetInput(self.heads_up(snapshot))
        self.plotter.render()
        self.frames += 1
        self.frame_times.append(time.perf_counter())

    def _loads(self, snapshot) -> None:
        """Nodal loads as arrows from their vertices (the largest a tenth of the body's size),
        gravity as one arrow above the body's far end, in the pictures' load colour."""
        size = float(np.ptp(snapshot.points, axis=0).max())

        def arrows():
            cloud = pyvista.PolyData(snapshot.loaded)
            cloud["load"] = snapshot.loads
            largest = float(np.linalg.norm(snapshot.loads, axis=1).max())
            return cloud.glyph(orient="load", scale="load", factor=0.1 * size / largest, geom=pyvista.Arrow())

        self._optional("loads", snapshot.loads, arrows, color=LOAD)
        low, high = snapshot.points.min(axis=0), snapshot.points.max(axis=0)
        top = (high[0], low[1], high[2] + 0.2 * size)  # above the far end: clear of the heads-up line
        self._optional("gravity", [] if snapshot.gravity is None else [snapshot.gravity],
                       lambda: pyvista.Arrow(start=top, direction=snapshot.gravity, scale=0.15 * size), color=LOAD)

    def _optional(self, name: str, items, make, **style) -> None:
        if len(items):
            self.plotter.add_mesh(make(), name=name, render=False, **style)  # one render a frame, in draw
        else:
            self.plotter.remove_actor(name, render=False)

    def frame_rate(self) -> float:
        """Frames per second over the last second (or what there is of it)."""
        recent = [t for t in self.frame_times[-200:] if t > self.frame_times[-1] - 1.0] if self.frame_times else []
        return (len(recent) - 1) / (recent[-1] - recent[0]) if len(recent) > 1 and recent[-1] > recent[0] else 0.0

    def heads_up(self, snapshot) -> str:
        worker = self.worker
        rate = worker.relaxations / worker.solve_seconds if worker.solve_seconds > 0 else 0.0
        state = "PAUSED " if self.paused else ""
        error = f"; error: {worker.error}" if worker.error else ""
        return (f"{state}{self.tool}, {self.frame_rate():.0f} frames/s, {rate:.1f} solves/s, "
                f"{snapshot.cells} cells, {snapshot.moves} moves, last solve: {snapshot.reason or '-'}{error}")

    def save_screenshot(self, path: Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.plotter.screenshot(str(path))
        return path

    # -- the loop ----------------------------------------------------------------------------
    def run(self, events=(), screenshot=None, close: bool = False, tick=None) -> None:
        """Show the window: render, feed the scripted ``events`` at their times, process the
        mouse and the keys, until closed (``close``: once the events are done and the worker
        is idle). ``tick()``, if given, is called every frame (tests)."""
        self.screenshot = Path(screenshot) if screenshot is not None else self.screenshot
        self.plotter.show(interactive_update=True, auto_close=False)
        self._listen()
        self.worker.start()
        pending = list(events)
        self.start = time.perf_counter()
        try:
            while not self.closed:
                now = time.perf_counter() - self.start
                while pending and pending[0].t <= now:
                    self.play(pending.pop(0))
                self.plotter.iren.process_events()
                self.draw()
                if tick is not None:
                    tick()
                if close and not pending and self.worker.idle() and self.shown == self.worker.version:
                    break
                time.sleep(0.005)
            if screenshot is not None:
                self.draw()
                self.save_screenshot(screenshot)
        finally:
            self.worker.stop()
            self.plotter.close()
