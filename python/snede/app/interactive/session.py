"""``ToolSession(scene, options)``: a built-in scene or a scene file driven by pointer events, headless — the
window (``snede.app.interactive.window``) shows one and feeds it the mouse, tests feed it scripted
events. Every tool move is carried out at once (the body relaxes after each) and recorded with
its time: ``recording()`` is the JSON a replay repeats (``snede.app.interactive.recording``).
"""
from __future__ import annotations

import hashlib
from pathlib import Path

from snede.app.interactive.recording import make as make_recording
from snede.app.interactive.events import PointerEvent
from snede.app.interactive.tools import TOOLS, Relaxation, file_tool

OPTIONS = ("divisions", "material", "formulation", "speed")  # the scenes' own, as `run` takes them
FILE_OPTIONS = ("material", "formulation")  # a scene file's, as `run` takes them


def is_scene_file(name: str) -> bool:
    from snede.app.scene_file import SUFFIX

    return str(name).endswith(SUFFIX)


def file_checksum(path) -> str:
    """The sha256 of a scene file's bytes: a recording's check that the file is the one it was made with."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError as error:
        raise ValueError(f"scene file {path}: cannot be read ({error.strerror or error})") from None


def _options_checked(options: dict, allowed: tuple, what: str) -> None:
    """Known option names, with values of the kinds the command line's parser gives (a
    recording's JSON may hold anything: "12" for divisions was a TypeError deep in a scene)."""
    from snede.app.scene_file.reading import COUNT, POSITIVE, REFUSED, TEXT, shown

    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise ValueError(f"unknown {what} option(s) {', '.join(unknown)} (the options: {', '.join(allowed)})")
    kinds = {"divisions": COUNT, "speed": POSITIVE, "material": TEXT, "formulation": TEXT}
    for name, value in options.items():
        if value is not None and kinds[name].convert(value) is REFUSED:
            raise ValueError(f"{what} option {name!r} must be {kinds[name].what}, got {shown(value)}")


def _scene(name: str, options: dict):
    from snede.app.scenes import Parameters, builders

    scenes = builders()  # (imported, the interactive scenes' modules have registered their tools)
    if name not in TOOLS:
        known = ", ".join(TOOLS)
        raise ValueError(f"unknown scene {name!r}: the interactive scenes are {known} or a scene file (.toml)"
                         if name not in scenes else
                         f"the {name} scene has no interactive tool (the interactive scenes are {known})")
    _options_checked(options, OPTIONS, "scene")
    module = scenes[name]
    given = [key for key, value in options.items() if value is not None and key != "material" and key not in module.OPTIONS]
    if given:
        raise ValueError(f"option {given[0]!r} does not apply to the {name} scene (its options: "
                         f"{', '.join(module.OPTIONS)})")
    return module.build(Parameters.of(options))


def _file_scene(path: str, options: dict):
    """A scene file's scene and its tools (``scene_file``)."""
    from snede.app.scene_file import read
    from snede.app.scene_file.scene import build

    _options_checked(options, FILE_OPTIONS, "scene file")
    recipe = read(path)
    return build(recipe, options.get("material"), options.get("formulation")), recipe.tools


class ToolSession:
    """The scene ``name`` (``cut``: the scalpel; ``needle``, ``needle3d``: the needle; a scene
    file, ``*.toml``: the tool of its first ``[[tool]]`` table) built with ``options``
    (``divisions``, ``material``, ``formulation``, ``speed``, as for ``run``; a scene file takes
    ``material`` and ``formulation``), relaxed with the scene's method and tolerance (or
    ``method``, ``rtol``)."""

    def __init__(self, name: str, options: dict | None = None, method: str | None = None, rtol: float | None = None):
        from snede.app.run_scene import fitting_method

        self.name, self.options = str(name), dict(options or {})
        self.scene_file = None  # a scene file's path and checksum (``recording``)
        if is_scene_file(self.name):
            self.scene_file = {"path": self.name, "sha256": file_checksum(self.name)}
            self.scene, tools = _file_scene(self.name, self.options)
        else:
            self.scene = _scene(self.name, self.options)
        self.method = method or fitting_method(self.scene)
        self.rtol = rtol or self.scene.default_rtol
        self.tool = (file_tool(self.scene, tools, self.method, self.rtol) if self.scene_file else
                     TOOLS[self.name](self.scene, self.method, self.rtol))
        self.view = self.tool.view
        self.moves: list[dict] = []
        self.resets = 0  # how many times the window started the scene again before this session (key r)
        self.last: Relaxation | None = self.tool.first

    @property
    def body(self):
        return self.scene.body

    def handle(self, event: PointerEvent) -> list[Relaxation]:
        """Carry out what the event does with the scene's tool; the relaxations of its moves."""
        if event.tool != self.tool.name:
            raise ValueError(f"the {self.name} scene's tool is the {self.tool.name}, not the {event.tool}")
        point = self.view.on_plane(event.x, event.y, *self.tool.plane)
        if event.type == "press":
            moves = self.tool.press(point)
        elif self.tool.held:
            moves = self.tool.drag(point) if event.type == "move" else self.tool.release(point)
        else:
            moves = []  # hovering
        return [r for r in (self.apply(move, event.t) for move in moves) if r is not None]

    def apply(self, move: dict, t: float) -> Relaxation | None:
        """Carry out one move (a recorded one in a replay), relax, and record it at time ``t``."""
        relaxation = self.tool.apply(move)
        entry = {"t": float(t), **move}
        if relaxation is not None:
            entry |= {"converged": relaxation.converged, "reason": relaxation.reason}
            if move["tool"] == "scalpel":
                entry["faces_dissected"] = relaxation.faces_dissected
            self.last = relaxation
        self.moves.append(entry)
        return relaxation

    def recording(self) -> dict:
        return make_recording(self)
