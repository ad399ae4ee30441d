"""Closed triangle surfaces built here from their definitions (not by snede), with what they
enclose, for the tests of reading, tetrahedralising and aiming."""
import itertools
import math

import numpy as np


def icosphere(subdivisions: int = 3, radius: float = 1.0):
    """(points, triangles) of a sphere: an icosahedron whose triangles are split in four
    ``subdivisions`` times, every vertex pushed out to ``radius``; outward normals."""
    g = (1 + math.sqrt(5)) / 2
    points = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g), (0, -1, -g), (0, 1, -g),
              (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
    triangles = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
                 (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
                 (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    points = [np.array(p, dtype=float) / np.linalg.norm(p) for p in points]
    for _ in range(subdivisions):
        middle = {}

        def between(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                m = points[a] + points[b]
                points.append(m / np.linalg.norm(m))
                middle[key] = len(points) - 1
            return middle[key]
        triangles = [t for a, b, c in triangles for t in
                     ((a, between(a, b), between(c, a)), (b, between(b, c), between(a, b)),
                      (c, between(c, a), between(b, c)), (between(a, b), between(b, c), between(c, a)))]
    return radius * np.array(points), np.array(triangles, dtype=np.int64)


def box_surface(size=(1.0, 2.0, 3.0)):
    """(points, triangles) of the box [0, size]: 8 corners, two triangles a side, outward."""
    corners = np.array(list(itertools.product((0, 1), repeat=3)), dtype=float) * size  # index 4x + 2y + z
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    triangles = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return corners, np.array(triangles, dtype=np.int64)


def torus_surface(radius=1.0, tube=0.4, around=64, across=32):
    """(points, triangles) of a torus around z: centre-line ``radius``, tube ``tube``."""
    u, v = np.meshgrid(np.arange(around) * 2 * math.pi / around, np.arange(across) * 2 * math.pi / across,
                       indexing="ij")
    ring = radius + tube * np.cos(v)
    points = np.stack([ring * np.cos(u), ring * np.sin(u), tube * np.sin(v)], axis=-1).reshape(-1, 3)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(around), np.arange(across), indexing="ij"))

    def vertex(i, j):
        return (i % around) * across + j % across
    triangles = np.concatenate([np.c_[vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)],
                                np.c_[vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)]])
    return points, triangles


def enclosed_volume(points, triangles) -> float:
    """The volume a closed triangle surface encloses (divergence theorem), whatever its orientation."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    return abs(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6


def corner_sets(points, cells) -> np.ndarray:
    """(m, corners, dim) coordinates of the cells' corners, each cell's corners and then the cells
    in lexicographic order: equal for two meshes with the same cells whatever their numbering and
    orientation (compare with a tolerance for a text file's rounding)."""
    corners = np.asarray(points, dtype=float)[np.asarray(cells)]
    for k in range(len(corners)):
        corners[k] = corners[k][np.lexsort(corners[k].T[::-1])]
    flat = corners.reshape(len(corners), -1)
    return corners[np.lexsort(flat.T[::-1])]


def assert_same_cells(points, cells, expected_points, expected_cells, atol=0.0):
    """The same cells, up to numbering and orientation, with corners equal to within ``atol``."""
    a, b = corner_sets(points, cells), corner_sets(expected_points, expected_cells)
    assert a.shape == b.shape
    np.testing.assert_allclose(a, b, rtol=0, atol=atol)
