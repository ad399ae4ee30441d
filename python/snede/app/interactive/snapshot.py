"""``Snapshot.of(session)``: a copy of what the window draws, taken by the worker thread after a
move, so the window never reads the body while the worker changes it."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def _space(points) -> np.ndarray:
    """Points in 3D (a plane body's in z = 0)."""
    points = np.asarray(points, dtype=float)
    return points if points.shape[1] == 3 else np.column_stack([points, np.zeros(len(points))])


@dataclass
class Snapshot:
    points: np.ndarray  # (n, 3) deformed
    faces: np.ndarray  # (m, 3) the triangles to draw: the boundary (3D), the cells (a plane body)
    magnitude: np.ndarray  # (n,) |u|
    lips: np.ndarray  # (k, 3) the incision's faces
    held: np.ndarray  # (h, 3) the held vertices, deformed
    marks: dict = field(default_factory=dict)  # name -> (p, 3) points: the tool's (``tools``)
    loaded: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # (l, 3) deformed, where nodal loads act
    loads: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # (l, 3) those loads (N)
    gravity: np.ndarray | None = None  # (3,) m/s², None without
    cells: int = 0
    moves: int = 0
    reason: str = ""

    @classmethod
    def of(cls, session) -> "Snapshot":
        from snede.app.plotting import applied_loads, loaded_vertices

        body, tool = session.body, session.tool
        mesh, u = body.mesh, body.displacement
        faces = mesh.boundary_faces() if mesh.cell_dim == 3 else mesh.cells
        held = session.scene.fixed(mesh.points) & mesh.live_vertices if session.scene.fixed else np.zeros(0, bool)
        x = _space(mesh.points + u)
        marks = {name: _space(value) for name, value in tool.marks().items() if value is not None and len(value)}
        forces, gravity = applied_loads(body)
        loaded = loaded_vertices(forces)
        return cls(x, np.asarray(faces).copy(), np.linalg.norm(u, axis=1), np.asarray(tool.lips()).copy(), x[held],
                   marks, loaded=x[loaded], loads=_space(forces[loaded]),
                   gravity=None if gravity is None else _space(gravity[None])[0], cells=mesh.n_cells,
                   moves=len(session.moves), reason="" if session.last is None else session.last.reason)
