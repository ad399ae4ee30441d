"""The user-facing simplicial mesh: triangles in 2D, tetrahedra in 3D, triangulated surfaces in
3D (thesis §7, §5.3)."""
from __future__ import annotations

import contextlib
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np

from snede import _checks, _geometry, _snede
from snede._engine import engine_property
from snede.mesh_edits import MeshEdits, serial_only


class MeshQuality(NamedTuple):
    """Per-cell measures, each an array of shape (n_cells,), in the row order of ``Mesh.cells``.
    Angles are in radians (``np.degrees`` gives degrees, as the demo prints them)."""

    volume: np.ndarray  #: volume (area in 2D), positive
    aspect_ratio: np.ndarray  #: minimum height / maximum edge (§3.2.3); 0.816 regular tet, 0.866 regular triangle
    min_dihedral: np.ndarray  #: smallest dihedral angle, radians (smallest interior angle in 2D)
    max_dihedral: np.ndarray  #: largest dihedral angle, radians (largest interior angle in 2D)


class RayHit(NamedTuple):
    """Where a ray first meets a mesh's boundary (``Mesh.ray_hit``)."""

    point: np.ndarray  #: (dim,) the point hit (on the deformed boundary when a displacement was given)
    face: np.ndarray  #: (cell_dim,) vertex indices of the face hit: a boundary triangle (a triangle of a
    #: surface mesh), or a boundary edge in 2D
    weights: np.ndarray  #: (cell_dim,) barycentric weights of the point on the face's vertices
    distance: float  #: from the ray's origin to the point


def _as_points(points) -> np.ndarray:
    array = np.asarray(points)
    if array.dtype.kind not in "fiu":
        raise ValueError(f"points must be real numbers (float64), got dtype {array.dtype}")
    if array.ndim != 2 or array.shape[1] not in (2, 3):
        raise ValueError(f"points must have shape (n_points, 2) or (n_points, 3), got {array.shape}")
    if array.shape[0] == 0:
        raise ValueError("points is empty: a mesh needs at least one cell")
    return np.ascontiguousarray(array, dtype=np.float64)


def _as_cells(cells, space_dim: int) -> np.ndarray:
    array = np.asarray(cells)
    if array.dtype.kind not in "iu":
        raise ValueError(f"cells must be integer vertex indices, got dtype {array.dtype}")
    allowed = (3,) if space_dim == 2 else (3, 4)
    if array.ndim != 2 or array.shape[1] not in allowed:
        expected = "(n_cells, 3) triangles" if space_dim == 2 else "(n_cells, 4) tetrahedra or (n_cells, 3) surface triangles"
        raise ValueError(f"cells must have shape {expected} for {space_dim}-D points, got {array.shape}")
    if array.shape[0] == 0:
        raise ValueError("cells is empty: a mesh needs at least one cell")
    # The engine checks the range (naming the cell); here only that the ids survive the cast.
    return _checks.index_array(array, "cells", what="a vertex of the mesh")


class Mesh(MeshEdits):
    """A simplicial mesh with the connectivity of thesis §7.

    ``Mesh(points, cells)``: ``points`` is ``(n_points, space_dim)`` with space_dim 2 or 3
    (float64), ``cells`` is ``(n_cells, cell_dim + 1)`` integer vertex indices: triangles in 2D,
    tetrahedra in 3D, or triangles in 3D — a surface mesh (``cell_dim`` 2, ``space_dim`` 3,
    §5.3), whose triangles are oriented consistently (a non-orientable surface is refused).
    ``dim`` is ``space_dim``, the width of every nodal array. Bad input raises
    ``ValueError`` naming the problem and the offending index: wrong shapes or dtypes,
    out-of-range or repeated vertex indices in a cell, non-finite coordinates, zero-volume
    cells, a face shared by more than two cells, two cells overlapping across a face.

    Cells with negative orientation (negative signed volume) are re-oriented by swapping
    their first two vertices, so every cell of ``mesh.cells`` has positive volume;
    ``mesh.n_reoriented`` says how many were turned.
    """

    def __init__(self, points, cells):
        points = _as_points(points)
        cells = _as_cells(cells, points.shape[1])
        _checks.size(len(points), len(cells), f"points ({len(points)} rows) and cells ({len(cells)} rows)")
        self._impl = _snede.Mesh(points, cells)

    @classmethod
    def _wrap(cls, impl) -> "Mesh":
        mesh = cls.__new__(cls)
        mesh._impl = impl
        return mesh

    # -- properties --------------------------------------------------------------------
    dim = engine_property("dim", "Coordinate dimension (columns of ``points`` and of every nodal field).")
    cell_dim = engine_property("cell_dim", "2 for triangles (in 2D or on a surface), 3 for tetrahedra.")
    space_dim = engine_property("space_dim")

    @property
    def is_surface(self) -> bool:
        """Triangles in 3D."""
        return self.cell_dim < self.space_dim

    n_live_points = engine_property("n_live_points", "Vertices not removed (``n_points`` counts rows, removed ones "
                                                     "included).")
    live_vertices = engine_property("live_vertices", "(n_points,) bool: False for a removed vertex, whose row is "
                                                     "kept until reused.")
    n_points = engine_property("n_points")
    n_cells = engine_property("n_cells")
    n_reoriented = engine_property("n_reoriented", "How many input cells were re-oriented to positive volume.")
    points = engine_property("points", "(n_points, dim) coordinates (a copy).")
    cells = engine_property("cells", "(n_cells, dim + 1) vertex indices, each row positively oriented (a copy).")

    @property
    def cell_ids(self) -> np.ndarray:
        """(n_cells,) element id of each row of ``cells`` (ids stay stable across mesh changes).
        Cached until the connectivity changes."""
        revision = self._impl.revision
        if getattr(self, "_cell_ids_revision", None) != revision:
            self._cell_ids = np.asarray(self._impl.cell_ids, dtype=np.int64)
            self._cell_ids.flags.writeable = False
            self._cell_ids_revision = revision
        return self._cell_ids

    # -- named groups (mesh_groups.py) -----------------------------------------------------
    @property
    def _group_store(self):
        store = getattr(self, "_groups", None)
        if store is None:
            from snede.mesh_groups import MeshGroups

            store = self._groups = MeshGroups()
        return store

    @property
    def cell_groups(self) -> dict[str, np.ndarray]:
        """Named groups of cells, name → rows of ``cells``: gmsh's physical groups of the file's
        dimension (or a VTK file's integer cell data), and those added by ``add_cell_group``. They
        follow refinement and cuts (a cell takes its parent's groups)."""
        return self._group_store.cell_groups(self)

    @property
    def boundary_groups(self) -> dict[str, np.ndarray]:
        """Named groups of boundary faces, name → (n, cell_dim) vertex indices: gmsh's physical
        groups one dimension lower than the cells, and those added by ``add_boundary_group``.
        They follow refinement (a face takes its parent's groups); the faces cuts open form the
        group ``"incision"`` (present, maybe empty, once any group is given)."""
        return self._group_store.boundary_groups(self)

    def add_cell_group(self, name: str, rows) -> None:
        """Name a group of cells: ``rows`` of ``cells`` (indices or a boolean mask)."""
        self._group_store.add_cells(self, name, rows)

    def add_boundary_group(self, name: str, faces) -> None:
        """Name a group of boundary faces, (n, cell_dim) vertex indices (e.g. from
        ``faces_where(..., interior=False)`` or ``boundary_patch``); a face that is not on the
        boundary is refused."""
        self._group_store.add_faces(self, name, faces)

    def group_vertices(self, name: str) -> np.ndarray:
        """The vertices of the named boundary or cell group (boundary groups first), sorted;
        a KeyError listing the names if there is none."""
        for groups, rows_to_vertices in ((self.boundary_groups, lambda faces: faces),
                                         (self.cell_groups, lambda rows: self.cells[rows])):
            if name in groups:
                return np.unique(rows_to_vertices(groups[name]))
        known = sorted(set(self.boundary_groups) | set(self.cell_groups))
        raise KeyError(f"no group {name!r} in this mesh (its groups: {', '.join(known) or 'none'})")

    # -- queries -----------------------------------------------------------------------
    def boundary_faces(self) -> np.ndarray:
        """(n_faces, cell_dim) vertex indices of the boundary faces (edges of triangles, in 2D
        or on a surface), oriented with the outward normal for tetrahedra and counter-clockwise
        around the body in 2D."""
        return self._impl.boundary_faces()

    def quality(self) -> MeshQuality:
        """Per-cell volume, aspect ratio and extreme dihedral angles (radians), see MeshQuality."""
        return MeshQuality(**self._impl.quality())

    def validate(self) -> None:
        """Check the connectivity invariants (7.1)–(7.5) and positive orientation of every
        cell; raise ``snede.InvalidMesh`` (a ValueError) describing the first violation."""
        self._impl.validate()

    def element_vertices(self, element: int) -> np.ndarray:
        """The vertices of the cell with element id ``element`` (stable across edits, unlike
        row numbers), in its row order of ``cells``."""
        element = _checks.index(element, "element", _checks.ID_LIMIT, "element ids")
        return np.asarray(self._impl.element_vertices(element), dtype=np.int64)

    def star(self, vertex: int) -> np.ndarray:
        """Element ids of all cells containing ``vertex`` (a scan, O(n))."""
        return np.asarray(self._impl.star(self._vertex(vertex)), dtype=np.int64)

    def connected_components(self) -> tuple[int, np.ndarray]:
        """(number of components, (n_cells,) component label per row of ``cells``)."""
        return self._impl.connected_components()

    def points_vec(self):
        """The coordinates as a sequential ``petsc4py.PETSc.Vec`` of block size ``dim``."""
        return self._impl.points_vec()

    def memory_bytes(self) -> int:
        """Bytes held by the coordinates and the connectivity (capacity, not just size)."""
        return self._impl.memory_bytes()

    def faces_where(self, inside, interior: bool = True) -> np.ndarray:
        """Faces whose vertices all satisfy ``inside`` — a boolean mask over the points, or a
        function of the (n_points, dim) coordinates returning one — as (n, cell_dim) sorted vertex
        indices. With ``interior`` (default) only faces between two cells: what ``dissect``
        takes, e.g. ``mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5))``."""
        mask = np.asarray(inside(self.points) if callable(inside) else inside, dtype=bool)
        if mask.shape != (self.n_points,):
            raise ValueError(f"inside must give one boolean per point ({self.n_points}), got shape {mask.shape}")
        cells = self.cells
        faces = np.concatenate([np.delete(cells, k, axis=1) for k in range(cells.shape[1])])
        faces = np.sort(faces[np.all(mask[faces], axis=1)], axis=1)
        unique, counts = np.unique(faces, axis=0, return_counts=True)
        return unique[counts == 2] if interior else unique

    # -- aiming (where a needle or a blade meets the body) -------------------------------
    def _vector(self, value, name: str) -> np.ndarray:
        try:
            vector = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            vector = np.full(0, np.nan)
        if vector.shape != (self.dim,) or not np.all(np.isfinite(vector)):
            raise ValueError(f"{name} must be {self.dim} finite numbers for this {self.dim}-D mesh, got {value!r}")
        return vector

    def _aiming_faces(self, displacement) -> tuple[np.ndarray, np.ndarray]:
        """The faces a ray can meet — the boundary faces, or every triangle of a surface mesh —
        and the points, displaced by ``displacement`` ((n_points, dim)) when it is given."""
        points = self.points
        if displacement is not None:
            displacement = np.asarray(displacement, dtype=np.float64)
            if displacement.shape != points.shape:
                raise ValueError(f"displacement must have shape {points.shape} (n_points, dim), "
                                 f"got {displacement.shape}")
            points = points + displacement
        return (self.cells if self.is_surface else self.boundary_faces()).astype(np.int64), points

    def ray_hit(self, origin, direction, displacement=None) -> RayHit | None:
        """The first boundary point the ray ``origin + t·direction`` (t ≥ 0) meets, as a
        ``RayHit`` (point, face, weights, distance), or None if it misses. The boundary is the
        boundary triangles of a tetrahedral mesh, every triangle of a surface mesh, the boundary
        edges of a 2D mesh; with ``displacement`` ((n_points, dim), e.g. ``body.displacement``)
        it is the deformed one. A ray starting inside the body meets it where it leaves."""
        origin, direction = self._vector(origin, "origin"), self._vector(direction, "direction")
        length = np.linalg.norm(direction)
        if length == 0:
            raise ValueError("direction must not be zero")
        direction = direction / length
        faces, points = self._aiming_faces(displacement)
        corners = [points[faces[:, k]] for k in range(faces.shape[1])]
        tolerance = 1e-12  # on barycentric coordinates: a ray through an edge hits a face beside it
        if self.dim == 3:
            t, u, v = _geometry.ray_triangles(origin, direction, *corners)
            weights = np.c_[1 - u - v, u, v]
        else:
            t, s = _geometry.ray_segments(origin, direction, *corners)
            weights = np.c_[1 - s, s]
        with np.errstate(invalid="ignore"):
            hits = np.flatnonzero((t >= 0) & np.all(weights >= -tolerance, axis=1))
        if len(hits) == 0:
            return None
        first = hits[np.argmin(t[hits])]
        return RayHit(origin + t[first] * direction, faces[first], weights[first], float(t[first]))

    def boundary_patch(self, point, radius: float, displacement=None) -> np.ndarray:
        """The boundary vertices within ``radius`` of ``point`` (all vertices of a surface mesh
        count), as sorted vertex indices, what ``Body.fix`` and ``add_nodal_force`` take; with
        ``displacement`` ((n_points, dim)) measured on the deformed body."""
        point = self._vector(point, "point")
        radius = _checks.non_negative(radius, "radius")
        faces, points = self._aiming_faces(displacement)
        vertices = np.unique(faces)
        return vertices[np.linalg.norm(points[vertices] - point, axis=1) <= radius]

    # -- changes -----------------------------------------------------------------------
    @serial_only
    def dissect(self, faces) -> np.ndarray:
        """Cut along interior faces (§7.3), given as ``(n, cell_dim)`` vertex indices (either
        orientation). Vertices whose star the cut splits are duplicated (same coordinates).
        Returns ``(n_new, 2)`` pairs ``(original, copy)``."""
        faces = np.asarray(faces)
        if faces.dtype.kind not in "iu" or faces.ndim != 2 or faces.shape[1] != self.cell_dim:
            raise ValueError(f"faces must be (n, {self.cell_dim}) integer vertex indices, got {faces.shape} {faces.dtype}")
        return _snede.dissect(self._impl, _checks.index_array(faces, "faces", self.n_points, "a vertex of the mesh"))

    @contextlib.contextmanager
    def batch(self):
        """``with mesh.batch(): ...edits...``: a Body on the mesh hears of all the edits once, at
        the end (one reissue of its vectors, fields carried through every step in order),
        instead of once per edit. Nestable. Bodies must not be used inside the block."""
        self._impl.begin_batch()
        try:
            yield self
        finally:
            self._impl.end_batch()

    # -- vertex lifecycle ----------------------------------------------------------------
    def _parents(self, parents, weights) -> tuple[np.ndarray, np.ndarray]:
        parents = np.atleast_1d(np.asarray(parents))
        weights = np.atleast_1d(np.asarray(weights, dtype=np.float64))
        if parents.dtype.kind not in "iu" or parents.ndim != 1 or weights.shape != parents.shape:
            raise ValueError(f"parents must be 1-D vertex indices with one weight each, got {parents.shape} "
                             f"{parents.dtype} and weights {weights.shape}")
        parents = _checks.index_array(parents, "parents", self.n_points, "a vertex of the mesh")
        return parents, np.ascontiguousarray(weights)

    @serial_only
    def add_vertex(self, parents, weights) -> int:
        """Add a vertex at ``Σ weights[i]·x[parents[i]]`` (barycentric: weights sum to 1) and
        return its id (a removed id is reused). Watchers (a Body) give it the interpolated
        displacement with the next mesh change."""
        return self._impl.add_vertex(*self._parents(parents, weights))

    @serial_only
    def move_vertex(self, vertex: int, parents=None, weights=None, *, point=None) -> None:
        """Move ``vertex`` in the reference configuration, either to ``Σ weights[i]·x[parents[i]]``
        (``parents`` may include ``vertex``; a Body re-interpolates its displacement the same
        way) or to explicit coordinates ``point`` (the displacement is kept). Moving a vertex
        can invert cells: ``snap_vertex`` refuses that, this does not."""
        if (point is None) == (parents is None):
            raise ValueError("give either parents and weights, or point")
        if point is not None:
            self._impl.move_vertex_to(self._vertex(vertex), np.ascontiguousarray(point, dtype=np.float64))
        else:
            self._impl.move_vertex(self._vertex(vertex), *self._parents(parents, weights))

    @serial_only
    def remove_vertex(self, vertex: int) -> None:
        """Remove a vertex that no cell uses any more (its id is reused by a later addition)."""
        self._impl.remove_vertex(self._vertex(vertex))

    # -- refinement (§6.5) -------------------------------------------------------------
    def _bisection(self):
        """The engine's bisection state (labelling and hierarchy), made on first use and kept
        with the mesh so that later refinements continue the same labelling."""
        bisection = self.__dict__.get("_bisection_impl")
        if bisection is None:
            bisection = self.__dict__["_bisection_impl"] = _snede.Bisection(self._impl)
        return bisection

    def _bisection_if_any(self):
        """The engine's bisection state if the mesh was ever refined by bisection, else None."""
        return self.__dict__.get("_bisection_impl")

    @serial_only
    def refine_uniform(self, levels: int | None = None, *, target_cells: int | None = None) -> int:
        """Bisect every cell ``levels`` times (default 1) by conforming bisection (§6.5:
        newest-vertex in 2D; in 3D Maubach's on ``meshing.box``, longest-edge on any other
        mesh); or, given ``target_cells`` instead, level after
        level until the mesh has at least ``target_cells`` cells (the fewest levels that reach
        it, so it may overshoot by a level's growth). Returns how many cells were split.

        Growth per level: on ``meshing.rectangle`` and ``meshing.box`` each level doubles the
        cell count exactly; on unstructured meshes conformity splits more, about 3.3× per level
        in 3D after the first (3.9–4.5× at the first: 1125 → 4427 → 14 443 → 46 977 tetrahedra
        in three levels on meshes/cylinder_small.msh, 596 → 31 597 on SOFA's liver.msh) and 2.2× in
        2D (a gmsh disk: 757 → 41 220 in five levels). ``levels`` is at most what keeps the
        cell count within the engine's 32-bit ids (each level at least doubles it)."""
        if target_cells is not None:
            if levels is not None:
                raise ValueError(f"give levels or target_cells, not both (got levels={levels!r}, "
                                 f"target_cells={target_cells!r})")
            target_cells = _checks.count(target_cells, "target_cells", 1)
            split = 0
            with self.batch():  # watchers (a Body) hear of all the levels at once
                while self.n_cells < target_cells:
                    split += self.refine_uniform(1)
            return split
        levels = 1 if levels is None else levels
        cells = max(self.n_cells, 1)
        most = (_checks.INT32_MAX // cells).bit_length() - 1  # n_cells · 2**most ≤ 2**31 − 1
        levels = _checks.count(levels, "levels", 0, most,
                               f": each level at least doubles the {self.n_cells} cells, and the engine numbers "
                               f"at most 2**31 − 1")
        return self._bisection().refine_uniform(levels)

    @serial_only
    def refine_around(self, point, h: float) -> int:
        """Bisect (§6.5 refine-around) until every cell containing ``point`` (shape (dim,))
        has edges no longer than ``h``; the refinement spreads only as far as conformity
        needs. Returns how many cells were split."""
        point = _checks.coordinates(point, (self.dim,), "point")
        return self._bisection().refine_around(point, _checks.positive(h, "h"))

    @serial_only
    def refine_near_segment(self, a, b, h: float, radius: float = 0.0) -> int:
        """Bisect until every cell that comes within ``radius`` of the segment ``a``–``b``
        (shape (dim,) each; a needle's shaft) has edges no longer than ``h``, as one mesh
        change. Nearness is decided on each cell's bounding ball, so cells up to one cell size
        beyond ``radius`` may be refined too. Returns how many cells were split."""
        a, b = (_checks.coordinates(end, (self.dim,), name) for end, name in ((a, "a"), (b, "b")))
        return self._bisection().refine_near_segment(a, b, _checks.positive(h, "h"),
                                                     _checks.non_negative(radius, "radius"))

    # -- files -------------------------------------------------------------------------
    @classmethod
    def read(cls, path) -> "Mesh":
        """Read a mesh file: gmsh ``.msh`` (formats 1, 2 and 4), VTK legacy ``.vtk`` (unstructured
        grids, and POLYDATA surfaces) and ``.vtu``, Medit ``.mesh``, XDMF, and the surface formats
        STL, OBJ, OFF and PLY — meshio's reader first, gmsh's own where meshio fails (in a child
        process: it crashes on some damaged files), snede's own for gmsh format 1. Tetrahedra
        are taken if present, else triangles (quads and polygons split into triangles from their
        first vertex): a 2D mesh when every z is 0, otherwise a surface mesh in 3D; triangles with
        a repeated vertex (STL files have them) are left out with a warning. Every point of the
        file is kept, in its order. A file that cannot be read, or holds no mesh snede can use,
        raises a ValueError naming the file and why (for a damaged text gmsh or VTK file, the line
        and what is wrong with it).

        An ``.xdmf`` time series written by ``snede.output.SeriesWriter`` (which meshio cannot
        read) gives the mesh of its last step; use ``snede.output.read_series`` for every step
        with its own mesh and fields."""
        from snede import mesh_files

        if not Path(path).exists():
            raise FileNotFoundError(f"no mesh file {path}")
        if Path(path).suffix.lower() in (".xdmf", ".xmf"):
            from snede import series_files

            if series_files.is_series(path):
                steps = series_files.read_steps(path, cls, last_only=True)
                if not steps:
                    raise ValueError(f"{path}: the series has no steps (yet): no mesh to read")
                return steps[-1][1]

        points, blocks, groups = mesh_files.read_blocks(Path(path))
        kind = "tetra" if "tetra" in blocks else "triangle"
        if kind not in blocks:
            raise ValueError(f"{path}: no tetrahedra or triangles (cell types: {sorted(blocks)})")
        cells = blocks[kind]
        if kind == "triangle":
            if points.shape[1] == 3 and np.all(points[:, 2] == 0):
                points = points[:, :2]
            collapsed = (cells[:, 0] == cells[:, 1]) | (cells[:, 1] == cells[:, 2]) | (cells[:, 2] == cells[:, 0])
            if collapsed.any():  # STL files hold them: corners merged into one point
                warnings.warn(f"{path}: {collapsed.sum()} triangles with a repeated vertex (no area) left out",
                              stacklevel=2)
                cells = cells[~collapsed]
        try:
            mesh = cls(points, cells)
        except ValueError as error:  # keep the type (InvalidMesh is one), name the file
            raise type(error)(f"{path}: {error}") from None
        mesh._add_file_groups(path, kind, groups)
        return mesh

    def _add_file_groups(self, path, kind: str, groups) -> None:
        """A file's groups of cells (of the mesh's kind) and of boundary faces (one dimension
        lower); a face group that is not on the boundary (an interface inside), or one whose name
        a group of the other dimension took, is left out with a warning."""
        face_kind = {"tetra": "triangle", "triangle": "line"}[kind]
        rows = {tuple(cell): row for row, cell in enumerate(np.sort(self.cells, axis=1).tolist())}
        for cell_type, name, cells in groups:
            try:
                if cell_type == kind:
                    keys = [tuple(cell) for cell in np.sort(cells, axis=1).tolist()]
                    self.add_cell_group(name, [rows[key] for key in keys if key in rows])
                elif cell_type == face_kind:
                    self.add_boundary_group(name, cells)
            except ValueError as error:  # an interface inside, a name given to two dimensions
                warnings.warn(f"{path}: {error}; the group is left out", stacklevel=3)

    def write(self, path) -> None:
        """Write with meshio; the format follows the file extension (.msh, .vtu, .xdmf, ...)."""
        import meshio

        points = self.points
        if self.dim == 2:
            points = np.column_stack([points, np.zeros(len(points))])
        kind = "tetra" if self.cell_dim == 3 else "triangle"
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        # meshio's default for .msh is ANSYS Fluent; snede's .msh files are gmsh's.
        gmsh = Path(path).suffix == ".msh"
        meshio.Mesh(points, [(kind, self.cells)]).write(
            str(path), **({"file_format": "gmsh22", "binary": False} if gmsh else {}))

    def __repr__(self) -> str:
        kind = "tetrahedra" if self.cell_dim == 3 else "surface triangles" if self.is_surface else "triangles"
        return f"<snede.Mesh {self.n_cells} {kind}, {self.n_live_points} points>"
