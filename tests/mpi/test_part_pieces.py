"""The serial Body's check that every piece is held, on a body no rank holds whole (issue 52):
on 1, 2 and 3 ranks, parts of two separate bars (cut into chunks by cell, so each bar lies on
several ranks) are refused or accepted exactly as the serial Body refuses or accepts them,
with the serial message where the body is one piece."""
import re

import numpy as np
import pytest
from mpi4py import MPI

import snede

COMM = MPI.COMM_WORLD


def chunk(n: int) -> slice:
    return slice(COMM.rank * n // COMM.size, (COMM.rank + 1) * n // COMM.size)


def two_bars():
    """Two 1 × 0.2 × 0.2 bars along x, 0.5 apart: one serial mesh of two pieces, their cells
    interleaved, so that every rank's chunk holds cells of both bars."""
    bar = snede.meshing.box((1.0, 0.2, 0.2), (5, 1, 1))
    points = np.vstack([bar.points, bar.points + (1.5, 0.0, 0.0)])
    cells = np.empty((2 * bar.n_cells, 4), dtype=np.int64)
    cells[0::2], cells[1::2] = bar.cells, bar.cells + len(bar.points)
    return snede.Mesh(points, cells)


def bodies(mesh):
    """The serial Body and the PartBody of the same mesh (its cells and points in chunks)."""
    part = snede.distribute_cells(mesh.cells[chunk(mesh.n_cells)], mesh.points[chunk(len(mesh.points))], COMM)
    material = snede.LinearElastic(1e5, 0.3)
    return snede.Body(mesh, material), snede.Body(part, material)


def refusal(body):
    """The message require_held raises, or None."""
    try:
        body.require_held() if isinstance(body, snede.PartBody) else body._model.require_held()
    except ValueError as error:
        return re.sub(r"^rank \d+: ", "", str(error))
    return None


def hold(body, where):
    """Fix the vertices of `body` whose points `where` picks (each rank its own)."""
    body.fix(where(body.mesh.points))


@pytest.mark.parametrize("case", ["both ends", "first bar only", "a line of the first bar", "nothing"])
def test_a_part_body_is_held_where_the_serial_body_is(case):
    serial, mine = bodies(two_bars())
    supports = {
        "both ends": lambda x: np.isclose(x[:, 0], 0.0) | np.isclose(x[:, 0], 1.5),
        "first bar only": lambda x: np.isclose(x[:, 0], 0.0),
        "a line of the first bar": lambda x: np.isclose(x[:, 0], 0.0) & np.isclose(x[:, 1], 0.0),
        "nothing": None,
    }[case]
    for body in (serial, mine):
        if supports is not None:
            hold(body, supports)
    expected, got = refusal(serial), refusal(mine)
    assert (expected is None) == (got is None), (expected, got)
    assert set(COMM.allgather(got)) == {got}  # the same on every rank
    if expected is not None:
        # The counts agree: constrained components, rigid motions stopped, pieces not held.
        numbers = lambda text: re.findall(r"(\d+) constrained displacement components, which stop (\d+) of its (\d+)",
                                          text) + re.findall(r"; (\d+) of the (\d+) pieces", text)
        assert numbers(got) == numbers(expected), (expected, got)


def test_one_piece_held_on_a_line_gives_the_serial_message():
    """One bar held on the vertices of one edge: it turns about it. Every count in the message
    (cells, constrained components, motions stopped) is the serial one."""
    bar = snede.meshing.box((1.0, 0.2, 0.2), (5, 1, 1))
    serial, mine = bodies(bar)
    for body in (serial, mine):
        hold(body, lambda x: np.isclose(x[:, 0], 0.0) & np.isclose(x[:, 1], 0.0))
    expected = refusal(serial)
    assert expected is not None and "stop 5 of its 6" in expected
    assert refusal(mine) == expected
    with pytest.raises(ValueError, match="stop 5 of its 6"):
        snede.StaticSolver(mine, "cg").solve()
