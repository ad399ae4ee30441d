"""snede.distribute on 1, 2 and 3 ranks (tools/run_tests.sh runs this file under pytest and
under `mpirun -n 2` and `-n 3`; every rank runs every test, and the checks gather what all
ranks hold). The parts are compared with the serial mesh they came from: together their cells
are its cells, each once; every vertex is owned by exactly one rank and has its serial
coordinates; each part is a valid, positively oriented mesh; a rank may get no cells; a
problem with rank 0's input raises the same error on every rank instead of hanging."""
import numpy as np
import pytest
from mpi4py import MPI

import snede

COMM = MPI.COMM_WORLD


def serial_meshes():
    return {"box": snede.meshing.box((1.0, 2.0, 1.0), (3, 4, 2)), "rectangle": snede.meshing.rectangle((2.0, 1.0), (8, 5))}


def signed_volumes(mesh):
    p = mesh.points[mesh.cells]
    edges = p[:, 1:] - p[:, :1]
    return np.linalg.det(edges) if mesh.dim == 3 else np.cross(edges[:, 0], edges[:, 1])


@pytest.mark.parametrize("name", ["box", "rectangle"])
def test_parts_hold_every_cell_once_and_every_vertex_owned_once(name):
    serial = serial_meshes()[name]
    part = snede.distribute(serial if COMM.rank == 0 else None)
    local = part.local
    assert part.n_global_vertices == len(serial.points) and part.n_global_cells == serial.n_cells
    # Cells, in serial vertex ids, gathered from every rank.
    cells = part.global_vertex[local.cells] if local.n_cells else np.zeros((0, serial.dim + 1), dtype=np.int64)
    everyone = COMM.allgather([tuple(sorted(c)) for c in cells.tolist()])
    gathered = [c for rank_cells in everyone for c in rank_cells]
    assert len(gathered) == serial.n_cells  # no cell twice
    assert set(gathered) == {tuple(sorted(c)) for c in serial.cells.tolist()}
    owners = np.concatenate(COMM.allgather(part.global_vertex[part.owned]))
    np.testing.assert_array_equal(np.sort(owners), np.arange(len(serial.points)))
    # Every local vertex sits where the serial mesh has it; ghosts are owned elsewhere.
    np.testing.assert_array_equal(local.points, serial.points[part.global_vertex])
    if COMM.size == 1:
        assert part.owned.all()


@pytest.mark.parametrize("name", ["box", "rectangle"])
def test_each_part_is_a_valid_positively_oriented_mesh(name):
    serial = serial_meshes()[name]
    part = snede.distribute(serial if COMM.rank == 0 else None)
    if part.local.n_cells:
        part.local.validate()
        assert signed_volumes(part.local).min() > 0
    counts = COMM.allgather(part.local.n_cells)
    if COMM.size > 1:
        assert min(counts) > 0  # PETSc's partitioner gives every rank some of 48 or 80 cells


def test_the_same_mesh_is_split_the_same_way_every_time():
    """PT-Scotch runs on one thread (its threads made the parts differ from call to call, and
    with them the iteration counts of partition-dependent preconditioners)."""
    mesh = snede.meshing.box((4.0, 1.0, 1.0), (16, 4, 4)) if COMM.rank == 0 else None
    parts = [snede.distribute(mesh) for _ in range(3)]
    for part in parts[1:]:
        assert np.array_equal(part.global_vertex, parts[0].global_vertex)
        assert np.array_equal(part.owned, parts[0].owned)


def test_a_rank_may_get_no_cells():
    """One triangle on every rank count: the ranks beyond the first hold nothing."""
    serial = snede.Mesh([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], [[0, 1, 2]])
    part = snede.distribute(serial if COMM.rank == 0 else None)
    counts = COMM.allgather(part.local.n_cells)
    assert sum(counts) == 1 and counts.count(1) == 1
    assert sum(COMM.allgather(int(part.owned.sum()))) == 3


def test_a_problem_on_rank_0_raises_the_same_error_everywhere():
    serial = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    with pytest.raises(ValueError, match="rank 0 must pass the serial mesh") as raised:
        snede.distribute(None if COMM.rank == 0 else serial)
    messages = COMM.allgather(str(raised.value))
    assert len(set(messages)) == 1
    # The communicator is still usable: nothing is left waiting.
    assert COMM.allreduce(1) == COMM.size


def test_topology_changes_on_a_part_are_refused_naming_the_operation():
    """Cuts, bisection, needle insertion and the local edits are serial for now: on a part
    each raises NotImplementedError naming the operation, on every rank (no rank waits), and
    leaves the part as it was; a serial copy of the part can still be edited."""
    serial = snede.meshing.box((2.0, 1.0, 1.0), (4, 2, 2))
    part = snede.distribute(serial if COMM.rank == 0 else None)
    mesh = part.local
    cells_before = mesh.cells.copy()
    body = snede.Body(mesh, snede.LinearElastic(1e5, 0.3))
    friction = snede.FrictionProfile([0.0, 1.0], [1.0, 1.0])
    attempts = {
        "refine_uniform": lambda: mesh.refine_uniform(),
        "refine_around": lambda: mesh.refine_around([0.5, 0.5, 0.5], 0.1),
        "split_edge": lambda: mesh.split_edge(0, 1),
        "dissect": lambda: mesh.dissect(np.zeros((0, 3), dtype=np.int64)),
        "add_vertex": lambda: mesh.add_vertex([0], [1.0]),
        "TetrahedralCutter": lambda: snede.TetrahedralCutter(body),
        "NeedleInsertion": lambda: snede.NeedleInsertion(body, [1.0, 0.5, 1.2], [0.0, 0.0, -1.0], friction),
    }
    for operation, attempt in attempts.items():
        with pytest.raises(NotImplementedError, match=rf"{operation} on rank {COMM.rank}'s part of a mesh distributed"):
            attempt()
    np.testing.assert_array_equal(mesh.cells, cells_before)
    assert COMM.allreduce(1) == COMM.size
    copy = snede.Mesh(mesh.points, mesh.cells)
    if copy.n_cells:
        assert copy.refine_uniform() > 0
