"""Measures of named groups (python/snede/mesh_groups.py), computed here independently of the
engine, the invariants a group keeps through edits (see mesh/test_mesh_groups_edits.py) and a
body held and loaded by group names: for the tests of the mesh, the cutters and the bodies."""
import numpy as np
import pytest

import snede


# -- measures ----------------------------------------------------------------------------------
def simplex_measure(corners):
    """(n, k, d) corners → (n,) measures of the simplices (k − 1 dimensional) in d-space."""
    corners = np.asarray(corners, dtype=float)
    if len(corners) == 0:
        return np.zeros(0)
    edges = corners[:, 1:] - corners[:, :1]
    gram = np.einsum("nid,njd->nij", edges, edges)
    k = corners.shape[1] - 1
    return np.sqrt(np.maximum(np.linalg.det(gram), 0.0)) / float(np.prod(np.arange(1, k + 1)))


def face_measure(mesh, faces):
    return simplex_measure(mesh.points[np.asarray(faces, dtype=np.int64).reshape(-1, mesh.cell_dim)]).sum()


def cell_measure(mesh, rows):
    return simplex_measure(mesh.points[mesh.cells[np.asarray(rows, dtype=np.int64)]]).sum()


def boundary_keys(mesh):
    return {tuple(f) for f in np.sort(mesh.boundary_faces(), axis=1).tolist()}


# -- invariant checks --------------------------------------------------------------------------
def check(mesh, partition, face_expect, cell_expect, incision_expect=None, rel=1e-12):
    """Every invariant named in the module docstring; ``partition`` names cell groups that cover
    the cells once; ``face_expect`` / ``cell_expect`` map names to expected measures (None: not
    checked this time)."""
    cells, faces = mesh.cell_groups, mesh.boundary_groups
    keys = boundary_keys(mesh)
    live = np.flatnonzero(mesh.live_vertices)
    for name, group in faces.items():
        assert group.ndim == 2 and group.shape[1] == mesh.cell_dim, name
        missing = {tuple(f) for f in np.sort(group, axis=1).tolist()} - keys
        assert not missing, f"boundary group {name!r} holds non-boundary faces {sorted(missing)[:3]}"
        assert np.all(np.isin(mesh.group_vertices(name), live)), name
    for name, rows in cells.items():
        assert rows.ndim == 1 and (len(rows) == 0 or (rows.min() >= 0 and rows.max() < mesh.n_cells)), name
        assert np.all(np.isin(mesh.group_vertices(name), live)), name
    if partition:
        together = np.concatenate([cells[name] for name in partition])
        assert len(together) == mesh.n_cells == len(np.unique(together)), "cell groups no longer partition the mesh"
    for name, expected in face_expect.items():
        if expected is not None:
            assert face_measure(mesh, faces[name]) == pytest.approx(expected, rel=rel, abs=1e-14), name
    for name, expected in cell_expect.items():
        if expected is not None:
            assert cell_measure(mesh, cells[name]) == pytest.approx(expected, rel=rel, abs=1e-14), name
    if incision_expect is not None:
        assert face_measure(mesh, faces["incision"]) == pytest.approx(incision_expect, rel=rel, abs=1e-14)


def interior_on_plane(mesh, axis, value, extra=None):
    """Interior faces lying on the plane x[axis] = value (optionally further restricted)."""
    def inside(x):
        keep = np.isclose(x[:, axis], value, atol=1e-12)
        return keep if extra is None else keep & extra(x)
    return mesh.faces_where(inside)


def label_partition(mesh, rng, n_groups=3):
    """Cell groups "g0".."g{n-1}" partitioning the cells by a random split of the centroid's
    first coordinate, and returns their names."""
    centroid = mesh.points[mesh.cells].mean(axis=1)
    cuts = np.sort(rng.uniform(centroid[:, 0].min(), centroid[:, 0].max(), n_groups - 1))
    which = np.searchsorted(cuts, centroid[:, 0])
    names = [f"g{k}" for k in range(n_groups)]
    for k, name in enumerate(names):
        mesh.add_cell_group(name, which == k)
    return names


def body_held_and_loaded_by_groups(mesh, traction, **body_options):
    """A linear elastic body on `mesh` held by its group "clamped" and pulled down by
    `traction` (Pa) on its group "loaded", whose area makes that 10 N (checked), solved by CG:
    the body, with the solve converged and the clamped vertices unmoved (checked)."""
    body = snede.Body(mesh, snede.LinearElastic(1e6, 0.3), **body_options)
    body.fix("clamped")
    body.add_traction("loaded", (0.0, 0.0, -traction))
    np.testing.assert_allclose(body.external_forces().sum(axis=0), (0.0, 0.0, -10.0), atol=1e-12)
    assert snede.StaticSolver(body, "cg", rtol=1e-8).solve().converged
    assert np.all(body.displacement[mesh.group_vertices("clamped")] == 0)
    return body
