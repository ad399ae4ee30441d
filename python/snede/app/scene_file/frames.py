"""The animation (GIF) of a scene file's tools: a frame after each relaxation, the deformed
boundary coloured by |u| on one scale for all frames, the incision in red, the tool (the blade,
the needle's shaft) in black, in one box."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from snede.app._extras import need
from snede.app.plotting import animate, draw_3d

VIEW = (25.0, -60.0)  # the camera (elevation, azimuth), as in the scene's picture


@dataclass
class Frame:
    points: np.ndarray
    faces: np.ndarray  # the boundary faces
    incision: np.ndarray  # (m, 3) faces the cuts opened
    displacement: np.ndarray
    tool: np.ndarray | None  # (2, 3) the blade's edge or the needle's shaft; None: no tool yet
    label: str


def clipped(segment, low, high) -> np.ndarray | None:
    """The part of ``segment`` ((2, 3)) inside the box [low, high], or None (3D axes do not clip)."""
    a, d = segment[0], segment[1] - segment[0]
    start, end = 0.0, 1.0
    for k in range(3):
        if d[k] == 0:
            if not low[k] <= a[k] <= high[k]:
                return None
            continue
        t1, t2 = sorted(((low[k] - a[k]) / d[k], (high[k] - a[k]) / d[k]))
        start, end = max(start, t1), min(end, t2)
    return None if start > end else np.array([a + start * d, a + end * d])


class Frames:
    def __init__(self):
        self.frames: list[Frame] = []

    def record(self, body, incision, tool, label: str) -> None:
        mesh = body.mesh
        self.frames.append(Frame(mesh.points, mesh.boundary_faces(), incision, body.displacement,
                                 None if tool is None else np.array(tool), label))

    def save(self, path: Path) -> Path:
        """The GIF of the frames recorded."""
        colors = need("matplotlib.colors", "snede's pictures")

        surfaces = [np.unique(f.faces) for f in self.frames]
        largest = max(float(np.linalg.norm(f.displacement[v], axis=1).max()) for f, v in zip(self.frames, surfaces))
        every = np.concatenate([f.points[v] + f.displacement[v] for f, v in zip(self.frames, surfaces)])
        self._box, self._norm = (every.min(axis=0), every.max(axis=0)), colors.Normalize(0.0, max(largest, 1e-12))
        return animate(self.frames, path, self._draw, fps=4, projection="3d")

    def _draw(self, ax, frame: Frame) -> None:
        draw_3d(ax, frame.points, frame.faces, frame.displacement, norm=self._norm, highlight=frame.incision)
        low, high = self._box
        tool = None if frame.tool is None else clipped(frame.tool, low, high)
        if tool is not None:
            ax.plot(tool[:, 0], tool[:, 1], tool[:, 2], color="k", linewidth=2.0, zorder=4)
        for setter, a, b in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), low, high):
            setter(a, b)
        ax.set_box_aspect(high - low, zoom=1.2)
        ax.view_init(*VIEW)
        ax.text2D(0.03, 0.95, frame.label, transform=ax.transAxes, fontsize=8)
