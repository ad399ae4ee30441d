"""Needle insertion into smoothed bodies (issue 35)."""
import numpy as np
import pytest

import snede
from smoothed_checks import check_invariants, smoothed_body, used_vertices

pytestmark = pytest.mark.filterwarnings("ignore::snede.LockingWarning")  # the P1 twins at ν ≥ 0.45


def test_needle_insertion_into_a_smoothed_sheet_and_block():
    """2D: the §6.8.1 slab, refined at the tip as the needle goes in; 3D: the cube of §6.9 with
    its needle refined along the shaft. Every update converges, the free vertices off the
    needle are in equilibrium, and the invariants hold on the refined meshes (with the needle
    nodes' constraints in the assembled tangent)."""
    size = 0.1
    mesh = snede.meshing.rectangle((size, size), (8, 8))
    body = smoothed_body(mesh, snede.LinearElastic(34e3, 0.45))
    body.fix(np.isclose(mesh.points[:, 0], size))
    needle = snede.NeedleInsertion(body, (0.0, 0.05), (1.0, 0.0), snede.FrictionProfile.figure_6_4(),
                                   h_ref=size / 32, rtol=1e-8)
    report = needle.insert(0.05, size / 32)
    assert report.converged, report
    assert mesh.n_cells > 2 * 64 and len(needle.needle_nodes) >= 5
    residual = body.internal_forces(body.displacement) + body.external_forces()
    off = np.ones(mesh.n_points, dtype=bool)
    off[body._model.constraint_table()[0]] = False
    off[needle.needle_nodes] = False
    off &= used_vertices(mesh)
    assert np.abs(residual[off]).max() <= 1e-6 * np.abs(body.internal_forces(body.displacement)).max()
    check_invariants(body, 1, "2D needle")

    mesh = snede.meshing.box((size, size, size), (2, 2, 2))
    mesh.refine_uniform(2)
    body = smoothed_body(mesh, snede.LinearElastic(34e3, 0.45))
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    needle = snede.NeedleInsertion(body, (-0.01, 0.05, 0.05), (1.0, 0.0, 0.0), snede.FrictionProfile.uniform(2000.0),
                                   radius=0.004, h_ref=0.012, rtol=1e-8)
    report = needle.insert(0.05, 0.012)
    assert report.converged, report
    assert len(needle.needle_nodes) >= 3
    check_invariants(body, 2, "3D needle")
