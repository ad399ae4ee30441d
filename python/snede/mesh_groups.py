"""Named groups of a mesh (issue 34): cell groups (name → rows of ``mesh.cells``) and boundary
groups (name → boundary faces), from a file's gmsh physical groups or VTK cell data, or given by
the user.

Groups are kept against a reference: the mesh's cells and boundary faces (their corners) when the
groups were last given or resolved, each with the groups it belongs to. They are resolved against the mesh as
it is now by where things lie: a cell takes the groups of the reference cell that contains its
centroid, a boundary face those of the reference boundary face its centroid lies on. So the
groups follow every edit without the engine knowing them: bisection's children lie in their
parents, a cut's copies where the cells were, and a face a cut opens lies on no reference
boundary face: it joins the group ``"incision"``. A vertex moved by node snapping (a fraction of
an edge) keeps its cells in their groups: a centroid just outside every reference simplex (within
a quarter of one) takes the nearest.
"""
from __future__ import annotations

import numpy as np

#: the boundary group of the faces that cuts opened
INCISION = "incision"
# A centroid this far outside every reference simplex (in barycentric weight) takes the nearest.
_NEAREST = 0.25


class MeshGroups:
    """The groups of one mesh, resolved lazily and cached per connectivity revision."""

    def __init__(self):
        self._cells = None  # (n, cell_dim + 1, dim) reference cells' corners
        self._faces = None  # (m, cell_dim, dim) reference boundary faces' corners
        self._cell_members: dict[str, np.ndarray] = {}  # name → (n,) bool
        self._face_members: dict[str, np.ndarray] = {}  # name → (m,) bool, "incision" among them
        self._cache: dict = {}

    def add_cells(self, mesh, name: str, rows) -> None:
        name = _name(name)
        if name == INCISION or name in self._face_members:
            raise ValueError(f"{name!r} names a boundary group already: one name, one group (bodies take names)")
        rows = _rows(rows, mesh.n_cells, f"cell group {name!r}", "rows of mesh.cells")
        self._rebase(mesh)
        member = np.zeros(mesh.n_cells, dtype=bool)
        member[rows] = True
        self._cell_members[name] = member
        self._cache.clear()

    def add_faces(self, mesh, name: str, faces) -> None:
        name = _name(name)
        if name == INCISION:
            raise ValueError(f"{INCISION!r} is the group of the faces cuts open; give the group another name")
        if name in self._cell_members:
            raise ValueError(f"{name!r} names a cell group already: one name, one group (bodies take names)")
        faces = np.asarray(faces)
        if faces.size == 0:
            faces = np.zeros((0, mesh.cell_dim), dtype=np.int64)
        if faces.dtype.kind not in "iu" or faces.ndim != 2 or faces.shape[1] != mesh.cell_dim:
            raise ValueError(f"boundary group {name!r} must be (n, {mesh.cell_dim}) vertex indices, got "
                             f"{faces.shape} {faces.dtype}")
        self._rebase(mesh)
        boundary = mesh.boundary_faces()
        place = {tuple(face): k for k, face in enumerate(np.sort(boundary, axis=1).tolist())}
        keys = [tuple(face) for face in np.sort(faces, axis=1).tolist()]
        missing = [key for key in keys if key not in place]
        if missing:
            raise ValueError(f"boundary group {name!r}: {len(missing)} face(s) are not boundary faces of the mesh, "
                             f"e.g. {list(missing[0])}")
        member = np.zeros(len(boundary), dtype=bool)
        member[[place[key] for key in keys]] = True
        self._face_members[name] = member
        self._cache.clear()

    def cell_groups(self, mesh) -> dict[str, np.ndarray]:
        return self._resolved(mesh)[0]

    def boundary_groups(self, mesh) -> dict[str, np.ndarray]:
        return self._resolved(mesh)[1]

    def _rebase(self, mesh) -> None:
        """The mesh as it is now becomes the reference, every group resolved onto it."""
        if self._cells is not None:
            self._resolved(mesh)  # which re-bases
            return
        self._face_members = {INCISION: np.zeros(len(mesh.boundary_faces()), dtype=bool)}
        self._cells = mesh.points[mesh.cells]
        self._faces = mesh.points[mesh.boundary_faces()]
        self._cache.clear()

    def _resolved(self, mesh):
        """The groups on the mesh as it is now, which then becomes the reference: resolving
        after each edit keeps the groups exact through edits that do not nest (a flip, a
        collapse), whose cells straddle the reference's, when refinement follows."""
        if self._cells is None:
            return {}, {}
        key = (mesh._impl.revision, mesh.n_points)
        if self._cache.get("key") != key:
            cells = mesh.points[mesh.cells]
            parents = _containing(cells.mean(axis=1), self._cells)
            self._cell_members = {name: (parents >= 0) & member[np.maximum(parents, 0)]
                                  for name, member in self._cell_members.items()}
            faces = mesh.boundary_faces()
            corners = mesh.points[faces]
            parents = _containing(corners.mean(axis=1), self._faces, corners)
            members = {name: (parents >= 0) & member[np.maximum(parents, 0)] for name, member in self._face_members.items()}
            members[INCISION] |= parents < 0
            self._face_members = members
            self._cells, self._faces = cells, corners
            value = ({name: np.flatnonzero(member) for name, member in self._cell_members.items()},
                     {name: faces[member] for name, member in self._face_members.items()})
            self._cache = {"key": key, "value": value}
        return self._cache["value"]


def copy_groups(source, target) -> None:
    """``source``'s groups onto ``target``, a mesh with the same vertices and cells in the same
    order (moved or scaled, say)."""
    for name, rows in source.cell_groups.items():
        target.add_cell_group(name, rows)
    for name, faces in source.boundary_groups.items():
        if name != INCISION:
            target.add_boundary_group(name, faces)


def _name(name) -> str:
    if not isinstance(name, str) or not name:
        raise ValueError(f"a group's name must be a non-empty string, got {name!r}")
    return name


def _rows(rows, n: int, what: str, of: str) -> np.ndarray:
    array = np.atleast_1d(np.asarray(rows))
    if array.size == 0 and array.ndim == 1:
        return np.zeros(0, dtype=np.int64)
    if array.dtype == bool:
        if array.shape != (n,):
            raise ValueError(f"{what}: a boolean mask must have shape ({n},), got {array.shape}")
        return np.flatnonzero(array)
    if array.dtype.kind not in "iu" or array.ndim != 1 or (len(array) and (array.min() < 0 or array.max() >= n)):
        raise ValueError(f"{what} must be indices into the {n} {of}, got {array.dtype} {array.shape}")
    return array


def _containing(points: np.ndarray, simplices: np.ndarray, oriented: np.ndarray | None = None,
                nearest: bool = True) -> np.ndarray:
    """For each point (q, dim), the index of a simplex of ``simplices`` (s, k, dim) containing it
    (k = dim + 1: volume simplices; k ≤ dim: faces or edges, the point within a hundredth of the
    simplex's size off it), else the nearest within a quarter of a simplex (in barycentric
    weight), else −1. A face or edge is then also taken up to a quarter of its size off its
    plane: a surface cell flipped across a crease, a boundary vertex moved by node snapping. With
    ``oriented`` (q, k, dim), each point's own face, that nearest one must be parallel to it
    (within 25°), so that a face a cut opened next to the boundary does not pass for boundary.
    Candidates come from a uniform grid over the simplices' bounding boxes: first the exact
    boxes, then, for the points left, boxes grown by a quarter. Without ``nearest``, only the
    first: a point in none of ``simplices`` (a subset of a mesh's) is −1."""
    q, (s, k, dim) = len(points), simplices.shape
    found = np.full(q, -1, dtype=np.int64)
    if q == 0 or s == 0:
        return found
    low, high = simplices.min(axis=1), simplices.max(axis=1)
    extent = (high - low).max(axis=1)
    # The grid: a typical simplex's size, coarse enough that the largest spans at most 16 cells.
    size = max(float(np.median(extent)), float(extent.max()) / 16, 1e-300)
    edges = np.transpose(simplices[:, 1:] - simplices[:, :1], (0, 2, 1))  # (s, dim, k − 1)
    # (EᵀE)⁻¹Eᵀ per simplex: a point's weights on the edges by least squares (exact for volumes)
    inverse = np.linalg.solve(np.einsum("sij,sik->sjk", edges, edges), np.transpose(edges, (0, 2, 1)))
    lower = k <= dim
    if lower and oriented is not None:
        directions, own_directions = _direction(simplices), _direction(oriented)
    passes = ((0.0, 1e-9, 1e-2), (_NEAREST, _NEAREST, _NEAREST)) if nearest else ((0.0, 1e-9, 1e-2),)
    for grow, slack, off_limit in passes:
        left = np.flatnonzero(found < 0)
        if len(left) == 0:
            break
        margin = (grow * extent + 1e-9 * size)[:, None]
        pairs_point, pairs_simplex = _candidate_pairs(points[left], low - margin, high + margin, size)
        if len(pairs_point) == 0:
            continue
        offset = points[left][pairs_point] - simplices[pairs_simplex, 0]
        weights = np.einsum("njd,nd->nj", inverse[pairs_simplex], offset)
        worst = np.minimum(1 - weights.sum(axis=1), weights.min(axis=1, initial=np.inf))
        if lower:  # a face or an edge: the point must lie on it, or near it and parallel
            off = np.linalg.norm(offset - np.einsum("ndj,nj->nd", edges[pairs_simplex], weights), axis=1)
            near = off <= off_limit * extent[pairs_simplex]
            if grow and oriented is not None:
                alignment = np.abs(np.einsum("nd,nd->n", directions[pairs_simplex], own_directions[left][pairs_point]))
                near &= alignment >= np.cos(np.radians(25))
            worst = np.where(near, worst, -np.inf)
        # Per point the candidate whose smallest weight is largest.
        order = np.lexsort((-worst, pairs_point))
        first = np.r_[True, pairs_point[order][1:] != pairs_point[order][:-1]]
        best_point, best_simplex = pairs_point[order][first], pairs_simplex[order][first]
        inside = worst[order][first] >= -slack
        found[left[best_point[inside]]] = best_simplex[inside]
    return found


def _direction(simplices: np.ndarray) -> np.ndarray:
    """A unit vector that orients each face: a triangle's normal, an edge's direction."""
    if simplices.shape[1] == 3 and simplices.shape[2] == 3:
        vector = np.cross(simplices[:, 1] - simplices[:, 0], simplices[:, 2] - simplices[:, 0])
    else:
        vector = simplices[:, 1] - simplices[:, 0]
    return vector / np.linalg.norm(vector, axis=1)[:, None]


def _candidate_pairs(points, low, high, size):
    """(point, simplex) pairs with the point in the simplex's box [low, high], found through a
    uniform grid of spacing ``size`` (every simplex registered in each grid cell its box touches)."""
    origin = low.min(axis=0)
    first = np.floor((low - origin) / size).astype(np.int64)
    last = np.floor((high - origin) / size).astype(np.int64)
    span = last - first + 1
    shape = np.maximum(last.max(axis=0) + 1, 1)
    keys, owners = [], []
    for offset in np.ndindex(*span.max(axis=0)):
        offset = np.asarray(offset)
        touched = np.all(offset < span, axis=1)
        cell = first[touched] + offset
        keys.append(np.ravel_multi_index(cell.T, shape))
        owners.append(np.flatnonzero(touched))
    keys, owners = np.concatenate(keys), np.concatenate(owners)
    order = np.argsort(keys, kind="stable")
    keys, owners = keys[order], owners[order]
    cell = np.floor((points - origin) / size).astype(np.int64)
    outside = np.any((cell < 0) | (cell >= shape), axis=1)
    point_keys = np.ravel_multi_index(np.clip(cell, 0, shape - 1).T, shape)
    start, stop = np.searchsorted(keys, point_keys, "left"), np.searchsorted(keys, point_keys, "right")
    stop[outside] = start[outside]
    counts = stop - start
    pairs_point = np.repeat(np.arange(len(points)), counts)
    within = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    pairs_simplex = owners[np.repeat(start, counts) + within]
    in_box = np.all((points[pairs_point] >= low[pairs_simplex]) & (points[pairs_point] <= high[pairs_simplex]), axis=1)
    return pairs_point[in_box], pairs_simplex[in_box]
