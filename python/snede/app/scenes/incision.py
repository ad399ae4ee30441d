"""What the cutting scenes measure on an incision: the cells along it and the widest gap
between its lips. Both cutters (§3.2 in 3D, §5.2 in 2D) make the two lips from the same
vertices, so each pair of lip vertices shares its reference position."""
from __future__ import annotations

import numpy as np

from snede.app.plotting import highlighted


def incision_cells(mesh, faces) -> np.ndarray:
    """(n_cells,) 1.0 on the cells with a side among ``faces`` (vertex ids: (m, 3) faces of
    tetrahedra, (m, 2) edges of triangles), else 0.0."""
    cells = mesh.cells
    corners = cells.shape[1]
    sides = np.concatenate([np.delete(cells, corner, axis=1) for corner in range(corners)])
    return highlighted(sides, faces).reshape(corners, -1).any(axis=0).astype(np.float64)


def lips_gap(body, faces) -> float:
    """The widest gap between the two lips of the cut (m): the largest deformed distance between
    vertices of ``faces`` that the cut made from one (the same reference position); 0 if none."""
    vertices = np.unique(np.asarray(faces).ravel())
    if len(vertices) == 0:
        return 0.0
    reference = body.mesh.points[vertices]
    deformed = reference + body.displacement[vertices]
    _, group = np.unique(reference, axis=0, return_inverse=True)
    group = group.ravel()
    widest = 0.0
    for g in np.flatnonzero(np.bincount(group) > 1):
        x = deformed[group == g]
        widest = max(widest, float(np.linalg.norm(x[:, None] - x[None], axis=2).max()))
    return widest
