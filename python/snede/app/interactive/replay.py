"""``replay(recording, out=None)``: a recorded tool session re-run headless (``python -m snede
replay FILE [--check] [--out DIR]``), its final state compared with the recording's digest."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from snede.app.interactive.recording import checked, compare, digest, load
from snede.app.interactive.session import ToolSession, file_checksum


@dataclass
class ReplayResult:
    scene: str
    moves: int
    digest: dict  # the replay's final state
    mismatches: list[str]  # against the recording's digest (``compare``)
    files: dict = field(default_factory=dict)  # what ``out`` received

    @property
    def matches(self) -> bool:
        return not self.mismatches


def replay(recording, out=None) -> ReplayResult:
    """Re-run a recording's moves (a dict, or the path of its JSON) headless on a new session of
    its scene, and compare the final state with its digest. With ``out``, write the series
    (one frame per move) and a picture of the end to ``out/SCENE/``, as ``run`` does."""
    recording = load(recording) if isinstance(recording, (str, Path)) else checked(recording, "recording")
    scene_file = recording.get("scene_file")
    if scene_file is not None and file_checksum(scene_file["path"]) != scene_file["sha256"]:
        raise ValueError(f"scene file {scene_file['path']} has changed since the recording was made (its sha256 is "
                         f"no longer {scene_file['sha256'][:12]}…): the replay would not repeat the session")
    session = ToolSession(recording["scene"], recording["options"], recording.get("method"), recording.get("rtol"))
    writer = folder = None
    if out is not None:
        from snede.output import SeriesWriter

        folder = Path(out) / session.scene.name
        writer = SeriesWriter(folder / session.scene.name)
        session.tool.write(writer, 0.0)
    for index, move in enumerate(recording["moves"]):
        if move["tool"] != session.tool.name:
            raise ValueError(f"move {index}: tool {move['tool']!r}, but the {session.name} scene's is the "
                             f"{session.tool.name}")
        move = {key: value for key, value in move.items() if key in ("tool", "action", "blade", "distance")}
        try:
            session.apply(move, recording["moves"][index]["t"])
        except (KeyError, TypeError) as error:
            raise ValueError(f"move {index}: malformed ({error!r} in {move!r})") from None
        if writer is not None and move["action"] != "lift":
            session.tool.write(writer, float(recording["moves"][index]["t"]))
    final = digest(session.body)
    files = {} if folder is None else _picture(session, folder, writer)
    mismatches = compare(recording["digest"], final, session.rtol)
    return ReplayResult(session.name, len(recording["moves"]), final, mismatches, files)


def _picture(session, folder: Path, writer) -> dict:
    from snede.app.plotting import plot_body
    from snede.app.run_scene import picture_arguments

    arguments = {**picture_arguments(session.scene, session.method), **session.tool.picture()}
    arguments["title"] = f"{session.scene.name}: replayed, {len(session.moves)} moves"
    png = plot_body(session.body, folder / f"{session.scene.name}.png", **arguments)
    return {"xdmf": str(writer.xdmf_path), "h5": str(writer.h5_path), "png": str(png)}
