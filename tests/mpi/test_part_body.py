"""A body that no rank holds whole, driven with the serial Body's calls (issue 52, item 2): on 1, 2
and 3 ranks, ``snede.Body(part, ...)`` is a PartBody; fix, slide, add_gravity, add_nodal_force and
add_traction take selections in the part's local numbering, joined over the ranks by serial id;
StaticSolver, DynamicRelaxation and SeriesWriter take the PartBody. Compared with the serial Body
given the same selections (by coordinates, so each rank picks its own points)."""
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

import snede

COMM = MPI.COMM_WORLD
CYLINDER = Path(__file__).parents[2] / "meshes" / "cylinder_large.msh"  # gmsh's, 8 724 tetrahedra
SIZE, DIVISIONS = (1.0, 0.2, 0.3), (9, 2, 3)


def chunk(n: int) -> slice:
    return slice(COMM.rank * n // COMM.size, (COMM.rank + 1) * n // COMM.size)


def cylinder_part():
    serial = snede.Mesh.read(CYLINDER)
    return serial, snede.distribute_cells(serial.cells[chunk(serial.n_cells)], serial.points[chunk(len(serial.points))],
                                          COMM)


def load(body):
    """The same calls on a serial Body and on a PartBody: held at x = 0, sliding along z at the
    far end, gravity, a traction on the upper faces around the middle, a nodal force on the far
    end. Returns how many faces this rank loaded."""
    points = body.mesh.points
    x, z = points[:, 0], points[:, 2]
    body.fix(x <= 1e-9)
    far = COMM.allreduce(x.max(), op=MPI.MAX) if isinstance(body, snede.PartBody) else x.max()
    top = COMM.allreduce(z.max(), op=MPI.MAX) if isinstance(body, snede.PartBody) else z.max()
    body.slide(np.isclose(x, far), (0.0, 0.0, 1.0))
    body.add_gravity((0.0, 0.0, -9.81))
    faces = body.boundary_faces()
    up = np.all(z[faces] > 0.5 * top, axis=1) & np.all(np.abs(x[faces] - 0.5 * far) < 0.25 * far, axis=1)
    body.add_traction(faces[up], (0.0, 0.0, -40.0))
    body.add_nodal_force(np.isclose(x, far), (0.0, 0.0, -0.01), channel="tip")
    return int(up.sum())


def test_body_of_a_part_is_a_part_body_and_solves_as_serially():
    """Neo-Hookean, Newton to rtol 1e-10 by (6.9): each rank's displacement is the serial one at
    its vertices, to the solvers' tolerance (both solve the same equations)."""
    serial_mesh, part = cylinder_part()
    material = snede.NeoHookean(3e4, 0.3)
    body = snede.Body(part, material, density=1000.0)
    assert isinstance(body, snede.PartBody) and body.mesh is part.local
    load(body)
    result = snede.StaticSolver(body, "newton", rtol=1e-10).solve()
    assert result.converged, result
    serial = snede.Body(serial_mesh, material, density=1000.0)
    assert load(serial) > 100  # the traction has faces to act on
    assert snede.StaticSolver(serial, "newton", rtol=1e-10).solve().converged
    scale = np.abs(serial.displacement).max()
    assert np.abs(body.displacement - serial.displacement[part.global_vertex]).max() <= 1e-6 * scale
    far = np.isclose(part.local.points[:, 0], serial_mesh.points[:, 0].max())
    np.testing.assert_allclose(body.displacement[far][:, :2], 0.0, atol=1e-12 * scale)  # slid along z only


def test_a_vertex_several_ranks_select_is_loaded_and_fixed_once():
    """Every rank selects every vertex it holds on the plane x = 0.5 (ghosts too): the nodal force
    on each counts once, so the body's total load is the force times the plane's vertex count, as
    serially; traction on the whole top once: its total is traction × the top's area."""
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    body = snede.Body(part, snede.LinearElastic(1e5, 0.3))
    plane = np.isclose(body.mesh.points[:, 0], 5 / 9)
    body.add_nodal_force(plane, (0.0, 0.0, -1.0))
    faces = body.boundary_faces()
    body.add_traction(faces[np.all(np.isclose(body.mesh.points[faces, 2], SIZE[2]), axis=1)], (0.0, 2.0, 0.0), "top")
    serial = snede.meshing.box(SIZE, DIVISIONS)
    n_plane = int(np.isclose(serial.points[:, 0], 5 / 9).sum())
    loads = [force for channel in body.load_channels for force in body._channels[channel].values()]
    np.testing.assert_allclose(np.sum(loads, axis=0), (0.0, 2.0 * SIZE[0] * SIZE[1], -float(n_plane)), rtol=1e-12)


def test_the_ranks_boundary_faces_are_the_bodys_each_once():
    """PartBody.boundary_faces leaves out the faces between two ranks' cells: together the ranks
    give the serial mesh's boundary faces, each once, oriented as serially."""
    serial, part = cylinder_part()
    body = snede.Body(part, snede.LinearElastic(1e5, 0.3))
    mine = part.global_vertex[body.boundary_faces()]
    gathered = np.concatenate(COMM.allgather(mine))
    expected = serial.boundary_faces()
    assert len(gathered) == len(expected)
    rotated = lambda faces: {tuple(np.roll(f, -int(np.argmin(f)))) for f in faces.tolist()}  # noqa: E731
    assert rotated(gathered) == rotated(expected)


def test_ranks_that_give_one_vertex_different_values_all_raise():
    """Each rank fixes the planes at both ends of its x layers at a displacement of its own: two
    neighbours share the plane between them (on N > 1 ranks), so every rank raises, naming a
    vertex and both values; a malformed mask on one rank raises on every rank too."""
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    body = snede.Body(part, snede.LinearElastic(1e5, 0.3))
    x = body.mesh.points[:, 0]
    ends = np.isclose(x, x.min()) | np.isclose(x, x.max())
    if COMM.size == 1:
        body.fix(ends, (0.0, 0.0, 0.1))
    else:
        with pytest.raises(ValueError, match="different values by different ranks"):
            body.fix(ends, (0.0, 0.0, 0.1 * (COMM.rank + 1)))
    with pytest.raises(ValueError, match="boolean vertex mask must have shape"):
        body.fix(np.zeros(3, dtype=bool) if COMM.rank == COMM.size - 1 else ends)
    assert COMM.allreduce(1) == COMM.size  # every rank got here: nobody hangs


def test_refusals_name_the_reason_on_every_rank():
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    with pytest.raises(NotImplementedError, match="not distributed yet"):
        snede.Body(part, snede.LinearElastic(1e5, 0.3), formulation="smoothed")
    body = snede.Body(part, snede.LinearElastic(1e5, 0.3))
    body.add_gravity((0.0, 0.0, -9.81))
    with pytest.raises(ValueError, match="the body is not held"):
        snede.StaticSolver(body, "cg").solve()
    with pytest.raises(ValueError, match="leave comm out"):
        snede.StaticSolver(body, "cg", comm=COMM.Dup())
    with pytest.raises(ValueError, match="shape"):
        body.displacement = np.zeros((3, 3))
    with pytest.raises(ValueError, match="non-zero finite 3-vector"):  # on one rank: every rank raises
        body.slide(np.isclose(body.mesh.points[:, 0], 1.0), (0.0, 0.0, 0.0) if COMM.rank == COMM.size - 1 else (0, 0, 1))
    assert COMM.allreduce(1) == COMM.size


def test_no_array_of_the_whole_body_on_a_rank():
    """After a solve, every array the PartBody and its problem hold per vertex has the part's
    size, and the conditions hold only the constrained vertices: on N > 1 ranks, fewer than the
    whole body's."""
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    body = snede.Body(part, snede.LinearElastic(1e5, 0.3))
    body.fix(np.isclose(body.mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "cg", rtol=1e-10).solve().converged
    n_local = part.local.n_points
    assert body.displacement.shape == (n_local, 3)
    assert body._displacement.shape == (n_local, 3) and body._local_order.shape == (n_local,)
    assert body._problem.local_displacement().shape == (n_local, 3)
    assert len(body._fixed) == (DIVISIONS[1] + 1) * (DIVISIONS[2] + 1)
    if COMM.size > 1:
        assert n_local < part.n_global_vertices


def test_dynamic_relaxation_of_a_part_body_follows_the_serial_one():
    """The same damped central-difference steps on the serial body and on the ranks: the same
    iterates in exact arithmetic, so the same number of steps to (6.9) and the same displacement
    up to the summation order's round-off."""
    material = snede.LinearElastic(1e5, 0.3)
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    body = snede.Body(part, material)
    body.fix(np.isclose(body.mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    serial = snede.Body(snede.meshing.box(SIZE, DIVISIONS), material)
    serial.fix(np.isclose(serial.mesh.points[:, 0], 0.0))
    serial.add_gravity((0.0, 0.0, -9.81))
    relaxation = snede.DynamicRelaxation(serial, damping=1.5)
    expected = relaxation.run(rtol=1e-6, max_steps=20000)
    assert expected.converged, expected
    result = snede.DynamicRelaxation(body, damping=1.5, dt=relaxation.dt).run(rtol=1e-6, max_steps=20000)
    assert result.converged, result
    assert result.iterations == expected.iterations
    scale = np.abs(serial.displacement).max()
    assert np.abs(body.displacement - serial.displacement[part.global_vertex]).max() <= 1e-10 * scale


def test_a_series_written_from_a_part_body_reads_back_with_serial_ids(tmp_path):
    """SeriesWriter.write of a PartBody writes the part: its displacement by serial vertex id,
    and the inverted cells (none at the solved state, all of them mirrored)."""
    folder = Path(COMM.bcast(str(tmp_path) if COMM.rank == 0 else None))
    part = snede.meshing.box(SIZE, DIVISIONS, comm=COMM)
    body = snede.Body(part, snede.LinearElastic(1e5, 0.3))
    body.fix(np.isclose(body.mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "cg", rtol=1e-10).solve().converged
    writer = snede.output.SeriesWriter(folder / "part_body", comm=COMM)
    writer.write(body)
    mirrored = -2.0 * body.mesh.points  # x → −x: every cell turned inside out
    writer.write(body, time=1.0, displacement=mirrored)
    COMM.Barrier()
    u = body.gathered_displacement()
    if COMM.rank == 0:
        solved, inverted = snede.output.read_series(folder / "part_body.xdmf")
        serial_ids = solved.point_fields["serial_vertex"].astype(np.int64)
        np.testing.assert_array_equal(solved.displacement, u[serial_ids])
        assert not solved.cell_fields["inverted"].any() and inverted.cell_fields["inverted"].all()
