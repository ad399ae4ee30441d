"""A serial mesh's named groups on its parts (issue 52, item 2): on 1, 2 and 3 ranks, the parts
of a gmsh file read by ``DistributedMesh.read`` (rank 0 reads it whole and distributes it) carry
its physical groups. Together the ranks hold each group's cells and faces once, faces oriented
as serially, and a PartBody held and loaded by group names solves as the serial Body given the
same names."""
import shutil
import tempfile
from pathlib import Path

import numpy as np
from mpi4py import MPI

import snede

COMM = MPI.COMM_WORLD
CYLINDER = Path(__file__).parents[2] / "meshes" / "cylinder_large.msh"  # gmsh's, 8 724 tetrahedra


def groups_of(mesh):
    """The cylinder's groups: its end at x = 0 ("held"), the upper faces around the middle
    ("top"), the cells with centroid below the axis ("lower") and the whole ("tissue")."""
    points, faces = mesh.points, mesh.boundary_faces()
    x, z = points[:, 0], points[:, 2]
    far, top = x.max(), z.max()
    held = faces[np.all(x[faces] <= 1e-9, axis=1)]
    upper = faces[np.all(z[faces] > 0.5 * top, axis=1) & np.all(np.abs(x[faces] - 0.5 * far) < 0.25 * far, axis=1)]
    lower = np.flatnonzero(points[mesh.cells][:, :, 2].mean(axis=1) < 0.5 * (z.min() + top))
    return {"held": held, "top": upper}, {"tissue": np.arange(mesh.n_cells), "lower": lower}


def write_gmsh(path: Path, mesh) -> None:
    """``mesh`` with groups_of's groups as gmsh physical groups, format 2.2."""
    faces, cells = groups_of(mesh)
    names = list(faces) + list(cells)
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names))]
    lines += [f"{2 if name in faces else 3} {tag} \"{name}\"" for tag, name in enumerate(names, 1)]
    lines += ["$EndPhysicalNames", "$Nodes", str(len(mesh.points))]
    lines += [f"{k + 1} {x:.17g} {y:.17g} {z:.17g}" for k, (x, y, z) in enumerate(mesh.points.tolist())]
    elements = [(2, names.index(name) + 1, face) for name, members in faces.items() for face in members.tolist()]
    lower = set(cells["lower"].tolist())
    for row, cell in enumerate(mesh.cells.tolist()):  # one element per group it is in
        elements.append((4, names.index("tissue") + 1, cell))
        if row in lower:
            elements.append((4, names.index("lower") + 1, cell))
    lines += ["$EndNodes", "$Elements", str(len(elements))]
    lines += [f"{k + 1} {kind} 2 {tag} {tag} " + " ".join(str(v + 1) for v in vertices)
              for k, (kind, tag, vertices) in enumerate(elements)]
    lines.append("$EndElements")
    path.write_text("\n".join(lines) + "\n")


def read_on_ranks():
    """The cylinder with its groups written by rank 0, read back whole on rank 0 (the serial
    mesh) and on the ranks (the part)."""
    folder = COMM.bcast(tempfile.mkdtemp() if COMM.rank == 0 else None, root=0)
    path = Path(folder) / "cylinder_groups.msh"
    if COMM.rank == 0:
        write_gmsh(path, snede.Mesh.read(CYLINDER))
    COMM.Barrier()
    serial = snede.Mesh.read(path)
    part = snede.DistributedMesh.read(path, COMM)
    COMM.Barrier()  # every rank has read it
    if COMM.rank == 0:
        shutil.rmtree(folder)
    return serial, part


def oriented(faces: np.ndarray) -> set:
    """Each face as a tuple rotated to start at its smallest id (orientation kept)."""
    return {tuple(np.roll(face, -int(np.argmin(face)))) for face in faces.tolist()}


def test_the_ranks_hold_each_group_member_once():
    serial, part = read_on_ranks()
    assert set(serial.boundary_groups) - {"incision"} == {"held", "top"}
    assert set(serial.cell_groups) == {"tissue", "lower"}
    local = part.local
    assert set(COMM.allgather(tuple(sorted(local.boundary_groups)))) == {tuple(sorted(serial.boundary_groups))}
    assert set(COMM.allgather(tuple(sorted(local.cell_groups)))) == {tuple(sorted(serial.cell_groups))}
    for name, faces in serial.boundary_groups.items():
        mine = part.global_vertex[local.boundary_groups[name]]
        gathered = [face for faces_of_rank in COMM.allgather(mine.tolist()) for face in faces_of_rank]
        assert len(gathered) == len(faces), name  # none twice, none missing
        assert oriented(np.array(gathered, dtype=np.int64).reshape(-1, serial.cell_dim)) == oriented(faces), name
    for name, rows in serial.cell_groups.items():
        mine = np.sort(part.global_vertex[local.cells[local.cell_groups[name]]], axis=1)
        gathered = {tuple(cell) for cells_of_rank in COMM.allgather(mine.tolist()) for cell in cells_of_rank}
        assert COMM.allreduce(len(mine)) == len(rows) == len(gathered), name
        assert gathered == {tuple(cell) for cell in np.sort(serial.cells[rows], axis=1).tolist()}, name


def test_a_part_body_held_and_loaded_by_group_names_solves_as_serially():
    """Held by "held", pressed on "top" and pulled down on "lower"'s vertices: the displacement
    on every rank is the serial Body's at its vertices (both to rtol 1e-10)."""
    serial_mesh, part = read_on_ranks()
    displacements = []
    for mesh in (serial_mesh, part):
        body = snede.Body(mesh, snede.LinearElastic(3e4, 0.3))
        body.fix("held")
        body.add_traction("top", (0.0, 0.0, -40.0))
        body.add_nodal_force("lower", (0.0, 0.0, -1e-3))
        result = snede.StaticSolver(body, "cg", rtol=1e-10).solve()
        assert result.converged, result
        displacements.append(body.displacement)
    serial, mine = displacements
    scale = np.abs(serial).max()
    assert scale > 0
    assert np.abs(mine - serial[part.global_vertex]).max() <= 1e-6 * scale
