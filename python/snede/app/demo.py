"""`make demo`: the built-in scenes (cantilever, cylinder, slab, needle, needle3d, cut, sheet-cut) with their table, files
and pictures, then a box cut in two through the §7 connectivity layer."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import snede

MESHES = Path(__file__).resolve().parents[3] / "meshes"


def _quality_line(name: str, mesh: snede.Mesh) -> str:
    q = mesh.quality()
    edges = _edge_lengths(mesh)
    return (f"{name:<22} {mesh.n_cells:>8} {mesh.n_points:>7} {q.volume.sum():>10.6f} "
            f"{edges.min():>8.4f} {edges.max():>8.4f} {np.degrees(q.min_dihedral.min()):>8.1f} "
            f"{np.degrees(q.max_dihedral.max()):>8.1f} {q.aspect_ratio.min():>7.3f}")


def _edge_lengths(mesh: snede.Mesh) -> np.ndarray:
    cells, points = mesh.cells, mesh.points
    pairs = [(i, j) for i in range(cells.shape[1]) for j in range(i + 1, cells.shape[1])]
    return np.concatenate([np.linalg.norm(points[cells[:, i]] - points[cells[:, j]], axis=1) for i, j in pairs])


def _write_pieces(mesh: snede.Mesh, path: Path, gap: float) -> None:
    """Write the mesh with its connected components pulled apart by `gap` along x, so the cut
    is visible; cell data: component, aspect ratio."""
    import meshio

    n_components, label = mesh.connected_components()
    points = mesh.points.copy()
    cells = mesh.cells
    for component in range(n_components):
        vertices = np.unique(cells[label == component])
        points[vertices, 0] += gap * component
    path.parent.mkdir(parents=True, exist_ok=True)
    meshio.Mesh(points, [("tetra", cells)],
                cell_data={"component": [label], "aspect_ratio": [mesh.quality().aspect_ratio]}).write(str(path))


def run(out: Path = Path("out"), progress: bool = True) -> int:
    from snede.app import run_scene
    from snede.app.scenes import Parameters, builders

    print(f"snede {snede.__version__} on PETSc {'.'.join(map(str, snede.PETSc.Sys.getVersion()))}\n")
    summaries = [run_scene.run(module.build(Parameters()), None, None, out, progress) for module in builders().values()]
    run_scene.print_table(summaries)
    print()
    cut_box(20, Path(out) / "cut")
    return 0 if all(s["converged"] for s in summaries) else 1


def cut_box(divisions: int, out: Path) -> None:
    print(f"{'mesh':<22} {'cells':>8} {'points':>7} {'volume':>10} {'min edge':>8} {'max edge':>8} "
          f"{'min dih°':>8} {'max dih°':>8} {'min AR':>7}")
    start = time.perf_counter()
    box = snede.meshing.box((1.0, 1.0, 1.0), (divisions,) * 3)
    build_seconds = time.perf_counter() - start
    box.validate()
    print(_quality_line(f"box {divisions}^3 (Kuhn)", box))
    for name in ("cylinder_small.msh", "cylinder_large.msh"):
        if (MESHES / name).exists():
            cylinder = snede.Mesh.read(MESHES / name)
            cylinder.validate()
            print(_quality_line(name, cylinder))

    # Cut the box through the plane x = 1/2 (§7.3 dissect): every interior face on the plane.
    half = divisions // 2 / divisions
    faces = box.faces_where(lambda x: np.isclose(x[:, 0], half))
    boundary_before = len(box.boundary_faces())
    start = time.perf_counter()
    split = box.dissect(faces)
    cut_seconds = time.perf_counter() - start
    box.validate()
    n_components, _ = box.connected_components()
    print(f"\ncut through x = {half:g}: {len(faces)} face pairs, {len(split)} vertices duplicated, "
          f"boundary faces {boundary_before} -> {len(box.boundary_faces())}, "
          f"connected components: {n_components}, volume {box.quality().volume.sum():.6f}")
    print(f"box of {box.n_cells} tetrahedra built in {build_seconds * 1e3:.0f} ms, cut in {cut_seconds * 1e3:.0f} ms; "
          f"validate() passed before and after the cut")
    path = out / "box_cut.vtu"
    _write_pieces(box, path, gap=0.1)
    print(f"wrote {path} (open it in ParaView; colour by 'component')")
    return 0
