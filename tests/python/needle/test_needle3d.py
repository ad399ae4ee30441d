"""3D needle insertion (§6.9, Figure 6.14; issue 17): the 2D tests' friction limits and
equilibrium in 3D (all-stick, zero friction, thresholds after every update, force balance
against the fixed face), refinement along the shaft (conforming, bounded similarity classes,
h_ref within r of the axis), and bad input."""
import itertools

import numpy as np
import pytest

import snede
from needle_checks import check_thresholds, threshold_tolerance

SIZE = 0.1  # the thesis's 10 cm cube, fixed at the bottom, needle from the left
RADIUS = 0.002
H_REF = 0.006
ENTRY, DIRECTION = (-0.01, 0.05, 0.05), (1.0, 0.0, 0.0)


def cube(material=None, levels=3):
    mesh = snede.meshing.box((SIZE, SIZE, SIZE), (2, 2, 2))
    mesh.refine_uniform(levels)
    body = snede.Body(mesh, material or snede.LinearElastic(34e3, 0.34))
    body.fix(bottom(body))
    return body


def bottom(body):
    return np.isclose(body.mesh.points[:, 2], 0.0)


def needle_for(body, friction=None, **options):
    options.setdefault("rtol", 1e-8)
    return snede.NeedleInsertion(body, ENTRY, DIRECTION, friction or snede.FrictionProfile.uniform(2000.0),
                                 radius=RADIUS, h_ref=H_REF, **options)


def distance_from_axis(x):
    r = x - np.asarray(ENTRY)
    return np.linalg.norm(r - np.outer(r @ np.asarray(DIRECTION), DIRECTION), axis=1)


def test_with_friction_far_above_any_force_every_needle_node_moves_with_the_needle():
    body = cube()
    needle = needle_for(body, snede.FrictionProfile.uniform(1e12))
    report = needle.insert(0.05, H_REF)
    assert report.converged, report
    # A node with a share of the needle's surface sticks; one inside the needle that no part
    # of the surface is nearest to has no friction to hold it.
    holding = needle.dynamic_thresholds > 0
    assert holding.sum() >= 10 and needle.sticking[holding].all()
    nodes = needle.needle_nodes[holding]
    before = body.displacement[nodes]
    step = needle.advance(0.003)
    assert step.converged
    # The nodes caught in this step re-partition the surface: a node whose share falls to zero
    # during the update slips (no friction holds it) and sticks again where it ends. Every
    # holding node sticks at the end, and all but those few moved exactly with the needle.
    index = {v: i for i, v in enumerate(needle.needle_nodes)}
    assert needle.sticking[needle.dynamic_thresholds > 0].all()
    assert all(v in index for v in nodes)
    moved = body.displacement[nodes] - before
    exact = np.all(np.abs(moved - [0.003, 0.0, 0.0]) <= 1e-15, axis=1)
    assert exact.mean() >= 0.9, exact


def test_without_friction_the_cube_does_not_move_and_every_node_slips():
    body = cube()
    needle = needle_for(body, snede.FrictionProfile.uniform(0.0), rtol=1e-10)
    report = needle.insert(0.06, H_REF)
    assert report.converged
    assert len(needle.needle_nodes) > 0 and not needle.sticking.any()
    # Zero up to the round-off floor of (6.9), about ε_round·H in displacement.
    assert np.abs(body.displacement).max() < 1e-8 * SIZE * np.sqrt(3)


@pytest.mark.parametrize("material, method, rtol", [(snede.LinearElastic(34e3, 0.34), "cg", 1e-8),
                                                    (snede.NeoHookean(34e3, 0.34), "newton", 1e-7)])
def test_after_every_update_thresholds_hold_and_the_needle_balances_the_support(material, method, rtol):
    body = cube(material)
    needle = needle_for(body, rtol=rtol, method=method)
    n_slipping = 0
    for _ in range(10):
        step = needle.advance(0.5 * H_REF)
        assert step.converged, step
        u = body.displacement
        tolerance = threshold_tolerance(body, needle, rtol, 34e3, SIZE)
        n_slipping += check_thresholds(body, needle, tolerance)
        # The needle's forces balance the reactions of the fixed bottom face.
        total = needle.needle_forces().sum(axis=0) + body.reaction_forces()[bottom(body)].sum(axis=0)
        assert np.abs(total).max() <= np.sqrt(u.size) * tolerance
    assert n_slipping > 0, "the test should see slipping nodes"
    assert np.abs(body.displacement).max() > 1e-5  # the needle drags the cube
    # Thresholds: the uniform profile times each node's share of the shaft's surface inside the
    # (deformed) body: they sum to 2πr times the inserted length, whose start is where the
    # dragged left face was when the update caught its nodes (before its solve, so within twice
    # the face's largest displacement now).
    length = np.sum(needle.dynamic_thresholds) / 2000.0 / (2 * np.pi * RADIUS)
    undeformed = needle.depth - (0.0 - ENTRY[0])
    assert abs(length - undeformed) <= 2 * np.abs(body.displacement[:, 0]).max()
    assert abs(length - undeformed) < 0.1 * undeformed


def similarity_classes(mesh) -> set:
    points = mesh.points[mesh.cells]
    squared = np.stack([((points[:, a] - points[:, b]) ** 2).sum(axis=1)
                        for a, b in itertools.combinations(range(4), 2)], axis=1)
    squared.sort(axis=1)
    return {tuple(row) for row in np.round(squared / squared[:, -1:], 8)}


def longest_edges(mesh):
    points = mesh.points[mesh.cells]
    return np.max([np.linalg.norm(points[:, a] - points[:, b], axis=1)
                   for a, b in itertools.combinations(range(4), 2)], axis=0)


def test_refinement_along_the_shaft_is_conforming_bounded_and_reaches_h_ref_within_r():
    body = cube()
    needle = needle_for(body, snede.FrictionProfile.uniform(0.0))  # the cube stays put: X = x
    needle.insert(0.07, 2 * H_REF)
    mesh = body.mesh
    mesh.validate()
    assert len(similarity_classes(mesh)) == 3  # Maubach bisection of the Kuhn cube (§6.5)
    corners = mesh.points[mesh.cells]
    # Every cell with a point within r of the inserted part of the axis has edges ≤ h_ref: its
    # corners' nearest distance bounds it from above, its centroid's from below by the size.
    centroid = corners.mean(axis=1)
    s = (centroid - np.asarray(ENTRY)) @ np.asarray(DIRECTION)
    inside = (s > 0.0 - ENTRY[0] + H_REF) & (s < needle.depth - H_REF)
    near = inside & (distance_from_axis(centroid) <= RADIUS)
    assert near.sum() > 10
    assert np.all(longest_edges(mesh)[near] <= H_REF)
    # Far from the shaft the mesh keeps its start size.
    far = distance_from_axis(centroid) > 0.03
    assert longest_edges(mesh)[far].max() > 4 * H_REF
    # Needle nodes: on the jagged image of the cylinder, inside the body, behind the tip.
    x = mesh.points[needle.needle_nodes]
    assert np.all(distance_from_axis(x) <= max(RADIUS, H_REF))
    assert np.all(np.abs(needle.d_perp - distance_from_axis(x)) < 1e-9)  # u: round-off only
    assert np.all((x[:, 0] >= -1e-12) & (x[:, 0] <= ENTRY[0] + needle.depth + 1e-12))


def test_refine_near_segment_alone():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    a, b, h, radius = np.array([0.1, 0.3, 0.4]), np.array([0.9, 0.6, 0.5]), 0.05, 0.05
    split = mesh.refine_near_segment(a, b, h, radius)
    assert split > 0
    mesh.validate()
    assert len(similarity_classes(mesh)) == 3
    corners = mesh.points[mesh.cells]
    t = np.linspace(0, 1, 401)[:, None]
    samples = a + t * (b - a)
    distance = np.linalg.norm(corners.mean(axis=1)[:, None, :] - samples[None], axis=2).min(axis=1)
    assert np.all(longest_edges(mesh)[distance <= radius] <= h)
    assert mesh.refine_near_segment(a, b, h, radius) == 0  # nothing left to do
    with pytest.raises(ValueError, match="does not come within"):
        mesh.refine_near_segment((5.0, 5.0, 5.0), (6.0, 5.0, 5.0), h, 0.1)
    with pytest.raises(ValueError, match="radius"):
        mesh.refine_near_segment(a, b, h, -1.0)
    with pytest.raises(ValueError, match="shape"):
        mesh.refine_near_segment(a[:2], b, h)


def test_bad_input_names_the_value():
    body = cube(levels=0)
    friction = snede.FrictionProfile.uniform(1.0)
    for radius in (0.0, -1e-3, np.inf):
        with pytest.raises(ValueError, match="radius"):
            snede.NeedleInsertion(body, ENTRY, DIRECTION, friction, radius=radius)
    with pytest.raises(ValueError, match="never meets the body"):
        snede.NeedleInsertion(body, (-0.1, 0.5, 0.5), DIRECTION, friction)
    with pytest.raises(ValueError, match="3 components"):
        snede.NeedleInsertion(body, (0.0, 0.05), (1.0, 0.0), friction)
    flat = snede.Body(snede.meshing.rectangle((0.1, 0.1), (2, 2)), snede.LinearElastic(1e4, 0.3), thickness=0.01)
    with pytest.raises(ValueError, match="radius is for 3D"):
        snede.NeedleInsertion(flat, (0.0, 0.05), (1.0, 0.0), friction, radius=1e-3)
    default = snede.NeedleInsertion(body, ENTRY, DIRECTION, friction)  # radius 1 mm by default
    assert default.tip.shape == (3,)
