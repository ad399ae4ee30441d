"""Files a person can open: an XDMF + HDF5 time series (ParaView) written by the engine.

Each step stores the displacement and per-cell fields: ``aspect_ratio`` (reference shape,
§3.2.3) and ``inverted`` (1 where det F ≤ 0), and any extra point fields. When the mesh changes
between steps (a cut, a refinement) the new mesh is written and the step points to it.

The engine's writer knows cell fields only; point fields are added here, next to its
datasets (``/step/<i>/<name>``), and declared in the XDMF file it rewrites at every step.
"""
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
        self._point_fields: dict[int, list[tuple[str, int]]] = {}  # step -> [(name, n_points)]

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
        for name, values in points.items():
            if len(values) != mesh.n_points:
                raise ValueError(f"point field {name!r} has {len(values)} values for {mesh.n_points} points")
        quality = mesh.quality()
        fields = {"aspect_ratio": quality.aspect_ratio, "min_angle": quality.min_dihedral}
        fields.update({name: np.asarray(values, dtype=np.float64) for name, values in cell_fields.items()})
        self._impl.write_step(float(time), mesh._impl, np.ascontiguousarray(u), fields)
        if points:
            self._add_point_fields(self.n_steps - 1, points)
        if self._point_fields:
            self._declare_point_fields()

    def _add_point_fields(self, step: int, fields: dict) -> None:
        import h5py

        with h5py.File(self.h5_path, "r+") as f:  # the engine closes the file between steps
            for name, values in fields.items():
                f[f"/step/{step}/{name}"] = values
        self._point_fields[step] = [(name, len(values)) for name, values in fields.items()]

    def _declare_point_fields(self) -> None:
        """Add the point fields' attributes to the steps of the XDMF file the engine rewrote."""
        h5 = self.h5_path.name
        blocks = self.xdmf_path.read_text().split(" </Grid>\n")  # one per step, then the closing tail
        for step, fields in self._point_fields.items():
            blocks[step] += "".join(
                f'  <Attribute Name="{name}" AttributeType="Scalar" Center="Node">\n   <DataItem Dimensions="{n}" '
                f'NumberType="Float" Precision="8" Format="HDF">{h5}:/step/{step}/{name}</DataItem>\n  </Attribute>\n'
                for name, n in fields)
        self.xdmf_path.write_text(" </Grid>\n".join(blocks))
