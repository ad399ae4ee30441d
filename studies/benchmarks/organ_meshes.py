"""Organ-like tetrahedral meshes for benchmarks: gmsh fills public anatomical surfaces.

    .venv/bin/python studies/benchmarks/organ_meshes.py [--refresh]

``organ_mesh(name, target_tets, seed=1)`` returns a ``snede.Mesh`` of about ``target_tets``
tetrahedra (within ±10 % when gmsh allows, always within ±30 %) filling the closed surface
``name`` of ``ORGANS`` ("liver", "liver2", "heart"). The surfaces are SOFA's two liver models and
its heart (``meshes/README.md`` gives their source and licence), the livers turned so that z points
up (cranially), and all scaled so that the organ is 0.2 m wide (largest bounding-box side; a
liver's width, too large for a heart), centred at the origin. Results are cached in
``out/organ_meshes/`` keyed by name, target, seed and a hash of the surface, this file and
gmsh's version, so a second call only reads an ``.npz``. Run as a script, it prints size and
quality of every organ at 20000 and 60000 tetrahedra (``--refresh`` regenerates them).
"""
from __future__ import annotations

import argparse
import hashlib
import math
import sys
import time
from pathlib import Path

import numpy as np

import snede

ROOT = Path(__file__).resolve().parents[2]
CACHE = ROOT / "out" / "organ_meshes"
WIDTH = 0.2  #: largest bounding-box side (m): an adult liver is about 0.2 m across

# name -> (surface file in meshes/, rotation taking the file's axes to ours).
# SOFA's liver scenes use gravity -y, so liver_surface.obj has y up; rotate it about x so that
# y becomes z. liver2_surface.obj is already z up (its frontal x-z outline is the liver's).
_SURFACES = {
    "liver": ("liver_surface.obj", np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])),
    "liver2": ("liver2_surface.obj", np.eye(3)),
    # SOFA's heart (coeur1.trian) has no documented orientation and no obvious long axis: as is.
    "heart": ("heart_surface.obj", np.eye(3)),
}
ORGANS = tuple(_SURFACES)

# gmsh's Delaunay mesh has fewer tetrahedra than volume / (volume of a regular tetrahedron of
# edge h): about 0.6-0.8 of it here (more at coarse h, where the surface layer dominates).
_FILL = 0.7


def _crossing_pairs(points, tris):
    """Pairs (i, j) of triangles that share no vertex and where an edge of one crosses the other
    (touching and coplanar overlaps are not detected). Vectorised: a few 0.1 s for 5000 triangles."""
    corners = points[tris]
    lo, hi = corners.min(1), corners.max(1)
    first, second = [], []
    for start in range(0, len(tris), 256):  # chunks keep the all-pairs box test small in memory
        rows = np.arange(start, min(start + 256, len(tris)))
        i, j = np.nonzero(np.all((lo[rows, None] <= hi[None]) & (lo[None] <= hi[rows, None]), axis=2))
        i = rows[i]
        first.append(i[i < j])
        second.append(j[i < j])
    i, j = np.concatenate(first), np.concatenate(second)
    apart = ~(tris[i][:, :, None] == tris[j][:, None, :]).any(axis=(1, 2))
    i, j = i[apart], j[apart]

    def edge_crosses(a, b):  # does an edge of triangles a (m, 3, 3) cross triangles b?
        normal = np.cross(b[:, 1] - b[:, 0], b[:, 2] - b[:, 0])
        height = np.einsum("mkd,md->mk", a - b[:, None, 0], normal)
        hit = np.zeros(len(a), dtype=bool)
        for k in range(3):
            hp, hq = height[:, k], height[:, (k + 1) % 3]
            with np.errstate(divide="ignore", invalid="ignore"):
                x = a[:, k] + (a[:, (k + 1) % 3] - a[:, k]) * (hp / (hp - hq))[:, None]
            side = np.stack([np.einsum("md,md->m", np.cross(b[:, (e + 1) % 3] - b[:, e], x - b[:, e]), normal)
                             for e in range(3)], axis=1)
            hit |= (hp * hq < 0) & (np.all(side > 0, axis=1) | np.all(side < 0, axis=1))
        return hit

    cross = edge_crosses(corners[i], corners[j]) | edge_crosses(corners[j], corners[i])
    return i[cross], j[cross]


def _surface(name):
    """The organ's closed surface (points in metres, triangles), repaired if it crosses itself."""
    import meshio

    file, rotation = _SURFACES[name]
    surface = meshio.read(ROOT / "meshes" / file)
    points = surface.points[:, :3].astype(np.float64) @ rotation.T
    tris = surface.cells_dict["triangle"].astype(np.int64)
    points = (points - (points.max(0) + points.min(0)) / 2) * (WIDTH / np.ptp(points, axis=0).max())
    # liver_surface.obj crosses itself in a fold (5 triangle pairs), which gmsh refuses
    # ("PLC Error: Two facets intersect"). Fix it locally: move the vertices of the crossing
    # triangles and their neighbours to their neighbours' mean (3 umbrella passes).
    neighbours = [set() for _ in points]
    for a, b, c in tris:
        neighbours[a] |= {b, c}
        neighbours[b] |= {a, c}
        neighbours[c] |= {a, b}
    for _ in range(5):
        i, j = _crossing_pairs(points, tris)
        if len(i) == 0:
            return points, tris
        ring = set(np.unique(tris[np.r_[i, j]]).tolist())
        ring = sorted(ring.union(*(neighbours[v] for v in ring)))
        for _ in range(3):
            points[ring] = [points[sorted(neighbours[v])].mean(0) for v in ring]
    raise RuntimeError(f"surface {name} still crosses itself after smoothing")


def _tetrahedralise(points, tris, h, seed):
    """gmsh: remesh the surface at edge length h, then Delaunay-fill it. (points, cells)."""
    import gmsh

    gmsh.initialize(readConfigFiles=False, interruptible=False)  # see snede.meshing.cylinder
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)  # deterministic, and modest on CPU
        gmsh.model.add("organ")
        surface = gmsh.model.addDiscreteEntity(2)
        gmsh.model.mesh.addNodes(2, surface, np.arange(1, len(points) + 1), points.ravel())
        gmsh.model.mesh.addElementsByType(surface, 2, [], (tris + 1).ravel())
        # Split the surface into patches gmsh can parametrise and remesh at h, so the boundary
        # resolution follows the target instead of the source's triangles. 40°: with 60° the
        # remeshed fold of the liver crossed itself at some h.
        gmsh.model.mesh.classifySurfaces(math.radians(40), True, True, math.pi)
        gmsh.model.mesh.createGeometry()
        loop = gmsh.model.geo.addSurfaceLoop([tag for _, tag in gmsh.model.getEntities(2)])
        gmsh.model.geo.addVolume([loop])
        gmsh.model.geo.synchronize()
        # Netgen's optimiser after gmsh's: on the liver it lifts the median aspect ratio from 0.45
        # to 0.51 and the smallest dihedral angle from 5° to 9°, for 2-3 times the meshing time.
        for option, value in (("Mesh.MeshSizeMin", h), ("Mesh.MeshSizeMax", h), ("Mesh.Algorithm3D", 1),
                              ("Mesh.Optimize", 1), ("Mesh.OptimizeNetgen", 1), ("Mesh.RandomSeed", seed)):
            gmsh.option.setNumber(option, value)
        gmsh.model.mesh.generate(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        kinds, _, nodes = gmsh.model.mesh.getElements(3)
    finally:
        gmsh.finalize()
    index_of_tag = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    index_of_tag[tags.astype(np.int64)] = np.arange(len(tags))
    cells = index_of_tag[np.concatenate([n for k, n in zip(kinds, nodes) if k == 4]).astype(np.int64)]
    used, cells = np.unique(cells, return_inverse=True)  # drop nodes in no tetrahedron
    return coords.reshape(-1, 3)[used], cells.reshape(-1, 4)


def _generate(name, target_tets, seed):
    points, tris = _surface(name)
    volume = np.einsum("ij,ij->i", points[tris[:, 0]], np.cross(points[tris[:, 1]], points[tris[:, 2]])).sum() / 6
    # n ≈ _FILL · volume / (h³ / (6√2)), solved for h; then correct h from the count obtained
    # (at most twice: gmsh's count is not monotone in h) until within 10 %.
    h = (_FILL * abs(volume) * 6 * math.sqrt(2) / target_tets) ** (1 / 3)
    best = None
    for _ in range(3):
        mesh_points, cells = _tetrahedralise(points, tris, h, seed)
        if best is None or abs(len(cells) / target_tets - 1) < abs(len(best[1]) / target_tets - 1):
            best = mesh_points, cells, h
        if abs(len(cells) / target_tets - 1) <= 0.1:
            break
        h *= (len(cells) / target_tets) ** (1 / 3)
    if abs(len(best[1]) / target_tets - 1) > 0.3:
        raise RuntimeError(f"{name}: {len(best[1])} tetrahedra, more than 30 % from {target_tets}")
    return best


def _cached(name, target_tets, seed, refresh=False):
    """The cached .npz (points, cells, h, seconds of generation), made first if missing."""
    if name not in _SURFACES:
        raise ValueError(f"unknown organ {name!r}; available: {', '.join(ORGANS)}")
    import gmsh

    # The key hashes the surface, this file and gmsh's version: a change to any of them remakes it.
    source = (ROOT / "meshes" / _SURFACES[name][0]).read_bytes() + Path(__file__).read_bytes()
    digest = hashlib.sha1(source + gmsh.__version__.encode()).hexdigest()[:10]
    path = CACHE / f"{name}-{int(target_tets)}-seed{int(seed)}-{digest}.npz"
    if refresh or not path.exists():
        start = time.perf_counter()
        points, cells, h = _generate(name, int(target_tets), int(seed))
        CACHE.mkdir(parents=True, exist_ok=True)
        np.savez(path, points=points, cells=cells, h=h, seconds=time.perf_counter() - start)
    with np.load(path) as data:
        return dict(data)


def organ_mesh(name: str, target_tets: int, seed: int = 1, refresh: bool = False) -> snede.Mesh:
    """About ``target_tets`` tetrahedra filling organ ``name`` (one of ``ORGANS``), in metres.
    Deterministic for given arguments; cached in out/organ_meshes/ (``refresh`` regenerates)."""
    data = _cached(name, target_tets, seed, refresh)
    return snede.Mesh(data["points"], data["cells"])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--refresh", action="store_true", help="regenerate instead of reading the cache")
    args = parser.parse_args()
    print(f"{'organ':8} {'target':>7} {'tets':>7} {'points':>7} {'h (m)':>7} {'bbox (m)':>20} "
          f"{'AR min':>7} {'AR med':>7} {'dihed min':>9} {'gen s':>6} {'comp':>4}")
    for name in ORGANS:
        for target in (20000, 60000):
            data = _cached(name, target, 1, args.refresh)
            mesh = snede.Mesh(data["points"], data["cells"])
            mesh.validate()  # raises on broken connectivity or an inverted cell
            components, _ = mesh.connected_components()
            assert components == 1 and mesh.n_reoriented == 0, (components, mesh.n_reoriented)
            quality = mesh.quality()
            box = np.ptp(mesh.points, axis=0)
            print(f"{name:8} {target:7d} {mesh.n_cells:7d} {mesh.n_points:7d} {float(data['h']):7.4f} "
                  f"{' × '.join(f'{s:.3f}' for s in box):>20} {quality.aspect_ratio.min():7.3f} "
                  f"{np.median(quality.aspect_ratio):7.3f} {math.degrees(quality.min_dihedral.min()):8.1f}° "
                  f"{float(data['seconds']):6.1f} {components:4d}")


if __name__ == "__main__":
    sys.exit(main())
