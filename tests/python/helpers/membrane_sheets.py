"""A taut membrane that the serial membrane tests and the MPI tests (tests/mpi) both solve."""
import numpy as np

import snede


def pretensioned_sheet(divisions: int) -> snede.Body:
    """A flat neo-Hookean square (a surface in 3D), its rim pulled out by 10 %, loaded across
    its plane: taut, so its equilibrium is unique."""
    sheet = snede.meshing.rectangle((1.0, 1.0), (divisions, divisions))
    mesh = snede.Mesh(np.c_[sheet.points, np.zeros(sheet.n_points)], sheet.cells)
    body = snede.Body(mesh, snede.NeoHookean(1e5, 0.3), thickness=0.001)
    rim = np.unique(mesh.boundary_faces())
    stretch = 0.1 * (mesh.points - [0.5, 0.5, 0.0])
    stretch[:, 2] = 0
    body.fix(rim, stretch[rim])
    body.add_nodal_force(np.setdiff1d(np.arange(mesh.n_points), rim), (0.0, 0.0, -1e-3))
    return body
