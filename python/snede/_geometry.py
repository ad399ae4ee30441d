"""Vectorised ray tests (Möller–Trumbore against triangles, rays against segments in 2D) and the
search for triangles of a surface that cross each other."""
from __future__ import annotations

import numpy as np

#: below this |det| / (|e1| |e2| |d|) a ray counts as parallel to a triangle (or a 2D segment)
PARALLEL = 1e-12


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def ray_triangles(origin, direction, a, b, c):
    """Möller–Trumbore for rays ``origin + t·direction`` and triangles ``abc`` (arrays that
    broadcast to (..., 3)): ``(t, u, v)``, the ray parameter and the crossing's barycentric
    coordinates on b and c (weights 1 − u − v, u, v); NaN where the ray is parallel to the plane."""
    e1, e2 = b - a, c - a
    p = np.cross(direction, e2)
    det = _dot(e1, p)
    scale = np.linalg.norm(e1, axis=-1) * np.linalg.norm(e2, axis=-1) * np.linalg.norm(direction, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inverse = np.where(np.abs(det) > PARALLEL * scale, 1.0 / det, np.nan)
    s = origin - a
    q = np.cross(s, e1)
    return _dot(e2, q) * inverse, _dot(s, p) * inverse, _dot(direction, q) * inverse


def ray_segments(origin, direction, a, b):
    """Rays ``origin + t·direction`` against segments ``a + s·(b − a)`` in 2D: ``(t, s)``, NaN
    where they are parallel."""
    def cross(x, y):
        return x[..., 0] * y[..., 1] - x[..., 1] * y[..., 0]
    edge, offset = b - a, a - origin
    det = cross(direction, edge)
    scale = np.linalg.norm(edge, axis=-1) * np.linalg.norm(direction, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inverse = np.where(np.abs(det) > PARALLEL * scale, 1.0 / det, np.nan)
    return cross(offset, edge) * inverse, cross(offset, direction) * inverse


def _overlapping_boxes(lo: np.ndarray, hi: np.ndarray, batch: int = 1 << 21):
    """Pairs (i, j), i ≠ j, of boxes [lo, hi] (n, 3) that overlap, in batches of about ``batch``
    pairs: sorted by their lower x, each box meets the boxes after it up to its upper x."""
    order = np.argsort(lo[:, 0], kind="stable")
    lo, hi = lo[order], hi[order]
    stop = np.searchsorted(lo[:, 0], hi[:, 0], side="right")
    counts = np.maximum(stop - np.arange(1, len(lo) + 1), 0)  # box k meets k + 1 .. stop[k] − 1 in x
    before = np.cumsum(counts) - counts  # pairs of the boxes before k
    start = 0
    while start < len(lo):
        end = max(int(np.searchsorted(before, before[start] + batch, side="right")), start + 1)
        c = counts[start:end]
        first = np.repeat(np.arange(start, end), c)
        second = first + 1 + np.arange(c.sum()) - np.repeat(before[start:end] - before[start], c)
        meet = np.all((lo[second, 1:] <= hi[first, 1:]) & (lo[first, 1:] <= hi[second, 1:]), axis=1)
        yield order[first[meet]], order[second[meet]]
        start = end


def crossing_triangles(points: np.ndarray, triangles: np.ndarray, tolerance: float = 1e-9) -> np.ndarray:
    """Pairs (i, j), i < j, of triangles that share at most one vertex and cross: an edge of one
    passes through the inside of the other (touching, and overlaps within one plane, are not
    counted). (n, 2), sorted."""
    corners = points[triangles]
    found = []
    for i, j in _overlapping_boxes(corners.min(axis=1), corners.max(axis=1)):
        shared = (triangles[i][:, :, None] == triangles[j][:, None, :]).sum(axis=(1, 2))
        i, j = i[shared <= 1], j[shared <= 1]
        crossing = np.zeros(len(i), dtype=bool)
        for one, other in ((i, j), (j, i)):
            a, b, c = (corners[other][:, None, k] for k in range(3))
            start = corners[one]
            t, u, v = ray_triangles(start, np.roll(start, -1, axis=1) - start, a, b, c)
            inside = (t > tolerance) & (t < 1 - tolerance) & (u > tolerance) & (v > tolerance) & (u + v < 1 - tolerance)
            crossing |= inside.any(axis=1)
        found.append(np.sort(np.c_[i[crossing], j[crossing]], axis=1))
    pairs = np.concatenate(found) if found else np.zeros((0, 2), dtype=np.int64)
    return np.unique(pairs, axis=0).reshape(-1, 2)
