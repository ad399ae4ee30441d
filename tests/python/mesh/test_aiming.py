"""Mesh.ray_hit and Mesh.boundary_patch (issue 34 item 4), against analytic answers: rays into
boxes and rectangles (the slab method), a tilted plane, and deformed boxes."""
import math

import numpy as np
import pytest
from closed_surfaces import icosphere
from expected_errors import refused

import snede
from snede import meshing


def slab(origin, direction, low, high):
    """The first t ≥ 0 where origin + t·direction is on the boundary of the box [low, high], or None."""
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = (np.asarray(low) - origin) / direction, (np.asarray(high) - origin) / direction
    near, far = np.nanmax(np.minimum(a, b)), np.nanmin(np.maximum(a, b))
    if near > far or far < 0:
        return None
    return near if near >= 0 else far  # from inside: where the ray leaves


def random_rays(dim, n, seed=0):
    """Rays from outside the unit box (and some from inside) aimed at random points of [−0.2, 1.2]^dim."""
    rng = np.random.default_rng(seed)
    origins = np.r_[rng.uniform(-2, 3, (n, dim)), rng.uniform(0.1, 0.9, (n // 4, dim))]
    targets = rng.uniform(-0.2, 1.2, (len(origins), dim))
    return origins, targets - origins


@pytest.mark.parametrize("dim", [2, 3])
def test_rays_into_a_box_meet_it_where_the_slab_method_says(dim):
    size = (1.0, 0.5, 2.0)[:dim]
    mesh = meshing.box(size, (3, 2, 4)) if dim == 3 else meshing.rectangle(size, (3, 2))
    hits = misses = 0
    for origin, direction in zip(*random_rays(dim, 200)):
        origin = origin * size
        expected = slab(origin, direction, np.zeros(dim), size)
        hit = mesh.ray_hit(origin, direction)
        if expected is None:
            assert hit is None
            misses += 1
            continue
        hits += 1
        unit = direction / np.linalg.norm(direction)
        assert hit.distance == pytest.approx(expected * np.linalg.norm(direction), abs=1e-12)
        np.testing.assert_allclose(hit.point, origin + hit.distance * unit, atol=1e-12)
        np.testing.assert_allclose(hit.weights @ mesh.points[hit.face], hit.point, atol=1e-12)
        assert np.all(hit.weights >= -1e-12) and hit.weights.sum() == pytest.approx(1)
        assert any(sorted(hit.face.tolist()) == sorted(f) for f in mesh.boundary_faces().tolist())
    assert hits > 60 and misses > 10


@pytest.mark.parametrize("target", [(0.5, 0.5, 1.0), (1.0, 0.5, 1.0), (1.0, 1.0, 1.0)], ids=["face", "edge", "corner"])
def test_a_ray_through_an_edge_or_a_corner_of_the_boundary_still_hits(target):
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    origin = np.array([0.2, 0.3, 3.0])
    hit = mesh.ray_hit(origin, np.subtract(target, origin))
    assert hit is not None
    np.testing.assert_allclose(hit.point, target, atol=1e-12)


def test_the_length_of_the_direction_does_not_matter():
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    a, b = (mesh.ray_hit((0.3, 0.4, -1.0), (0.1 * k, 0.0, k)) for k in (1.0, 1e-6))
    assert a.distance == pytest.approx(b.distance) and np.allclose(a.point, b.point)


def test_a_tilted_surface_mesh_is_hit_at_the_analytic_point():
    """Every triangle of a surface mesh counts: the plane z = 0.3 + 0.2x − 0.1y over the unit square."""
    mesh = meshing.height_field(lambda x, y: 0.3 + 0.2 * x - 0.1 * y, divisions=(5, 5))
    origin, direction = np.array([0.35, 0.6, 2.0]), np.array([0.1, -0.2, -1.0])
    # (origin + t·d)_z = 0.3 + 0.2 (origin + t·d)_x − 0.1 (origin + t·d)_y, solved for t
    t = (0.3 + 0.2 * origin[0] - 0.1 * origin[1] - origin[2]) / (direction[2] - 0.2 * direction[0] + 0.1 * direction[1])
    hit = mesh.ray_hit(origin, direction)
    np.testing.assert_allclose(hit.point, origin + t * direction, atol=1e-12)
    assert hit.distance == pytest.approx(t * np.linalg.norm(direction))
    assert mesh.ray_hit(origin, -direction) is None


def test_on_a_sphere_the_hit_lies_between_the_inscribed_and_the_true_sphere():
    points, triangles = icosphere(3)
    mesh = meshing.tetrahedralize(snede.Mesh(points, triangles), 0.3, remesh=False)
    rng = np.random.default_rng(1)
    for direction in rng.normal(size=(30, 3)):
        origin = -3 * direction / np.linalg.norm(direction) + rng.uniform(-0.2, 0.2, 3)
        hit = mesh.ray_hit(origin, direction)
        radius = np.linalg.norm(hit.point)
        assert 0.97 < radius <= 1 + 1e-12  # the chords of subdivision 3 sag less than 3 %


def test_on_the_deformed_body():
    """A displacement that stretches the box by 1.5 along z and moves it by 0.25 along x."""
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    u = np.c_[np.full(mesh.n_points, 0.25), np.zeros(mesh.n_points), 0.5 * mesh.points[:, 2]]
    origin, direction = np.array([0.6, 0.5, 5.0]), np.array([0.0, 0.1, -1.0])
    hit = mesh.ray_hit(origin, direction, displacement=u)
    expected = slab(origin, direction, (0.25, 0, 0), (1.25, 1, 1.5))
    np.testing.assert_allclose(hit.point, origin + expected * direction, atol=1e-12)
    np.testing.assert_allclose(hit.weights @ (mesh.points + u)[hit.face], hit.point, atol=1e-12)
    reference = hit.weights @ mesh.points[hit.face]  # where that material point was
    assert reference[2] == pytest.approx(1.0)
    assert mesh.ray_hit((0.1, 0.5, 5.0), direction, displacement=u) is None  # left of the moved box


def test_a_ray_that_misses_gives_none():
    mesh = meshing.box((1.0, 1.0, 1.0), (1, 1, 1))
    assert mesh.ray_hit((2.0, 2.0, 2.0), (1.0, 0.0, 0.0)) is None
    assert mesh.ray_hit((0.5, 0.5, -1.0), (0.0, 0.0, -1.0)) is None  # pointing away
    assert mesh.ray_hit((0.5, 2.0, 0.5), (1.0, 0.0, 0.0)) is None  # beside it, parallel to faces


@pytest.mark.parametrize("call, message", [
    (lambda m: m.ray_hit((0, 0), (1, 0, 0)), "origin must be 3 finite numbers for this 3-D mesh, got (0, 0)"),
    (lambda m: m.ray_hit((0, 0, math.nan), (1, 0, 0)), "origin must be 3 finite numbers"),
    (lambda m: m.ray_hit((0, 0, 0), "x"), "direction must be 3 finite numbers"),
    (lambda m: m.ray_hit((0, 0, 0), (0, 0, 0)), "direction must not be zero"),
    (lambda m: m.ray_hit((0, 0, 0), (1, 0, 0), displacement=np.zeros((3, 3))),
     "displacement must have shape (8, 3) (n_points, dim), got (3, 3)"),
    (lambda m: m.boundary_patch((0, 0, 0), -1.0), "radius must be non-negative and finite, got -1.0"),
    (lambda m: m.boundary_patch((0, 0, 0), math.inf), "radius must be non-negative and finite, got inf"),
    (lambda m: m.boundary_patch((0, 0), 1.0), "point must be 3 finite numbers"),
    (lambda m: m.boundary_patch((0, 0, 0), 1.0, displacement=np.zeros(8)), "displacement must have shape (8, 3)"),
], ids=["origin-shape", "origin-nan", "direction-text", "direction-zero", "displacement", "radius-negative",
        "radius-inf", "point-shape", "patch-displacement"])
def test_bad_arguments_are_refused_by_name(call, message):
    refused(lambda: call(meshing.box((1.0, 1.0, 1.0), (1, 1, 1))), message)


# -- boundary_patch ---------------------------------------------------------------------------------
def on_box_boundary(points, size):
    return np.any(np.isclose(points, 0) | np.isclose(points, size), axis=1)


@pytest.mark.parametrize("dim", [2, 3])
def test_the_patch_is_the_boundary_vertices_within_the_radius(dim):
    size = (1.0, 2.0, 1.5)[:dim]
    mesh = meshing.box(size, (4, 4, 4)) if dim == 3 else meshing.rectangle(size, (4, 4))
    point = np.array([1.0, 0.7, 0.4])[:dim]
    patch = mesh.boundary_patch(point, 0.8)
    near = np.linalg.norm(mesh.points - point, axis=1) <= 0.8
    expected = np.flatnonzero(near & on_box_boundary(mesh.points, size))
    np.testing.assert_array_equal(patch, expected)
    assert len(expected) > 3 and np.any(near & ~on_box_boundary(mesh.points, size))  # interior ones left out


def test_the_patch_on_the_deformed_body_and_a_body_holds_it():
    mesh = meshing.box((1.0, 1.0, 1.0), (4, 4, 4))
    u = np.tile([0.0, 0.0, -0.5], (mesh.n_points, 1))
    patch = mesh.boundary_patch((0.5, 0.5, 0.5), 0.3, displacement=u)  # the top, moved down to z = 0.5
    near = np.linalg.norm(mesh.points - (0.5, 0.5, 1.0), axis=1) <= 0.3
    np.testing.assert_array_equal(patch, np.flatnonzero(near & on_box_boundary(mesh.points, 1.0)))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3))
    body.fix(patch)
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "cg", rtol=1e-10).solve().converged
    np.testing.assert_allclose(body.displacement[patch], 0)
    assert body.reaction_forces()[patch, 2].sum() == pytest.approx(1000 * 9.81, rel=1e-6)  # holds the weight


def test_on_a_surface_mesh_every_vertex_is_on_the_boundary():
    mesh = meshing.height_field(lambda x, y: 0 * x, divisions=(4, 4))
    patch = mesh.boundary_patch((0.5, 0.5, 0.0), 0.26)
    np.testing.assert_array_equal(patch, np.flatnonzero(np.linalg.norm(mesh.points - (0.5, 0.5, 0), axis=1) <= 0.26))
    assert len(patch) == 5  # the centre and its four neighbours at 0.25
