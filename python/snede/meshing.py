"""Mesh generators: structured boxes and rectangles, unstructured solids (gmsh: a cylinder, an
ellipsoid, a torus, a lumpy organ-like solid, the inside of any closed surface), and
surfaces in 3D for cutting (height fields, the Gaussian bell of Figure 5.19, a folded sheet).

The gmsh generators first estimate how many tetrahedra their edge length makes
(``tetrahedra_estimate``), and the structured box and rectangle count theirs, and refuse more
than ``max_cells`` (default ``MAX_CELLS``) with a ValueError that gives the number: a length
given in the wrong unit (1e-9 for 1e-3), or 1000 divisions a side, would otherwise keep gmsh
or numpy busy for hours and then exhaust the memory."""
from __future__ import annotations

import itertools
import math

import numpy as np

from snede import _checks, _geometry, _gmsh
from snede.mesh import Mesh

# The generators' default limit: gmsh takes about 60 µs and 0.6 kB per tetrahedron
# (measured on a cylinder of 1.3 million), so 10 million take some 10 minutes and 6 GB; a body
# of that size is beyond what a static solve or an interactive session relaxes in useful time.
MAX_CELLS = 10_000_000


def _grid_points(size, divisions) -> np.ndarray:
    axes = [np.linspace(0.0, s, n + 1) for s, n in zip(size, divisions)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(size))


def _check(size, divisions, dim: int, cells_per_box: int, max_cells):
    size = tuple(float(s) for s in size)
    divisions = tuple(divisions)
    if len(size) != dim or len(divisions) != dim:
        raise ValueError(f"size and divisions must have {dim} entries, got {size} and {divisions}")
    if not all(np.isfinite(s) and s > 0 for s in size):
        raise ValueError(f"size must be positive and finite, got {size}")
    divisions = tuple(_checks.count(n, f"divisions[{k}]", 1, None) for k, n in enumerate(divisions))
    # What the engine cannot number (32-bit ids) first, then what it could but should not build.
    _checks.size(math.prod(n + 1 for n in divisions), cells_per_box * math.prod(divisions), f"divisions {divisions}")
    check_cells(cells_per_box * math.prod(divisions), _checks.count(max_cells, "max_cells", 1, None),
                f"divisions {divisions}", "give fewer divisions, or raise max_cells if you mean it",
                "tetrahedra" if dim == 3 else "triangles")
    return size, divisions


def box(size=(1.0, 1.0, 1.0), divisions=(10, 10, 10), *, max_cells: int = MAX_CELLS, comm=None):
    """Structured tetrahedra on [0, size]: each of the nx·ny·nz cubes split into six
    tetrahedra around its main diagonal (the Kuhn split, which conforming bisection needs).
    Gives 6·nx·ny·nz cells and (nx+1)(ny+1)(nz+1) points; more than ``max_cells`` are refused
    (see the module).

    ``comm`` (an mpi4py communicator; collective): the same mesh made on the ranks, which no
    rank holds whole (issue 52): each rank makes the cubes of its share of the x layers and the
    points of its share of the point layers, and DMPlex balances them; it returns this rank's
    part, a :class:`snede.distributed.DistributedMesh` whose ``global_vertex`` are the serial
    box's vertex ids."""
    size, divisions = _check(size, divisions, 3, 6, max_cells)
    if comm is None:
        return Mesh(_grid_points(size, divisions), _box_cells(0, divisions[0], divisions))
    from snede.distributed import distribute_cells

    nx, ny, nz = divisions
    first, last = _share(nx, comm.rank, comm.size)
    low, high = _share(nx + 1, comm.rank, comm.size)
    axes = [np.linspace(0.0, s, n + 1) for s, n in zip(size, divisions)]
    axes[0] = axes[0][low:high]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return distribute_cells(_box_cells(first, last, divisions), points, comm)


def _share(n: int, rank: int, ranks: int) -> tuple[int, int]:
    """Rank ``rank``'s part of ``n`` layers split as evenly as possible, in rank order."""
    return rank * n // ranks, (rank + 1) * n // ranks


def _box_cells(first: int, last: int, divisions) -> np.ndarray:
    """The Kuhn tetrahedra of the box's cubes in x layers first..last − 1 (serial vertex ids)."""
    nx, ny, nz = divisions

    def vertex(i, j, k):
        return (i * (ny + 1) + j) * (nz + 1) + k

    i, j, k = (a.ravel() for a in np.meshgrid(np.arange(first, last), np.arange(ny), np.arange(nz), indexing="ij"))
    cells = []
    # Kuhn split: one tetrahedron per path 000 -> 111 along the axes in the order of a permutation.
    for permutation in itertools.permutations(range(3)):
        corner = np.zeros(3, dtype=np.int64)
        path = [vertex(i, j, k)]
        for axis in permutation:
            corner[axis] += 1
            path.append(vertex(i + corner[0], j + corner[1], k + corner[2]))
        odd = np.linalg.det(np.eye(3)[list(permutation)]) < 0
        if odd:  # keep every cell positively oriented
            path[2], path[3] = path[3], path[2]
        cells.append(np.stack(path, axis=1))
    return np.concatenate(cells).astype(np.int64, copy=False)


def rectangle(size=(1.0, 1.0), divisions=(10, 10), *, max_cells: int = MAX_CELLS) -> Mesh:
    """Structured right triangles on [0, size]: each square split along its diagonal from
    (x, y) to (x + hx, y + hy). Gives 2·nx·ny cells and (nx+1)(ny+1) points; more than
    ``max_cells`` are refused (see the module)."""
    size, divisions = _check(size, divisions, 2, 2, max_cells)
    nx, ny = divisions
    points = _grid_points(size, divisions)
    i, j = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij"))

    def vertex(i, j):
        return i * (ny + 1) + j

    lower = np.stack([vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)], axis=1)
    upper = np.stack([vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)], axis=1)
    return Mesh(points, np.concatenate([lower, upper]))


def _positive(**values) -> None:
    for name, value in values.items():
        _checks.positive(value, name)


_REGULAR_TETRAHEDRON = 1.0 / (6.0 * math.sqrt(2.0))  # volume of the regular tetrahedron of edge 1
_EQUILATERAL_TRIANGLE = math.sqrt(3.0) / 4.0  # area of the equilateral triangle of side 1
# gmsh's tetrahedra at target edge h are about twice as large as regular ones of edge h: it made
# 0.47–0.52 of tetrahedra_estimate's count on a cylinder, a torus and a thin slab at several h
_GMSH_SHARE = 0.5


def tetrahedra_estimate(volume: float, area: float, h: float) -> float:
    """How many regular tetrahedra of edge ``h`` fill a solid of ``volume`` and boundary ``area``:
    the volume over that of one, plus one per boundary triangle (the area over that of an
    equilateral triangle of side h), which a thin solid has more of than it has volume for."""
    return volume / _REGULAR_TETRAHEDRON / h / h / h + area / _EQUILATERAL_TRIANGLE / h / h


def check_cells(estimate: float, max_cells: int, given: str,
                remedy: str = "give a larger edge length (each halving makes 8 times as many), or raise max_cells "
                              "if you mean it", cells: str = "tetrahedra") -> None:
    """Refuse ``estimate`` cells beyond ``max_cells`` with a ValueError: ``given`` names the value
    that asks for them ("h = 1e-09"), ``remedy`` what to do."""
    if not estimate <= max_cells:
        about = f"about {estimate:.2g}" if math.isfinite(estimate) else "more than 1e308"
        raise ValueError(f"{given} would make {about} {cells} (limit {max_cells}); {remedy}")


def _check_size(volume: float, area: float, h: float, max_cells, name: str = "h") -> None:
    max_cells = _checks.count(max_cells, "max_cells", 1, None)
    check_cells(_GMSH_SHARE * tetrahedra_estimate(volume, area, h), max_cells, f"{name} = {h:g}")


def _gmsh_tetrahedra(name: str, add_solid, h: float, seed: int | None) -> Mesh:
    """Tetrahedra of the OpenCASCADE solid that ``add_solid(occ)`` adds, meshed by gmsh
    (Delaunay, then optimised) at target edge length ``h``; deterministic for given arguments
    (gmsh's random factor fixed by ``seed`` when given)."""
    def add(gmsh):
        add_solid(gmsh.model.occ)
        gmsh.model.occ.synchronize()
    return _gmsh_fill(name, add, h, seed)


def _gmsh_fill(name: str, add_volume, h: float, seed: int | None) -> Mesh:
    """Tetrahedra of the volume that ``add_volume(gmsh)`` adds to a new gmsh model (leaving it
    synchronised), at target edge length ``h``: gmsh's Delaunay mesher, then its optimiser."""
    if seed is not None:
        seed = _checks.count(seed, "seed", 0)  # gmsh's Mesh.RandomSeed is a C int
    with _gmsh.model(f"snede-{name}") as gmsh:
        add_volume(gmsh)
        for option, value in (("Mesh.MeshSizeMin", h), ("Mesh.MeshSizeMax", h), ("Mesh.MeshSizeFromCurvature", 0),
                              ("Mesh.Algorithm3D", 1), ("Mesh.Optimize", 1)):
            gmsh.option.setNumber(option, value)
        if seed is not None:
            gmsh.option.setNumber("Mesh.RandomSeed", seed)
        gmsh.model.mesh.generate(3)
        points, blocks = _gmsh.elements(gmsh, 3)
    tetrahedra = [cells for kind, cells in blocks if kind == "tetra"]
    if not tetrahedra:
        raise RuntimeError(f"gmsh produced no tetrahedra for the {name}")
    # gmsh lists nodes that are not in any tetrahedron (geometry points); keep only used ones.
    used, cells = np.unique(np.concatenate(tetrahedra), return_inverse=True)
    return Mesh(points[used], cells.reshape(-1, 4))


def cylinder(length=0.1, radius=0.03, h=0.01, seed: int | None = None, *, max_cells: int = MAX_CELLS) -> Mesh:
    """Unstructured tetrahedra of the cylinder 0 ≤ x ≤ length, y² + z² ≤ radius², meshed by
    gmsh (Delaunay, then optimised) with target edge length ``h``. Deterministic for given
    arguments (gmsh's random factor is fixed by ``seed`` when given). ``max_cells``: see the
    module."""
    _positive(length=length, radius=radius, h=h)
    _check_size(math.pi * radius**2 * length, 2 * math.pi * radius * (radius + length), h, max_cells)
    return _gmsh_tetrahedra("cylinder", lambda occ: occ.addCylinder(0, 0, 0, length, 0, 0, radius), h, seed)


def ellipsoid(radii=(0.06, 0.04, 0.03), h=0.01, seed: int | None = None, *, max_cells: int = MAX_CELLS) -> Mesh:
    """Unstructured tetrahedra (gmsh, edge length ``h``) of the ellipsoid centred at the origin
    with semi-axes ``radii`` along x, y, z. ``max_cells``: see the module."""
    radii = np.asarray(radii, dtype=np.float64)
    if radii.shape != (3,):
        raise ValueError(f"radii must be 3 numbers, got shape {radii.shape}")
    _positive(h=h, **{f"radii[{k}]": r for k, r in enumerate(radii)})
    a, b, c = radii
    # the area by Thomsen's formula (within 1.1 %)
    p = 1.6075
    area = 4 * math.pi * (((a * b) ** p + (a * c) ** p + (b * c) ** p) / 3) ** (1 / p)
    _check_size(4 / 3 * math.pi * a * b * c, area, h, max_cells)

    def add(occ):
        sphere = occ.addSphere(0, 0, 0, 1.0)
        occ.dilate([(3, sphere)], 0, 0, 0, *radii)
    return _gmsh_tetrahedra("ellipsoid", add, h, seed)


def hollow_sphere(inner=0.5, outer=1.0, h=0.1, seed: int | None = None, *, max_cells: int = MAX_CELLS) -> Mesh:
    """Unstructured tetrahedra (gmsh, edge length ``h``) of the shell inner ≤ |x| ≤ outer centred
    at the origin: the pressurised sphere of Lamé's analytic solution (studies/benchmarks/locking.py).
    ``max_cells``: see the module."""
    _positive(inner=inner, outer=outer, h=h)
    if not inner < outer:
        raise ValueError(f"inner radius must be below the outer one, got inner={inner}, outer={outer}")
    _check_size(4 / 3 * math.pi * (outer**3 - inner**3), 4 * math.pi * (outer**2 + inner**2), h, max_cells)

    def add(occ):
        shell, _ = occ.cut([(3, occ.addSphere(0, 0, 0, outer))], [(3, occ.addSphere(0, 0, 0, inner))])
        assert len(shell) == 1
    return _gmsh_tetrahedra("hollow sphere", add, h, seed)


def torus(radius=0.05, tube=0.02, h=0.01, seed: int | None = None, *, max_cells: int = MAX_CELLS) -> Mesh:
    """Unstructured tetrahedra (gmsh, edge length ``h``) of the torus around the z axis with
    centre-line ``radius`` and tube radius ``tube`` < ``radius``: a body with a hole, which one
    cut through its ring leaves in one piece. ``max_cells``: see the module."""
    _positive(radius=radius, tube=tube, h=h)
    if not tube < radius:
        raise ValueError(f"tube ({tube}) must be smaller than radius ({radius})")
    _check_size(2 * math.pi**2 * radius * tube**2, 4 * math.pi**2 * radius * tube, h, max_cells)
    return _gmsh_tetrahedra("torus", lambda occ: occ.addTorus(0, 0, 0, radius, tube), h, seed)


def lumpy(radius=0.04, lumps: int = 6, h=0.01, seed: int = 0, *, max_cells: int = MAX_CELLS) -> Mesh:
    """Unstructured tetrahedra (gmsh, edge length ``h``) of an organ-like lumpy solid: a sphere
    of ``radius`` fused with ``lumps`` smaller spheres (radius 0.45–0.7 × ``radius``) centred
    0.6–0.9 × ``radius`` from its centre in directions drawn from ``seed``: lobes, necks and
    concave folds a cut can run into. ``max_cells``: see the module (the estimate takes the
    spheres' volumes and areas as if apart, at most 0.7³ and 0.7² of the big one's per lump)."""
    _positive(radius=radius, h=h)
    lumps = _checks.count(lumps, "lumps", 0)
    _check_size(4 / 3 * math.pi * radius**3 * (1 + 0.7**3 * lumps), 4 * math.pi * radius**2 * (1 + 0.7**2 * lumps),
                h, max_cells)
    rng = np.random.default_rng(_checks.count(seed, "seed", 0))
    directions = rng.normal(size=(lumps, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    centres = directions * rng.uniform(0.6, 0.9, size=(lumps, 1)) * radius
    radii = rng.uniform(0.45, 0.7, size=lumps) * radius

    def add(occ):
        body = [(3, occ.addSphere(0, 0, 0, radius))]
        others = [(3, occ.addSphere(*c, r)) for c, r in zip(centres, radii)]
        if others:
            occ.fuse(body, others)
    return _gmsh_tetrahedra("lumpy", add, h, seed)


def _where(point) -> str:
    return "(" + ", ".join(f"{float(x):.4g}" for x in point) + ")"


def tetrahedralize(surface, size: float, *, remesh: bool = True, seed: int | None = None,
                   max_cells: int = MAX_CELLS) -> Mesh:
    """Tetrahedra filling a closed triangle surface: ``surface`` is a surface ``Mesh`` (triangles
    in 3D) or a file ``Mesh.read`` reads as one (STL, OBJ, OFF, PLY, VTK, ...). gmsh fills it
    (Delaunay, then optimised) with edges of about ``size``. With ``remesh`` (default) gmsh first
    remeshes the surface at ``size`` on its own triangles (in patches split at creases sharper
    than 40°, which stay sharp): a coarser polyhedron, which on a sphere of radius R encloses
    about 0.3·(size/R)² less (1 % at size = R/5.5). ``remesh=False`` keeps the surface's
    triangles as the boundary of the result (the same volume), and the tetrahedra near it take
    their size from them. ``seed`` fixes gmsh's random factor. ``max_cells``: the most tetrahedra
    to make (see the module), estimated from the volume and area the surface encloses.

    A ValueError names what stops it: a mesh that is no surface, a surface that is open (with
    one of its boundary edges), in several pieces, or that crosses itself (with a pair of
    crossing triangles and where they are), or else gmsh's own error."""
    if not isinstance(surface, Mesh):
        surface = Mesh.read(surface)
    _positive(size=size)
    if not surface.is_surface:
        raise ValueError(f"tetrahedralize fills a closed surface (triangles in 3D), got {surface!r}"
                         + (": its boundary is meshing.boundary_surface(mesh)[0]" if surface.cell_dim == 3 else ""))
    points, triangles = surface.points, surface.cells
    edges = surface.boundary_faces()
    if len(edges):
        a, b = edges[0]
        raise ValueError(f"the surface is open: {len(edges)} edges belong to one triangle only, e.g. the edge from "
                         f"vertex {a} at {_where(points[a])} to vertex {b} at {_where(points[b])}; tetrahedralize "
                         "needs a closed surface")
    pieces = surface.connected_components()[0]
    if pieces > 1:
        raise ValueError(f"the surface is in {pieces} separate pieces; tetrahedralize fills one closed surface: "
                         "pass each piece alone")
    # A surface Mesh's triangles are oriented alike, so the signed volumes of the cones from the
    # origin add up to ± the enclosed volume.
    a, b, c = (points[triangles[:, k]] for k in range(3))
    volume = abs(float(np.einsum("ij,ij->", a, np.cross(b, c)))) / 6
    area = float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()) / 2
    _check_size(volume, area, size, max_cells, "size")

    def add(gmsh):
        entity = gmsh.model.addDiscreteEntity(2)
        gmsh.model.mesh.addNodes(2, entity, np.arange(1, len(points) + 1), points.ravel())
        gmsh.model.mesh.addElementsByType(entity, 2, [], (triangles + 1).ravel())
        if remesh:
            gmsh.model.mesh.classifySurfaces(math.radians(40), True, True, math.pi)
            gmsh.model.mesh.createGeometry()
        gmsh.model.geo.addVolume([gmsh.model.geo.addSurfaceLoop([tag for _, tag in gmsh.model.getEntities(2)])])
        gmsh.model.geo.synchronize()

    try:
        return _gmsh_fill("surface", add, size, seed)
    except Exception as error:  # gmsh raises plain Exceptions
        crossing = _geometry.crossing_triangles(points, triangles)
        if len(crossing):
            i, j = crossing[0]
            raise ValueError(f"the surface crosses itself: {len(crossing)} pairs of triangles cross, e.g. triangles "
                             f"{i} {triangles[i].tolist()} and {j} {triangles[j].tolist()} near "
                             f"{_where(points[triangles[i]].mean(axis=0))} (gmsh: {error})") from None
        hint = "; the remeshed one may: try another size, or remesh=False" if remesh else ""
        raise ValueError(f"gmsh could not fill the surface: {error}; no two of its triangles cross (touching ones "
                         f"are not looked for){hint}") from None


def lifted(sheet: Mesh, to_space) -> Mesh:
    """The triangles of a 2D mesh mapped into 3D by ``to_space(x, y) -> (n, 3)`` points."""
    if sheet.cell_dim != 2 or sheet.space_dim != 2:
        raise ValueError(f"lifted maps a 2D triangle mesh, got {sheet.cell_dim}-D cells in {sheet.space_dim}-D")
    x, y = sheet.points.T
    points = np.asarray(to_space(x, y), dtype=np.float64)
    if points.shape != (len(x), 3) or not np.all(np.isfinite(points)):
        raise ValueError(f"to_space must give finite ({len(x)}, 3) points, got shape {points.shape}")
    return Mesh(points, sheet.cells)


def height_field(height, size=(1.0, 1.0), divisions=(10, 10)) -> Mesh:
    """The surface z = height(x, y) over ``rectangle(size, divisions)`` (``height`` takes and
    returns numpy arrays)."""
    return lifted(rectangle(size, divisions), lambda x, y: np.c_[x, y, np.broadcast_to(height(x, y), x.shape)])


def gaussian_bell(amplitude: float = 0.4, spread: float = 0.08, divisions: int = 14) -> Mesh:
    """z = amplitude · exp(−((x − ½)² + (y − ½)²) / spread) over the unit square, 2·divisions²
    triangles: by default the 392-triangle bell of the thesis's Figure 5.19."""
    return height_field(lambda x, y: amplitude * np.exp(-((x - 0.5) ** 2 + (y - 0.5) ** 2) / spread),
                        divisions=(divisions, divisions))


def folded_sheet(flat: float = 0.4, radius: float = 0.15, divisions=(10, 8)) -> Mesh:
    """A unit-wide sheet folded over itself along y: a lower layer z = 0 for x in [0, flat], a
    half-cylinder crease of ``radius``, and an upper layer z = 2·radius running back towards
    x = 0, as long as the rest of the sheet allows (the sheet's length is 1.4)."""
    length = 1.4

    def to_space(x, y):
        s = x * length  # arc length across the sheet
        angle = np.clip((s - flat) / radius, 0.0, math.pi)
        crease = (s > flat) & (s < flat + math.pi * radius)
        upper = s >= flat + math.pi * radius
        sx = np.where(crease, flat + radius * np.sin(angle), np.where(upper, flat - (s - flat - math.pi * radius), s))
        sz = np.where(crease, radius - radius * np.cos(angle), np.where(upper, 2 * radius, 0.0))
        return np.c_[sx, y, sz]

    return lifted(rectangle((1.0, 1.0), divisions), to_space)


def _edge_keys(a: np.ndarray, b: np.ndarray, n: int) -> np.ndarray:
    """One integer per undirected edge {a, b} of vertex ids below n."""
    return np.minimum(a, b) * n + np.maximum(a, b)


def _wedge_partners(faces: np.ndarray, tetrahedra: np.ndarray, edges: np.ndarray, n: int) -> np.ndarray:
    """For each edge (a, b) met by more than two boundary faces, pairs (f, g) of the faces that
    bound the same wedge of solid around it: going round the edge from f through the
    tetrahedra that share a face with it, the next boundary face is g."""
    edge_keys = _edge_keys(edges[:, 0], edges[:, 1], n)
    local_edges = np.array(list(itertools.combinations(range(4), 2)))
    keys = _edge_keys(tetrahedra[:, local_edges[:, 0]], tetrahedra[:, local_edges[:, 1]], n)
    tets, slots = np.nonzero(np.isin(keys, edge_keys))
    around: dict[int, list[int]] = {}
    for tet, key in zip(tets.tolist(), keys[tets, slots].tolist()):
        around.setdefault(key, []).append(tet)
    near = np.nonzero(np.isin(faces, edges).sum(axis=1) >= 2)[0]
    face_of = {tuple(sorted(faces[f])): f for f in near.tolist()}
    pairs = []
    for (a, b), key in zip(edges.tolist(), edge_keys.tolist()):
        # Around edge ab each tetrahedron abcd joins its faces abc and abd: chains of them run
        # from one boundary face to another (the wedges), the boundary faces being those of a
        # single tetrahedron.
        neighbours: dict[int, list[int]] = {}
        for tet in tetrahedra[around[key]].tolist():
            c, d = (v for v in tet if v != a and v != b)
            neighbours.setdefault(c, []).append(d)
            neighbours.setdefault(d, []).append(c)
        seen = set()
        for start in neighbours:
            if len(neighbours[start]) != 1 or start in seen:
                continue
            previous, current = start, neighbours[start][0]
            while len(neighbours[current]) == 2:
                previous, current = current, next(v for v in neighbours[current] if v != previous)
            seen.update((start, current))
            pairs.append((face_of[tuple(sorted((a, b, start)))], face_of[tuple(sorted((a, b, current)))]))
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def _fans(faces: np.ndarray, mesh: Mesh) -> np.ndarray:
    """A label per corner of each boundary face of `mesh`, (n_faces, 3): corners of one vertex
    get one label per fan of faces around it, faces that follow each other round the vertex
    across a shared edge."""
    n = mesh.n_points
    n_faces = len(faces)

    def fans(half_edge_pairs: np.ndarray) -> np.ndarray:
        """Corner labels (corner 3 f + k: corner k of face f, labelled by the smallest corner of
        its fan): across paired half-edges (a → b in one face, b → a in the other) the corners
        at a and those at b belong to the same fans."""
        f, k = np.divmod(half_edge_pairs[:, 0], 3)
        g, m = np.divmod(half_edge_pairs[:, 1], 3)
        joined = np.concatenate([np.c_[3 * f + k, 3 * g + (m + 1) % 3], np.c_[3 * f + (k + 1) % 3, 3 * g + m]])
        labels = np.arange(3 * n_faces)
        while True:  # the smallest corner of each fan spreads through it
            lowest = np.minimum(labels[joined[:, 0]], labels[joined[:, 1]])
            updated = labels.copy()
            np.minimum.at(updated, joined[:, 0], lowest)
            np.minimum.at(updated, joined[:, 1], lowest)
            updated = updated[updated]
            if np.array_equal(updated, labels):
                return labels
            labels = updated

    # Half-edge k of face f runs from corner k to corner k + 1; an edge's faces are its owners.
    tail, head = faces, np.roll(faces, -1, axis=1)
    keys = _edge_keys(tail, head, n).ravel()
    order = np.argsort(keys, kind="stable")
    _, first, uses = np.unique(keys[order], return_index=True, return_counts=True)
    # Two faces at an edge follow each other.
    two = first[uses == 2]
    manifold_pairs = np.c_[order[two], order[two + 1]]
    touching = first[uses > 2]
    if not len(touching):
        return fans(manifold_pairs).reshape(n_faces, 3)
    # At an edge ab where the boundary touches itself (4, 6, ... faces), those that close the
    # same wedge of solid do, to begin with: pairs of half-edges, the one running from the
    # edge's lower vertex a to b first.
    half_edges = order[touching]
    edges = np.c_[tail.ravel()[half_edges], head.ravel()[half_edges]]
    at_edge: dict[tuple[int, int], list[list[int]]] = {}
    for f, g in _wedge_partners(faces, mesh.cells, edges, n).tolist():
        shared = set(faces[f]) & set(faces[g])
        k = next(k for k in range(3) if {faces[f][k], faces[f][(k + 1) % 3]} == shared)
        m = next(m for m in range(3) if {faces[g][m], faces[g][(m + 1) % 3]} == shared)
        if faces[f][k] > faces[f][(k + 1) % 3]:
            f, k, g, m = g, m, f, k
        at_edge.setdefault((int(faces[f][k]), int(faces[f][(k + 1) % 3])), []).append([3 * f + k, 3 * g + m])
    while True:
        wedge_pairs = np.array([pair for pairs in at_edge.values() for pair in pairs]).reshape(-1, 2)
        labels = fans(np.concatenate([manifold_pairs, wedge_pairs]))
        # Two pairs of an edge ab whose faces are in one fan round a and one fan round b would
        # still put four faces on one edge of the surface. That happens where the solid round
        # each of a and b is connected: the wedges meet again beyond both ends of the edge,
        # with a gap between them on either side of it (two notches whose tips touch along the
        # edge; where two of SOFA's ossicles touch). Then the two pairs trade partners, so that
        # the faces that bound the same gap follow each other. The faces round a follow each
        # other in a cycle (a permutation's), which passes the edge once per pair; trading
        # partners between two pairs of one cycle cuts it in two, as a transposition does, and
        # so round b: each of the two pairs gets its own copy of a and of b. Trades at edges
        # with no vertex in common are made at once; each splits two fans and merges none, so
        # this ends.
        done: set[int] = set()
        for (a, b), pairs in at_edge.items():
            if a in done or b in done:
                continue
            ends = [(labels[h], labels[h + 1 if h % 3 < 2 else h - 2]) for h, _ in pairs]
            clash = next(((i, j) for i in range(len(pairs)) for j in range(i) if ends[i] == ends[j]), None)
            if clash is not None:
                i, j = clash
                pairs[i][1], pairs[j][1] = pairs[j][1], pairs[i][1]
                done.update((a, b))
        if not done:
            return labels.reshape(n_faces, 3)


def boundary_surface(mesh: Mesh) -> tuple[Mesh, np.ndarray]:
    """The boundary of a tetrahedral mesh as a surface mesh (triangles in 3D, outward
    normals), with the volume mesh's id of each surface vertex: ``(surface, vertex_ids)``.

    Where the boundary touches itself — two bones that meet along an edge or at a vertex — the
    surface is split into manifold surfaces: such a vertex becomes one surface vertex per fan of
    boundary triangles around it (along an edge, the two triangles that close the same wedge of
    solid follow each other; where the wedges meet again beyond both ends of the edge, so that
    this would leave four triangles on one edge, the two that bound the same gap between them
    do), so that every edge is shared by exactly two triangles and a membrane can be built on
    it. Each copy sits where its vertex is, and ``vertex_ids`` maps
    every copy to that same volume vertex. Surface vertices are numbered in ascending order of
    their volume vertex; the extra copies come after them."""
    if mesh.cell_dim != 3:
        raise ValueError(f"boundary_surface needs a tetrahedral mesh, got cell_dim {mesh.cell_dim}")
    faces = mesh.boundary_faces()
    fans = _fans(faces, mesh)
    fan_ids, fan_of_corner = np.unique(fans, return_inverse=True)
    fan_vertex = faces.ravel()[fan_ids]
    # The first fan of each vertex (by lowest corner) keeps the vertex's place in ascending
    # order; further fans of a vertex are appended.
    vertex_ids, first_fan = np.unique(fan_vertex, return_index=True)
    extra = np.setdiff1d(np.arange(len(fan_ids)), first_fan)
    numbering = np.empty(len(fan_ids), dtype=np.int64)
    numbering[first_fan] = np.arange(len(first_fan))
    numbering[extra] = len(first_fan) + np.arange(len(extra))
    vertex_ids = np.concatenate([vertex_ids, fan_vertex[extra]])
    triangles = numbering[fan_of_corner].reshape(faces.shape)
    return Mesh(mesh.points[vertex_ids], triangles), vertex_ids
