"""Files a person can open: an XDMF + HDF5 time series (ParaView) written by the engine.

Each step stores the displacement and per-cell fields: ``aspect_ratio`` (reference shape,
§3.2.3) and ``inverted`` (1 where det F ≤ 0), and any extra point fields. When the mesh changes
between steps (a cut, a refinement) the new mesh is written and the step points to it."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from snede import _snede


class SeriesWriter:
    """``SeriesWriter("out/scene/cantilever")`` writes ``cantilever.xdmf`` and ``cantilever.h5``."""

    def __init__(self, base):
        base = Path(base)
        base.parent.mkdir(parents=True, exist_ok=True)
        self._impl = _snede.XdmfWriter(str(base))

    @property
    def xdmf_path(self) -> Path:
        return Path(self._impl.xdmf_path)

    @property
    def h5_path(self) -> Path:
        return Path(self._impl.h5_path)

    @property
    def n_steps(self) -> int:
        return self._impl.n_steps

    @property
    def n_meshes(self) -> int:
        return self._impl.n_meshes

    def write(self, body, time: float = 0.0, displacement=None, point_fields: dict | None = None,
              **cell_fields) -> None:
        """Write the body's state (or ``displacement``) at ``time``, with the standard cell
        fields, extra ones given as arrays of shape (n_cells,) and ``point_fields``
        ({name: array of shape (n_points,)})."""
        u = body.displacement if displacement is None else np.asarray(displacement, dtype=np.float64)
        inverted = np.zeros(body.mesh.n_cells)
        inverted[body.inverted_elements(u)] = 1.0
        self.write_mesh(body.mesh, time, u, point_fields, inverted=inverted, **cell_fields)

    def write_mesh(self, mesh, time: float = 0.0, displacement=None, point_fields: dict | None = None,
                   **cell_fields) -> None:
        """Write a mesh without a body (a surface mesh, a mesh being edited) with its
        ``aspect_ratio`` and ``min_angle`` (radians; the smallest dihedral angle for tetrahedra)
        cell fields, an optional (n_points, dim) ``displacement``, extra cell fields and
        ``point_fields``."""
        u = np.zeros((mesh.n_points, mesh.dim)) if displacement is None else np.asarray(displacement, dtype=np.float64)
        points = {name: np.asarray(values, dtype=np.float64).ravel() for name, values in (point_fields or {}).items()}
        quality = mesh.quality()
        fields = {"aspect_ratio": quality.aspect_ratio, "min_angle": quality.min_dihedral}
        fields.update({name: np.asarray(values, dtype=np.float64) for name, values in cell_fields.items()})
        self._impl.write_step(float(time), mesh._impl, np.ascontiguousarray(u), fields, points)
