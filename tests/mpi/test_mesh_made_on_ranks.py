"""A mesh that no rank holds whole (issue 52, item 2, first part), on 1, 2 and 3 ranks:
``snede.meshing.box(..., comm=)`` makes each rank's share of the box and DMPlex balances it
(``snede.distribute_cells``: kept as given when balanced, else DMPlex partitions them). Compared with the serial box: together the parts hold its cells,
each once, every vertex owned once at its serial coordinates; no rank holds the whole (on
more than one rank); a static solve on it gives the serial displacement; malformed parts
raise the same ValueError on every rank."""
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

import snede

COMM = MPI.COMM_WORLD
SIZE, DIVISIONS = (1.0, 0.2, 0.3), (9, 2, 3)
CYLINDER = Path(__file__).parents[2] / "meshes" / "cylinder_large.msh"  # gmsh's, 8 724 tetrahedra


def gathered_cells(part):
    cells = part.global_vertex[part.local.cells] if part.local.n_cells else np.zeros((0, 4), dtype=np.int64)
    return [c for rank_cells in COMM.allgather([tuple(sorted(c)) for c in cells.tolist()]) for c in rank_cells]


def test_the_parts_are_the_serial_box_each_cell_and_vertex_once():
    serial = snede.meshing.box(SIZE, DIVISIONS)
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    assert (part.n_global_vertices, part.n_global_cells) == (len(serial.points), serial.n_cells)
    cells = gathered_cells(part)
    assert len(cells) == serial.n_cells and set(cells) == {tuple(sorted(c)) for c in serial.cells.tolist()}
    owners = np.concatenate(COMM.allgather(part.global_vertex[part.owned]))
    np.testing.assert_array_equal(np.sort(owners), np.arange(len(serial.points)))
    np.testing.assert_array_equal(part.local.points, serial.points[part.global_vertex])  # the same linspace values
    if part.local.n_cells:
        part.local.validate()
        p = part.local.points[part.local.cells]
        assert np.linalg.det(p[:, 1:] - p[:, :1]).min() > 0  # positively oriented, as serially


def test_no_rank_holds_the_whole_box():
    """Each rank makes only its share (its x layers of cubes and of points) and keeps only its
    part: on N > 1 ranks, no part has more than (1/N + a layer's worth) of the cells, nor
    close to all the vertices."""
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    share = part.n_global_cells / COMM.size
    layer = part.n_global_cells / DIVISIONS[0]
    counts = COMM.allgather(part.local.n_cells)
    assert sum(counts) == part.n_global_cells
    if COMM.size > 1:
        assert max(counts) <= share + layer, counts
        assert part.local.n_points < part.n_global_vertices


def test_a_static_solve_on_the_box_made_on_ranks_gives_the_serial_displacement():
    """A cantilever under gravity, held at x = 0 (ids picked on every rank's own points by
    vertices_where): linear CG to 1e-12 on the ranks against the serial solver on the serial box;
    both solve the same equations, so they agree to the solvers' tolerance."""
    material = snede.LinearElastic(1e5, 0.3)
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    held = part.vertices_where(lambda x: np.isclose(x[:, 0], 0.0))
    serial_mesh = snede.meshing.box(SIZE, DIVISIONS)
    np.testing.assert_array_equal(held, np.flatnonzero(np.isclose(serial_mesh.points[:, 0], 0.0)))
    problem = snede.DistributedStatic(part, material, density=1000.0, fixed=held, gravity=(0.0, 0.0, -9.81))
    result = problem.solve("cg", rtol=1e-12, criterion="6.9")
    assert result.converged, result
    body = snede.Body(serial_mesh, material, density=1000.0)
    body.fix(np.isclose(serial_mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "cg", rtol=1e-12).solve().converged
    u = problem.gathered_displacement()
    assert np.abs(u - body.displacement).max() <= 1e-8 * np.abs(body.displacement).max()


def chunk(n: int) -> slice:
    """This rank's share of n items in rank order (as a reader of a file would take them)."""
    return slice(COMM.rank * n // COMM.size, (COMM.rank + 1) * n // COMM.size)


@pytest.mark.parametrize("given", ["chunks", "rank 0"])
def test_a_gmsh_mesh_given_in_chunks_or_by_one_rank_solves_as_serially(given):
    """gmsh's cylinder read on every rank, each giving a chunk of its cells in file order and of
    its vertex ids (balanced: kept as given), or rank 0 giving all (unbalanced on N > 1 ranks:
    DMPlex partitions it anew): the parts are its cells, every rank gets some, and a
    neo-Hookean solve under gravity, held at x = 0, gives the serial Newton displacement."""
    serial = snede.Mesh.read(CYLINDER)
    if given == "chunks":
        cells, points = serial.cells[chunk(serial.n_cells)], serial.points[chunk(len(serial.points))]
    else:
        everything = slice(None) if COMM.rank == 0 else slice(0, 0)
        cells, points = serial.cells[everything], serial.points[everything]
    part = snede.distribute_cells(cells, points, COMM)
    gathered = gathered_cells(part)
    assert len(gathered) == serial.n_cells and set(gathered) == {tuple(sorted(c)) for c in serial.cells.tolist()}
    np.testing.assert_array_equal(part.local.points, serial.points[part.global_vertex])
    assert min(COMM.allgather(part.local.n_cells)) > 0
    material = snede.NeoHookean(3e4, 0.3)
    held = part.vertices_where(lambda x: x[:, 0] <= 1e-9)
    problem = snede.DistributedStatic(part, material, density=1000.0, fixed=held, gravity=(0.0, 0.0, -9.81))
    result = problem.solve("newton", rtol=1e-10, criterion="6.9")
    assert result.converged, result
    body = snede.Body(serial, material, density=1000.0)
    body.fix(serial.points[:, 0] <= 1e-9)
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "newton", rtol=1e-10).solve().converged
    u = problem.gathered_displacement()
    assert np.abs(u - body.displacement).max() <= 1e-6 * np.abs(body.displacement).max()


@pytest.mark.parametrize("given", ["chunks", "rank 0"])
def test_the_ranks_agree_on_every_vertex_owner_and_number(given):
    """PETSc's vertex numbering, whether the part was kept as given (balanced chunks: made by
    snede's own exchange) or partitioned by DMPlex (everything given by rank 0): each rank's
    owned vertices are numbered after the lower ranks' ones, contiguously; a vertex held by
    several ranks has exactly one owner among them and the same number on each; the numbers are
    0..n−1, once each."""
    serial = snede.Mesh.read(CYLINDER)
    mine = chunk(serial.n_cells) if given == "chunks" else slice(None) if COMM.rank == 0 else slice(0, 0)
    points = chunk(len(serial.points)) if given == "chunks" else mine
    part = snede.distribute_cells(serial.cells[mine], serial.points[points], COMM)
    n_owned = COMM.allgather(int(part.owned.sum()))
    first = sum(n_owned[:COMM.rank])
    np.testing.assert_array_equal(np.sort(part.global_number[part.owned]), np.arange(first, first + n_owned[COMM.rank]))
    held = COMM.allgather((part.global_vertex, part.global_number, part.owned))
    number, owners = {}, np.zeros(len(serial.points), dtype=int)
    for ids, numbers, owned in held:
        for vertex, n in zip(ids.tolist(), numbers.tolist()):
            assert number.setdefault(vertex, n) == n, vertex
        np.add.at(owners, ids[owned], 1)
    np.testing.assert_array_equal(owners, 1)
    assert sorted(number.values()) == list(range(len(serial.points)))


def shared_folder(tmp_path) -> Path:
    """Rank 0's temporary folder, the same path on every rank (each rank's pytest makes its own)."""
    return Path(COMM.bcast(str(tmp_path) if COMM.rank == 0 else None))


def test_a_series_file_is_read_in_shares_and_any_other_file_through_rank_0(tmp_path):
    """DistributedMesh.read: a series SeriesWriter wrote serially (its last step's mesh, read by
    each rank in its share of the HDF5 rows) and gmsh's .msh (read by rank 0 and distributed)
    give the parts of the same mesh; a missing file raises on every rank."""
    folder = shared_folder(tmp_path)
    serial = snede.Mesh.read(CYLINDER)
    if COMM.rank == 0:
        snede.output.SeriesWriter(folder / "cylinder").write(snede.Body(serial, snede.LinearElastic(1e5, 0.3)))
    COMM.Barrier()
    for path in (folder / "cylinder.xdmf", CYLINDER):
        part = snede.DistributedMesh.read(path, COMM)
        gathered = gathered_cells(part)
        assert len(gathered) == serial.n_cells, path
        assert set(gathered) == {tuple(sorted(c)) for c in serial.cells.tolist()}, path
        np.testing.assert_array_equal(part.local.points, serial.points[part.global_vertex])
    with pytest.raises(FileNotFoundError, match="no mesh file"):
        snede.DistributedMesh.read(folder / "missing.msh", COMM)


def test_a_series_written_on_ranks_reads_back_with_its_serial_ids(tmp_path):
    """From file to series and back on the ranks: a box made on the ranks, solved, written by
    write_part (PETSc's vertex order, serial ids in 'serial_vertex'), read in shares: the parts
    are the box again with the serial box's vertex ids, and a solve from them gives the same
    displacement."""
    folder = shared_folder(tmp_path)
    material = snede.LinearElastic(1e5, 0.3)
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    held = part.vertices_where(lambda x: np.isclose(x[:, 0], 0.0))
    problem = snede.DistributedStatic(part, material, fixed=held, gravity=(0.0, 0.0, -9.81))
    assert problem.solve("cg", rtol=1e-12, criterion="6.9").converged
    snede.output.SeriesWriter(folder / "on_ranks", comm=COMM).write_part(part, displacement=problem.local_displacement())
    COMM.Barrier()
    again = snede.DistributedMesh.read(folder / "on_ranks.xdmf", COMM)
    serial = snede.meshing.box(SIZE, DIVISIONS)
    assert set(gathered_cells(again)) == {tuple(sorted(c)) for c in serial.cells.tolist()}
    np.testing.assert_array_equal(again.local.points, serial.points[again.global_vertex])
    assert again.vertices_where(lambda x: np.isclose(x[:, 0], 0.0)).tolist() == held.tolist()
    solved_again = snede.DistributedStatic(again, material, fixed=held, gravity=(0.0, 0.0, -9.81))
    assert solved_again.solve("cg", rtol=1e-12, criterion="6.9").converged
    u, v = problem.gathered_displacement(), solved_again.gathered_displacement()
    assert np.abs(u - v).max() <= 1e-8 * np.abs(u).max()


@pytest.mark.parametrize("bad, message", [
    ("id", "cell vertex id .* is outside 0.."),
    ("corners", "tetrahedra in 3D"),
    ("unused", "vertices are in no cell"),
])
def test_a_malformed_part_raises_the_same_error_on_every_rank(bad, message):
    serial = snede.meshing.box(SIZE, (2, 1, 1))
    mine = slice(None) if COMM.rank == 0 else slice(0, 0)
    cells, points = serial.cells[mine], serial.points[mine]
    last = COMM.size - 1
    if bad == "id" and COMM.rank == last:
        cells = np.array([[0, 1, 2, 10_000]])
    if bad == "corners":
        cells = cells[:, :2]
    if bad == "unused" and COMM.rank == 0:
        cells = cells[cells.max(axis=1) < len(serial.points) - 1]  # the last vertex in no cell
    with pytest.raises(ValueError, match=message):
        snede.distribute_cells(cells, points, COMM)
    assert COMM.allreduce(1) == COMM.size  # every rank got here: nobody hangs


def test_vertices_where_checks_what_the_predicate_gives():
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    with pytest.raises(ValueError, match="one bool per point"):
        part.vertices_where(lambda x: np.ones(3, dtype=bool) if COMM.rank == COMM.size - 1 else x[:, 0] > 0.5)
