"""One XDMF + HDF5 series written by all ranks together (issue 18): ``SeriesWriter(base, comm)``
and ``write_part`` on 1, 2 and 3 ranks (see test_distribute.py for how they run). Rank 0 reads
the series back with ``read_series`` and finds the serial mesh (through the ``serial_vertex``
point field), the displacement u = t (A x + b) at every point, cell fields on the cells they were
given for, and both steps pointing to one mesh. Bad input raises the same ValueError on every
rank, and the writer stays usable."""
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

import snede
from snede.output import SeriesWriter, read_series

COMM = MPI.COMM_WORLD
several = pytest.mark.skipif(COMM.size == 1, reason="needs several ranks")


def serial_meshes():
    return {"box": snede.meshing.box((1.0, 2.0, 1.0), (3, 4, 2)), "rectangle": snede.meshing.rectangle((2.0, 1.0), (8, 5))}


def shared_folder(tmp_path_factory) -> Path:
    """A folder every rank names alike (each rank's pytest has its own tmp_path)."""
    return Path(COMM.bcast(str(tmp_path_factory.mktemp("series")) if COMM.rank == 0 else None))


def displacement(points, time):
    """u = t (A x + b), a known function of the serial coordinates."""
    dim = points.shape[1]
    A = np.arange(1.0, dim * dim + 1).reshape(dim, dim) / 10.0
    b = np.linspace(-0.5, 0.5, dim)
    return time * (points @ A.T + b)


def write_two_steps(writer, part):
    """Steps at t = 0.5 and 1: the displacement, the point field ``height`` (last coordinate)
    and the cell fields ``lowest`` (smallest serial id of the cell's corners) and ``rank``."""
    local = part.local
    lowest = part.global_vertex[local.cells].min(axis=1) if local.n_cells else np.zeros(0)
    for time in (0.5, 1.0):
        writer.write_part(part, time, displacement(local.points, time), point_fields={"height": local.points[:, -1]},
                          lowest=lowest, rank=np.full(local.n_cells, float(COMM.rank)))


def check_series(path, serial):
    """What rank 0 reads back is the serial mesh with the fields write_two_steps wrote."""
    steps = read_series(path)
    assert [step.time for step in steps] == [0.5, 1.0]
    mesh = steps[0].mesh
    assert steps[1].mesh is mesh  # one mesh, written once
    ids = steps[0].point_fields["serial_vertex"].astype(np.int64)
    np.testing.assert_array_equal(np.sort(ids), np.arange(len(serial.points)))
    assert mesh.dim == serial.dim
    np.testing.assert_array_equal(mesh.points, serial.points[ids])
    cells = [tuple(sorted(c)) for c in ids[mesh.cells].tolist()]
    assert len(cells) == serial.n_cells and set(cells) == {tuple(sorted(c)) for c in serial.cells.tolist()}
    quality = mesh.quality()
    for step in steps:
        assert set(step.point_fields) == {"displacement", "height", "serial_vertex"}
        assert set(step.cell_fields) == {"aspect_ratio", "min_angle", "lowest", "rank"}
        np.testing.assert_allclose(step.displacement, displacement(serial.points[ids], step.time), rtol=1e-14, atol=1e-15)
        np.testing.assert_array_equal(step.point_fields["height"], serial.points[ids, -1])
        np.testing.assert_array_equal(step.cell_fields["lowest"], ids[mesh.cells].min(axis=1))
        np.testing.assert_allclose(step.cell_fields["aspect_ratio"], quality.aspect_ratio, rtol=1e-12)
        np.testing.assert_allclose(step.cell_fields["min_angle"], quality.min_dihedral, rtol=1e-12)
    return steps


@pytest.mark.parametrize("name", ["box", "rectangle"])
def test_the_ranks_write_one_series_of_the_serial_mesh(name, tmp_path_factory):
    serial = serial_meshes()[name]
    part = snede.distribute(serial if COMM.rank == 0 else None)
    writer = SeriesWriter(shared_folder(tmp_path_factory) / "made" / "by rank 0" / name, COMM)
    write_two_steps(writer, part)
    assert (writer.n_steps, writer.n_meshes) == (2, 1)
    COMM.Barrier()
    if COMM.rank == 0:
        steps = check_series(writer.xdmf_path, serial)
        # Each rank's cells are one block of rows, in rank order.
        ranks = steps[0].cell_fields["rank"]
        np.testing.assert_array_equal(ranks, np.sort(ranks))
        assert set(ranks) == set(range(COMM.size))
    COMM.Barrier()


def test_ranks_without_cells_take_part(tmp_path_factory):
    """One triangle: on 2 and 3 ranks all but one rank have nothing to write."""
    serial = snede.Mesh([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], [[0, 1, 2]])
    part = snede.distribute(serial if COMM.rank == 0 else None)
    writer = SeriesWriter(shared_folder(tmp_path_factory) / "triangle", COMM)
    write_two_steps(writer, part)
    COMM.Barrier()
    if COMM.rank == 0:
        check_series(writer.xdmf_path, serial)
    COMM.Barrier()


def test_a_part_of_one_rank_in_a_serial_writer(tmp_path_factory):
    """A part distributed over COMM_SELF, written by a writer without a communicator: each rank
    writes a series of the whole mesh on its own."""
    serial = serial_meshes()["box"]
    part = snede.distribute(serial, MPI.COMM_SELF)
    writer = SeriesWriter(shared_folder(tmp_path_factory) / f"rank {COMM.rank}" / "box")
    write_two_steps(writer, part)
    check_series(writer.xdmf_path, serial)


def wrong_on_the_last_rank(part, kind):
    """write_part's arguments, with one wrong on the last rank only."""
    local = part.local
    wrong = COMM.rank == COMM.size - 1
    u = np.zeros((local.n_points + (kind == "displacement" and wrong), local.dim))
    cell_fields = {"label": np.zeros(local.n_cells + (kind == "cell field" and wrong))}
    point_fields = {"height": np.zeros(local.n_points + (kind == "point field" and wrong))}
    if kind == "not numbers" and wrong:
        cell_fields["label"] = ["soft"] * local.n_cells  # numpy cannot make floats of it
    return u, point_fields, cell_fields


@pytest.mark.parametrize("kind, message", [("displacement", "displacement has"),
                                           ("cell field", "cell field 'label' has"),
                                           ("point field", "point field 'height' has"),
                                           ("not numbers", "could not convert string to float")])
def test_bad_input_on_one_rank_raises_the_same_error_on_every_rank(kind, message, tmp_path_factory):
    serial = serial_meshes()["box"]
    part = snede.distribute(serial if COMM.rank == 0 else None)
    writer = SeriesWriter(shared_folder(tmp_path_factory) / "bad", COMM)
    u, point_fields, cell_fields = wrong_on_the_last_rank(part, kind)
    with pytest.raises(ValueError, match=message) as raised:
        writer.write_part(part, 0.0, u, point_fields=point_fields, **cell_fields)
    assert len(set(COMM.allgather(str(raised.value)))) == 1
    if COMM.size > 1:
        assert str(raised.value).startswith(f"rank {COMM.size - 1}: ")
    assert writer.n_steps == 0
    # Nothing was left half done: the writer goes on with good input.
    write_two_steps(writer, part)
    COMM.Barrier()
    if COMM.rank == 0:
        check_series(writer.xdmf_path, serial)
    COMM.Barrier()


@several
def test_different_field_names_on_the_ranks_are_refused_everywhere(tmp_path_factory):
    part = snede.distribute(serial_meshes()["rectangle"] if COMM.rank == 0 else None)
    writer = SeriesWriter(shared_folder(tmp_path_factory) / "names", COMM)
    name = "first" if COMM.rank == 0 else "other"
    with pytest.raises(ValueError, match=r"the fields differ from rank 0's") as raised:
        writer.write_part(part, 0.0, **{name: np.zeros(part.local.n_cells)})
    assert len(set(COMM.allgather(str(raised.value)))) == 1
    assert COMM.allreduce(1) == COMM.size


@several
def test_a_shared_writer_refuses_a_serial_mesh_and_a_serial_writer_a_distributed_part(tmp_path_factory):
    folder = shared_folder(tmp_path_factory)
    serial = serial_meshes()["rectangle"]
    shared = SeriesWriter(folder / "shared", COMM)
    with pytest.raises(ValueError, match=f"shared by {COMM.size} ranks"):
        shared.write_mesh(serial)
    part = snede.distribute(serial if COMM.rank == 0 else None)
    alone = SeriesWriter(folder / f"alone {COMM.rank}")
    with pytest.raises(ValueError, match="distributed over other ranks than the writer's"):
        alone.write_part(part)
    assert COMM.allreduce(1) == COMM.size


def test_a_folder_rank_0_cannot_make_is_an_error_on_every_rank(tmp_path_factory):
    folder = shared_folder(tmp_path_factory)
    if COMM.rank == 0:
        (folder / "a file").write_text("not a folder")
    COMM.Barrier()
    with pytest.raises(OSError):
        SeriesWriter(folder / "a file" / "series", COMM)
    assert COMM.allreduce(1) == COMM.size
