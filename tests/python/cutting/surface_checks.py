"""Surfaces, scalpel paths and checks shared by the surface cutter's tests."""
import math

import numpy as np

import snede


def flat_square(n=8):
    return snede.meshing.height_field(lambda x, y: 0 * x, divisions=(n, n))


def bell_height(x, y):
    return 0.4 * np.exp(-((x - 0.5) ** 2 + (y - 0.5) ** 2) / 0.08)


def bell():
    """Figure 5.19's 392-triangle bell."""
    return snede.meshing.gaussian_bell()


def folded():
    """The sheet folded over a crease of radius 0.15: layers z = 0 and z = 0.3."""
    return snede.meshing.folded_sheet()


def normals(mesh):
    p = mesh.points[mesh.cells]
    return np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])


def largest_turn_between_neighbours(mesh):
    """The largest angle (degrees) between the normals of two triangles sharing an edge."""
    n = normals(mesh)
    n = n / np.linalg.norm(n, axis=1)[:, None]
    sides = np.sort(np.concatenate([mesh.cells[:, [0, 1]], mesh.cells[:, [1, 2]], mesh.cells[:, [2, 0]]]), axis=1)
    owner = np.tile(np.arange(mesh.n_cells), 3)
    order = np.lexsort(sides.T[::-1])
    sides, owner = sides[order], owner[order]
    shared = np.all(sides[1:] == sides[:-1], axis=1)
    cosines = np.einsum("ij,ij->i", n[owner[:-1][shared]], n[owner[1:][shared]])
    return np.degrees(np.arccos(np.clip(cosines, -1, 1))).max(initial=0.0)


def check_surface(mesh, cutter, original_normal, h):
    """Valid, no flat triangle, every normal on its side of the surface, incisions on the
    boundary, at most one active node per triangle (§5.3.2). Where the surface has no normal
    field to compare with (original_normal None: a fold's crease, as coarse as its curvature),
    no two neighbouring triangles may turn by 120° or more (the uncut fold's largest turn is
    53°; a triangle folded over its neighbour turns by nearly 180°)."""
    mesh.validate()
    n = normals(mesh)
    areas = 0.5 * np.linalg.norm(n, axis=1)
    assert areas.min() > 1e-8 * h * h
    if original_normal is None:
        assert largest_turn_between_neighbours(mesh) < 120, "a triangle folded over its neighbour"
    else:
        centroids = mesh.points[mesh.cells].mean(axis=1)
        expected = original_normal(centroids)
        facing = np.einsum("ij,ij->i", n, expected) / (2 * areas * np.linalg.norm(expected, axis=1))
        assert facing.min() > 0.05, "a triangle folded over against the surface"
    edges = cutter.incision_edges()
    if edges.size:
        boundary = {tuple(sorted(f)) for f in mesh.boundary_faces()}
        assert all(tuple(sorted(e)) in boundary for e in edges)
    active = cutter.active_nodes
    if active:
        assert all((mesh.cells == v).any() for v in active)
        assert np.isin(mesh.cells, active).sum(axis=1).max() <= 1, "a triangle touches two active nodes"


def mean_edge(mesh):
    p = mesh.points
    c = mesh.cells
    return np.mean([np.linalg.norm(p[c[:, i]] - p[c[:, (i + 1) % 3]], axis=1).mean() for i in range(3)])


def along(points, step):
    """A polyline sampled at most `step` apart, its vertices kept."""
    out = [points[0]]
    for a, b in zip(points[:-1], points[1:]):
        pieces = max(1, int(math.ceil(np.linalg.norm(b - a) / step)))
        out.extend(a + (b - a) * k / pieces for k in range(1, pieces + 1))
    return np.array(out)


def vertical_scalpels(path_xy, bottom=-1.0, top=1.0, tilt=(0.0, 0.0)):
    """Scalpels through (x, y) from z = bottom to z = top, leaning by `tilt` per unit height."""
    return np.array([[[x + tilt[0] * bottom, y + tilt[1] * bottom, bottom], [x + tilt[0] * top, y + tilt[1] * top, top]]
                     for x, y in path_xy])


def up(points):
    return np.tile([0.0, 0.0, 1.0], (len(points), 1))


def bell_normal(points):
    x, y = points[:, 0], points[:, 1]
    dz = bell_height(x, y)[:, None] * -2 * np.c_[x - 0.5, y - 0.5] / 0.08
    return np.c_[-dz, np.ones(len(x))]


def random_path(rng, corners=4):
    """A polyline from outside the unit square through random points inside and out again."""
    start = rng.choice([[-0.2, rng.uniform(0.2, 0.8)], [rng.uniform(0.2, 0.8), -0.2]])
    inside = rng.uniform(0.1, 0.9, (corners, 2))
    end = [1.2, rng.uniform(0.2, 0.8)]
    return np.vstack([start, inside, end])


def components(mesh):
    """The vertex sets of the pieces the mesh falls into (Mesh.connected_components)."""
    count, label = mesh.connected_components()
    return [np.unique(mesh.cells[label == k]) for k in range(count)]
