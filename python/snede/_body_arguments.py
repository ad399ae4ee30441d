"""What a body's calls take, checked in one place for the serial :class:`snede.Body` and for
:class:`snede.PartBody`, a rank's share of a distributed one: the constructor's arguments, a
vertex selection (indices, a boolean mask or a group's name), a displacement field, and a
traction lumped to the vertices of boundary faces."""
from __future__ import annotations

import warnings

import numpy as np

from snede import _checks
from snede.mesh import Mesh

# Above this Poisson's ratio linear tetrahedra visibly lock (docs/results/extremes.md: at
# ν = 0.45 a 16×4×4 cantilever bends 73 % of beam theory, at ν = 0.499 only 10 %).
LOCKING_POISSON_RATIO = 0.45

FORMULATIONS = {
    "p1": "one constant strain per linear simplex (the thesis's element, §2.3); tetrahedra lock as ν → ½",
    "smoothed": "strains averaged over patches (smoothed FEM): on tetrahedra the shear part over edge patches and "
                "the bulk part over vertex patches, free of volumetric locking; on plane triangles the whole energy "
                "over edge patches. Tetrahedra and plane triangles only (docs/results/locking.md)",
}


class LockingWarning(UserWarning):
    """Linear (P1) simplices lock for nearly incompressible materials: too stiff."""


def check_body(mesh: Mesh, material, thickness, formulation, stacklevel: int) -> None:
    """ValueError (TypeError) for arguments a body cannot be made of; a LockingWarning when
    linear tetrahedra would lock (``stacklevel`` points it at the user's call)."""
    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh must be a snede.Mesh, got {type(mesh).__name__}")
    if mesh.is_surface and thickness is None:
        raise ValueError("a surface mesh is an elastic membrane: give its thickness (e.g. thickness=0.001)")
    if mesh.dim == 2 and thickness is None:
        raise ValueError("a 2D mesh is a plane-stress sheet: give its thickness (e.g. thickness=0.01)")
    if mesh.cell_dim == 3 and thickness is not None:
        raise ValueError(f"thickness is only for 2D (plane-stress) meshes and membranes; this mesh is tetrahedral "
                         f"(got thickness={thickness})")
    if not isinstance(formulation, str) or formulation not in FORMULATIONS:
        raise ValueError(f"unknown formulation {formulation!r}; snede.formulations() lists {sorted(FORMULATIONS)}")
    if formulation != "p1" and mesh.is_surface:
        raise ValueError(f"formulation {formulation!r} is for tetrahedra and plane triangles; a membrane (surface "
                         "mesh) takes 'p1': in plane stress it does not lock")
    lam, mu = material.lame
    poisson = lam / (2 * (lam + mu))
    if poisson >= LOCKING_POISSON_RATIO and formulation == "p1" and mesh.cell_dim == 3:
        warnings.warn(f"Poisson's ratio {poisson:.4g} is close to 1/2: linear tetrahedra lock (volumetric locking) "
                      "and the body will deform too little; Body(..., formulation=\"smoothed\") does not lock "
                      "(docs/results/locking.md)", LockingWarning, stacklevel=stacklevel + 1)


def vertex_selection(mesh: Mesh, vertices) -> np.ndarray:
    """The mesh's vertex indices that ``vertices`` names: indices, a boolean mask over the
    points, or the name of one of the mesh's groups."""
    if isinstance(vertices, str):
        return mesh.group_vertices(vertices)
    array = np.atleast_1d(np.asarray(vertices))
    if array.dtype == bool:
        if array.shape != (mesh.n_points,):
            raise ValueError(f"a boolean vertex mask must have shape ({mesh.n_points},), got {array.shape}")
        array = np.flatnonzero(array)
    if array.dtype.kind not in "iu" or array.ndim != 1:
        raise ValueError(f"vertices must be a 1-D array of vertex indices or a boolean mask, got {array.dtype} {array.shape}")
    return _checks.index_array(array, "vertices", mesh.n_points, "a vertex of the mesh")


def displacement_field(mesh: Mesh, dim: int, name: str, value) -> np.ndarray:
    """``value`` as a C-contiguous (n_points, dim) float array, or ValueError naming ``name``."""
    array = np.asarray(value, dtype=np.float64)
    expected = (mesh.n_points, dim)
    if array.shape != expected:
        raise ValueError(f"{name} must have shape {expected} (n_points, dim), got {array.shape}")
    return np.ascontiguousarray(array)


def traction_faces(mesh: Mesh, faces) -> np.ndarray:
    """The (n, cell_dim) vertex indices of boundary faces: a boundary group's name or indices."""
    if isinstance(faces, str):
        groups = mesh.boundary_groups
        if faces not in groups:
            raise KeyError(f"no boundary group {faces!r} in this mesh (its boundary groups: "
                           f"{', '.join(sorted(groups)) or 'none'})")
        faces = groups[faces]
    faces = np.asarray(faces)
    cell_dim = mesh.cell_dim
    if faces.dtype.kind not in "iu" or faces.ndim != 2 or faces.shape[1] != cell_dim:
        raise ValueError(f"faces must be a boundary group's name or (n, {cell_dim}) vertex indices, got "
                         f"{faces.shape} {faces.dtype}")
    return _checks.index_array(faces, "faces", mesh.n_points, "a vertex of the mesh")


def face_forces(mesh: Mesh, faces: np.ndarray, traction, dim: int, thickness) -> np.ndarray:
    """Each face's share per corner of a uniform traction (force per unit reference area):
    traction × area / cell_dim (edges in 2D and on membranes: × length × thickness), (n, dim)."""
    traction = np.broadcast_to(np.asarray(traction, dtype=np.float64), (dim,))
    corners = mesh.points[faces]
    if mesh.cell_dim == 3:
        measure = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    else:
        measure = np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1) * thickness
    return np.outer(measure / mesh.cell_dim, traction)
