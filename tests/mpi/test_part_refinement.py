"""Conforming bisection of a body no rank holds whole (issue 52, item 3): on 1, 2 and 3 ranks,
``PartBody.refine_uniform`` and ``refine_around`` give exactly the serial refinement's cells
(compared by their corners' coordinates, bit for bit: midpoints are computed alike), without a
hanging vertex across the rank boundary, carry the displacement and the fixed vertices as the
serial Body does, and the refined body's solve is the serial refined body's. The partitions are
DMPlex's (``distribute``) and chunks of the cell list (``distribute_cells``), so rank boundaries
cross the meshes anywhere."""
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

import snede

COMM = MPI.COMM_WORLD
MESHES = Path(__file__).resolve().parents[2] / "meshes"


def chunk(n: int) -> slice:
    return slice(COMM.rank * n // COMM.size, (COMM.rank + 1) * n // COMM.size)


def box():
    return snede.meshing.box((1.0, 0.6, 0.4), (5, 3, 2))


def cylinder():  # gmsh's, refined by longest-edge bisection
    return snede.Mesh.read(MESHES / "cylinder_small.msh")


def rectangle():
    return snede.meshing.rectangle((1.0, 0.5), (6, 3))


def part_of(mesh, partition):
    if partition == "dmplex":
        return snede.distribute(mesh if COMM.rank == 0 else None, comm=COMM)
    return snede.distribute_cells(mesh.cells[chunk(mesh.n_cells)], mesh.points[chunk(mesh.n_points)], COMM)


def cell_corners(points, cells) -> list:
    """Every cell as the sorted tuple of its corners' coordinates, sorted."""
    return sorted(tuple(sorted(map(tuple, corners))) for corners in points[cells])


def gathered(body):
    """The whole refined mesh of a PartBody (points by global id, cells), on every rank."""
    every = COMM.allgather((body.part.global_vertex, body.mesh.points, body.mesh.cells))
    points = np.zeros((body.part.n_global_vertices, body.dim))
    for ids, x, _ in every:
        points[ids] = x
    return points, np.concatenate([ids[cells] for ids, _, cells in every])


def assert_same_cells(body, serial_mesh):
    points, cells = gathered(body)
    assert len(cells) == serial_mesh.n_cells == body.part.n_global_cells
    assert len(points) == serial_mesh.n_points
    assert cell_corners(points, cells) == cell_corners(serial_mesh.points, serial_mesh.cells)
    # Conforming: a hanging vertex would leave faces that only one cell has inside the body.
    whole = snede.Mesh(points, cells)
    assert len(whole.boundary_faces()) == len(serial_mesh.boundary_faces())


MATERIAL = snede.LinearElastic(1e4, 0.3)


@pytest.mark.parametrize("make", [box, cylinder, rectangle])
@pytest.mark.parametrize("partition", ["dmplex", "chunks"])
def test_uniform_refinement_on_ranks_is_the_serial_one(make, partition):
    serial = make()
    body = snede.Body(part_of(serial, partition), MATERIAL, thickness=0.01 if serial.dim == 2 else None)
    split = body.refine_uniform(2)
    assert split == serial.refine_uniform(2)
    assert_same_cells(body, serial)


@pytest.mark.parametrize("partition", ["dmplex", "chunks"])
def test_successive_refinements_go_on_as_the_serial_hierarchy(partition):
    """Maubach's tags carried from one refinement to the next (also through a rebalancing):
    relabelling the refined Kuhn box afresh splits 8 400 cells at the third level, not 5 040."""
    serial = snede.meshing.box((1.0, 1.0, 1.0), (7, 6, 5))
    body = snede.Body(part_of(serial, partition), MATERIAL)
    corner = COMM.bcast(body.mesh.points[body.mesh.cells[0]].mean(axis=0), root=0)  # in a cell of rank 0
    crowd = (corner, corner + 0.03, 0.03, 0.05)  # a short shaft in rank 0's cells: DMPlex rebalances
    for edit in (lambda target: target.refine_uniform(1), lambda target: target.refine_near_segment(*crowd),
                 lambda target: target.refine_uniform(1), lambda target: target.refine_uniform(1)):
        assert edit(body) == edit(serial)
        assert_same_cells(body, serial)


def test_labels_of_another_part_are_refused_on_every_rank():
    body = snede.Body(part_of(box(), "chunks"), MATERIAL)
    n_cells = body.mesh.n_cells
    too_few = (0, np.zeros((max(n_cells - 1, 0), 5), dtype=np.int64))
    with pytest.raises(ValueError, match="not this part's"):
        snede._snede.PartRefinement(body.part._impl, too_few)
    elsewhere = np.full((n_cells, 5), body.part.n_global_vertices + 7, dtype=np.int64)  # vertices no rank has
    elsewhere[:, 4] = 3
    with pytest.raises(ValueError, match="not this part's"):
        snede._snede.PartRefinement(body.part._impl, (0, elsewhere))


@pytest.mark.parametrize("make", [box, cylinder])
@pytest.mark.parametrize("partition", ["dmplex", "chunks"])
def test_refinement_around_a_point_on_ranks_is_the_serial_one(make, partition):
    serial = make()
    body = snede.Body(part_of(serial, partition), MATERIAL)
    low, high = serial.points.min(axis=0), serial.points.max(axis=0)
    point, h = low + (high - low) * (0.43, 0.51, 0.37), 0.02 * np.max(high - low)
    split = body.refine_around(point, h)
    assert split == serial.refine_around(point, h) > 0
    assert_same_cells(body, serial)


@pytest.mark.parametrize("partition", ["dmplex", "chunks"])
def test_refinement_along_a_needle_shaft_on_ranks_is_the_serial_one(partition):
    serial = cylinder()
    body = snede.Body(part_of(serial, partition), MATERIAL)
    low, high = serial.points.min(axis=0), serial.points.max(axis=0)
    a, b = low + (high - low) * (0.1, 0.45, 0.5), low + (high - low) * (0.9, 0.55, 0.45)
    h, radius = 0.04 * np.max(high - low), 0.01 * np.max(high - low)
    split = body.refine_near_segment(a, b, h, radius)
    assert split == serial.refine_near_segment(a, b, h, radius) > 0
    assert_same_cells(body, serial)


def gathered_groups(body) -> tuple[dict, dict]:
    """The body's cell and boundary groups over every rank, as sorted corner coordinates."""
    mesh = body.mesh
    mine = ({name: cell_corners(mesh.points, mesh.cells[rows]) for name, rows in mesh.cell_groups.items()},
            {name: cell_corners(mesh.points, faces) for name, faces in mesh.boundary_groups.items() if name != "incision"})
    every = COMM.allgather(mine)
    return tuple({name: sorted(member for groups in every for member in groups[kind].get(name, []))
                  for name in every[0][kind]} for kind in (0, 1))


@pytest.mark.parametrize("partition", ["dmplex", "chunks"])
def test_named_groups_follow_the_refinement_as_serially(partition):
    serial = box()
    x = serial.points
    serial.add_cell_group("left", np.flatnonzero(x[serial.cells].mean(axis=1)[:, 0] < 0.5))
    top = serial.boundary_faces()
    serial.add_boundary_group("top", top[np.all(np.isclose(x[top][:, :, 2], 0.4), axis=1)])
    body = snede.Body(part_of(serial, partition), MATERIAL)
    if partition == "chunks":  # distribute_cells takes no groups: name them on the parts
        centroids = body.mesh.points[body.mesh.cells].mean(axis=1)
        body.mesh.add_cell_group("left", np.flatnonzero(centroids[:, 0] < 0.5))
        faces = body.boundary_faces()
        body.mesh.add_boundary_group("top", faces[np.all(np.isclose(body.mesh.points[faces][:, :, 2], 0.4), axis=1)])
    body.refine_around((0.45, 0.3, 0.38), 0.1)
    serial.refine_around((0.45, 0.3, 0.38), 0.1)
    cells, faces = gathered_groups(body)
    assert cells["left"] == cell_corners(serial.points, serial.cells[serial.cell_groups["left"]])
    assert faces["top"] == cell_corners(serial.points, serial.boundary_groups["top"])
    assert len(faces["top"]) > 5 * 3 * 2  # refined: more than the 30 faces it started with
    body.fix("top")  # a group of the refined part is a condition as serially


def test_a_linear_displacement_is_carried_exactly_and_midpoints_of_fixed_vertices_are_fixed():
    serial = box()
    body = snede.Body(part_of(serial, "chunks"), MATERIAL)
    gradient = np.array([[0.01, -0.02, 0.005], [0.003, 0.02, 0.0], [-0.01, 0.0, 0.015]])
    body.fix(np.isclose(body.mesh.points[:, 0], 0.0), value=(0.001, -0.002, 0.003))
    body.displacement = body.mesh.points @ gradient.T
    body.refine_uniform(1)
    x = body.mesh.points
    # The parents' mean of a linear field is the field (to the rounding of the mean).
    assert np.allclose(body.displacement, x @ gradient.T, rtol=0, atol=1e-15)
    on_face = np.isclose(x[:, 0], 0.0)
    fixed = np.array(sorted(body._fixed))
    held = np.isin(body.part.global_vertex, fixed)
    assert np.array_equal(held, on_face)  # every new vertex of the held face is fixed, none elsewhere
    assert all(body._fixed[v] == (0.001, -0.002, 0.003) for v in fixed)  # the mean of equal anchors


EDITS = {"uniform": lambda target: target.refine_uniform(1),
         "around": lambda target: target.refine_around((0.7, 0.3, 0.2), 0.08)}


@pytest.mark.parametrize("edit", EDITS)
@pytest.mark.parametrize("partition", ["dmplex", "chunks"])
def test_the_refined_part_numbers_every_vertex_once(edit, partition):
    """Owners and PETSc's numbering, whether the refined part stays in place (balanced) or
    DMPlex rebalances it: each vertex owned by one rank, owned rows contiguous in rank order,
    a ghost carrying its owner's row."""
    body = snede.Body(part_of(box(), partition), MATERIAL)
    EDITS[edit](body)
    part = body.part
    every = COMM.allgather((part.global_vertex, part.owned, part.global_number))
    owned_ids = np.concatenate([ids[owned] for ids, owned, _ in every])
    assert np.array_equal(np.sort(owned_ids), np.arange(part.n_global_vertices))
    rows = np.concatenate([numbers[owned] for _, owned, numbers in every])
    assert np.array_equal(np.sort(rows), np.arange(part.n_global_vertices))
    starts = np.cumsum([0] + [int(owned.sum()) for _, owned, _ in every])
    for rank, (_, owned, numbers) in enumerate(every):
        assert np.all((numbers[owned] >= starts[rank]) & (numbers[owned] < starts[rank + 1]))
    row_of = dict(zip(owned_ids.tolist(), rows.tolist()))
    for ids, owned, numbers in every:
        assert all(row_of[i] == r for i, r in zip(ids[~owned].tolist(), numbers[~owned].tolist()))


@pytest.mark.parametrize("edit", EDITS)
def test_the_refined_body_solves_as_the_serial_refined_body(edit):
    serial = box()
    body = snede.Body(part_of(serial, "dmplex"), MATERIAL)
    serial_body = snede.Body(serial, MATERIAL)
    for b in (body, serial_body):
        b.fix(np.isclose(b.mesh.points[:, 0], 0.0))
        b.add_gravity((0.0, 0.0, -9.81))
    EDITS[edit](body)
    EDITS[edit](serial_body.mesh)
    for b in (body, serial_body):
        assert snede.StaticSolver(b, "cg", rtol=1e-12).solve().converged
    order = np.lexsort(serial.points.T[::-1])
    points, _ = gathered(body)
    mine = np.lexsort(points.T[::-1])
    assert np.array_equal(points[mine], serial.points[order])
    u = body.gathered_displacement()
    scale = np.abs(serial_body.displacement).max()
    assert scale > 0
    assert np.abs(u[mine] - serial_body.displacement[order]).max() <= 1e-8 * scale


def test_parts_are_rebalanced_when_refinement_crowds_one_rank():
    serial = snede.meshing.box((1.0, 1.0, 1.0), (6, 6, 6))
    body = snede.Body(part_of(serial, "chunks"), MATERIAL)
    corner = COMM.bcast(body.mesh.points[body.mesh.cells[0]].mean(axis=0), root=0)  # inside a cell of rank 0
    body.refine_near_segment(corner, corner + 0.03, 0.03, 0.05)  # three times the cells, all near rank 0's
    counts = COMM.allgather(body.mesh.n_cells)
    assert sum(counts) == body.part.n_global_cells
    if COMM.size > 1:
        assert max(counts) <= 1.2 * np.mean(counts)


def test_bad_or_differing_arguments_raise_on_every_rank():
    serial = box()
    body = snede.Body(part_of(serial, "chunks"), MATERIAL)
    with pytest.raises(ValueError, match="outside the mesh"):
        body.refine_around((5.0, 5.0, 5.0), 0.1)
    with pytest.raises(ValueError, match="h"):
        body.refine_around((0.5, 0.3, 0.2), -1.0)
    if COMM.size > 1:
        with pytest.raises(ValueError, match="different inputs"):
            body.refine_around((0.5, 0.3, 0.2), 0.1 + COMM.rank)
        with pytest.raises(ValueError, match="different inputs"):
            body.refine_uniform(1 + COMM.rank % 2)
    assert body.part.n_global_cells == serial.n_cells  # nothing was lost; the body refines as before
    assert body.refine_uniform(1) == serial.n_cells
    assert body.part.n_global_cells == 2 * serial.n_cells
