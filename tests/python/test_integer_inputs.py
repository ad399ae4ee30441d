"""Issue 14, item 7: integers handed to the engine are checked in Python (snede._checks).

Before, a count beyond the engine's 32-bit ``int`` (``refine_uniform(2**40)``,
``max_iterations=2**40``, ``DynamicRelaxation.step(2**40)``, ...) reached pybind11 as an opaque
"incompatible function arguments" TypeError; a uint64 id beyond int64 was wrapped to a negative
number and reported as such ("id -9223372036854775803 is out of range"); ``rectangle((1, 1),
(2**40, 2))`` ran numpy out of memory; a float id was truncated (``star(1.5)`` was vertex 1) and a
negative row counted from the end (``element_stiffness(-1, u)``). Now each is a ValueError naming
the argument and the offending value, and the values the engine can take still work.
"""
import re

import numpy as np
import pytest

import snede
from expected_errors import refused
from snede import _checks
from snede.meshing import box, rectangle

INT32_MAX = 2**31 - 1
BIG = 2**40  # beyond the engine's int32 and PetscInt
BEYOND_INT64 = 2**63 + 5  # a uint64 that int64 wraps to -9223372036854775803


def sheet():
    """A 2 × 2-square sheet: 9 vertices (4 the centre), 8 triangles."""
    mesh = rectangle((1.0, 1.0), (2, 2))
    return mesh, snede.Body(mesh, snede.LinearElastic(1e4, 0.3), thickness=0.01)


def needle(body, **kwargs):
    return snede.NeedleInsertion(body, (0.0, 0.5), (1.0, 0.0), snede.FrictionProfile.uniform(1.0), **kwargs)


# -- counts ---------------------------------------------------------------------------------------
# (id, call(mesh, body, value), argument name, smallest allowed value)
COUNTS = [
    ("refine_uniform-levels", lambda m, b, v: m.refine_uniform(v), "levels", 0),
    ("StaticSolver-max_iterations", lambda m, b, v: snede.StaticSolver(b, "cg", max_iterations=v), "max_iterations", 1),
    ("DynamicRelaxation.step-n", lambda m, b, v: snede.DynamicRelaxation(b, 10.0).step(v), "n", 0),
    ("DynamicRelaxation.run-max_steps", lambda m, b, v: snede.DynamicRelaxation(b, 10.0).run(max_steps=v), "max_steps", 0),
    ("DynamicRelaxation.critical_time_step-min_steps",
     lambda m, b, v: snede.DynamicRelaxation(b, 10.0).critical_time_step(min_steps=v), "min_steps", 1),
    ("NeedleInsertion-max_rearrangements", lambda m, b, v: needle(b, max_rearrangements=v), "max_rearrangements", 1),
    ("NeedleInsertion-solves_per_update", lambda m, b, v: needle(b, solves_per_update=v), "solves_per_update", 0),
    ("NeedleInsertion-max_iterations", lambda m, b, v: needle(b, max_iterations=v), "max_iterations", 1),
    ("rectangle-divisions", lambda m, b, v: rectangle((1.0, 1.0), (v, 2)), "divisions[0]", 1),
    ("box-divisions", lambda m, b, v: box((1.0, 1.0, 1.0), (2, v, 2)), "divisions[1]", 1),
    ("cylinder-seed", lambda m, b, v: snede.meshing.cylinder(seed=v), "seed", 0),
]
COUNT_IDS = [c[0] for c in COUNTS]


@pytest.mark.parametrize("entry, call, name, low", COUNTS, ids=COUNT_IDS)
@pytest.mark.parametrize("bad", [True, 1.5, 2.0, np.float64(3.0), "3"], ids=repr)
def test_a_count_that_is_no_integer_is_refused_by_name(entry, call, name, low, bad):
    mesh, body = sheet()
    refused(lambda: call(mesh, body, bad), f"{name} must be", repr(bad))


@pytest.mark.parametrize("entry, call, name, low", COUNTS, ids=COUNT_IDS)
@pytest.mark.parametrize("offset", [1, 2**31])
def test_a_count_below_its_range_is_refused_with_the_value(entry, call, name, low, offset):
    mesh, body = sheet()
    refused(lambda: call(mesh, body, low - offset), f"{name} must be at least {low}, got {low - offset}")


@pytest.mark.parametrize("entry, call, name, low", [c for c in COUNTS if "divisions" not in c[0]],
                         ids=[i for i in COUNT_IDS if "divisions" not in i])
@pytest.mark.parametrize("big", [BIG, INT32_MAX + 1, np.int64(BIG), np.uint64(BEYOND_INT64)], ids=repr)
def test_a_count_beyond_the_engine_is_a_value_error_not_a_type_error(entry, call, name, low, big):
    mesh, body = sheet()
    message = refused(lambda: call(mesh, body, big), f"{name} must be at most", f"got {int(big)}")
    assert re.search(rf"\b{low}\.\.\d+", message), message  # the allowed range


def test_refine_uniform_stops_where_the_cell_count_would_leave_32_bits():
    mesh, _ = sheet()  # 8 cells: 8 · 2**27 = 2**30 fits, 8 · 2**28 = 2**31 does not
    message = refused(lambda: mesh.refine_uniform(28), "levels must be at most 27, got 28", "0..27", "2**31 − 1")
    assert "8 cells" in message
    assert mesh.n_cells == 8


@pytest.mark.parametrize("divisions, name", [((BIG, 2), "rectangle"), ((46341, 46341), "rectangle"),
                                             ((2, 2, BIG), "box"), ((1290, 1290, 1290), "box")])
def test_a_structured_mesh_too_large_for_32_bit_ids_is_refused_before_it_is_built(divisions, name):
    make = rectangle if name == "rectangle" else box
    size = (1.0,) * len(divisions)
    refused(lambda: make(size, divisions), f"divisions {divisions}", "too large", "32-bit", str(INT32_MAX))


@pytest.mark.parametrize("good", [0, 1, np.int8(1), np.uint64(1), np.int32(0)], ids=repr)
def test_counts_the_engine_takes_still_work(good):
    mesh, body = sheet()
    assert mesh.refine_uniform(good) == (8 if good else 0)
    dynamics = snede.DynamicRelaxation(body, 10.0)
    assert dynamics.step(good).converged
    assert dynamics.run(max_steps=good) is not None
    assert rectangle((1.0, 1.0), (int(good) + 1, np.uint64(2))).n_cells == 2 * (int(good) + 1) * 2


@pytest.mark.parametrize("largest", [INT32_MAX, np.int64(INT32_MAX), np.uint64(INT32_MAX)], ids=repr)
def test_the_largest_32_bit_count_is_taken(largest):
    _, body = sheet()
    snede.StaticSolver(body, "cg", max_iterations=largest)  # made, not run
    needle(body, max_rearrangements=largest, solves_per_update=largest, max_iterations=largest)
    mesh = rectangle((1.0, 1.0), (1, 1))  # 2 cells: levels up to 29 (2 · 2**29 = 2**30)
    refused(lambda: mesh.refine_uniform(30), "at most 29")


# -- single ids -----------------------------------------------------------------------------------
# (id, call(mesh, body, value), argument name, limit: "points", "cells" or "elements")
IDS = [
    ("Mesh.star", lambda m, b, v: m.star(v), "vertex", "points"),
    ("Mesh.remove_vertex", lambda m, b, v: m.remove_vertex(v), "vertex", "points"),
    ("Mesh.move_vertex-point", lambda m, b, v: m.move_vertex(v, point=(0.5, 0.5)), "vertex", "points"),
    ("Mesh.move_vertex-parents", lambda m, b, v: m.move_vertex(v, [4], [1.0]), "vertex", "points"),
    ("Mesh.flip_edge", lambda m, b, v: m.flip_edge(v, 4), "a", "points"),
    ("Mesh.is_locally_delaunay", lambda m, b, v: m.is_locally_delaunay(4, v), "b", "points"),
    ("Mesh.split_edge", lambda m, b, v: m.split_edge(v, 4), "a", "points"),
    ("Mesh.collapse_edge", lambda m, b, v: m.collapse_edge(4, v), "gone", "points"),
    ("Mesh.remove_vertex_by_flips", lambda m, b, v: m.remove_vertex_by_flips(v), "vertex", "points"),
    ("Mesh.snap_vertex", lambda m, b, v: m.snap_vertex(v, [4], [1.0]), "vertex", "points"),
    ("Mesh.element_vertices", lambda m, b, v: m.element_vertices(v), "element", "elements"),
    ("Mesh.insert_vertex", lambda m, b, v: m.insert_vertex(v, [0.2, 0.3, 0.5]), "element", "elements"),
    ("Body.element_stiffness", lambda m, b, v: b.element_stiffness(v, np.zeros((9, 2))), "row", "cells"),
]
ID_IDS = [i[0] for i in IDS]


def limit_of(kind: str, mesh) -> int:
    return {"points": mesh.n_points, "cells": mesh.n_cells, "elements": 2**31}[kind]


@pytest.mark.parametrize("entry, call, name, kind", IDS, ids=ID_IDS)
@pytest.mark.parametrize("bad", [-1, None, BIG, np.int64(BIG), np.uint64(BEYOND_INT64)], ids=repr)
def test_an_id_out_of_range_names_the_argument_and_the_real_value(entry, call, name, kind, bad):
    """None stands for the limit itself: n_points, n_cells, or 2**31 for element ids."""
    mesh, body = sheet()
    before = mesh.cells.copy()
    limit = limit_of(kind, mesh)
    value = limit if bad is None else int(bad)
    refused(lambda: call(mesh, body, limit if bad is None else bad), f"{name} {value} does not exist",
                f"0..{limit - 1}")
    np.testing.assert_array_equal(mesh.cells, before)


@pytest.mark.parametrize("entry, call, name, kind", IDS, ids=ID_IDS)
@pytest.mark.parametrize("bad", [True, 1.5, np.float64(4.0), "4"], ids=repr)
def test_an_id_that_is_no_integer_is_refused(entry, call, name, kind, bad):
    mesh, body = sheet()
    refused(lambda: call(mesh, body, bad), f"{name} must be an integer index, got {bad!r}")


@pytest.mark.parametrize("convert", [int, np.int32, np.int64, np.uint64, np.uint16], ids=lambda c: c.__name__)
def test_ids_at_the_edges_of_their_range_still_work(convert):
    mesh, body = sheet()
    n = mesh.n_points
    assert len(mesh.star(convert(0))) == 2 and len(mesh.star(convert(n - 1))) == 2  # corners (0, 0) and (1, 1)
    assert body.element_stiffness(convert(mesh.n_cells - 1), np.zeros((n, 2))).shape == (6, 6)
    assert body.element_stiffness(convert(0), np.zeros((n, 2))).shape == (6, 6)
    last = int(mesh.cell_ids[-1])
    np.testing.assert_array_equal(mesh.element_vertices(convert(last)), mesh.cells[-1])
    assert mesh.is_locally_delaunay(convert(4), convert(n - 1))
    new = mesh.add_vertex(np.array([0, n - 1], dtype=convert), [0.5, 0.5])
    mesh.move_vertex(convert(new), point=(0.5, 0.25))
    mesh.remove_vertex(convert(new))
    assert mesh.split_edge(convert(4), convert(n - 1))
    mesh.validate()


# -- id arrays ------------------------------------------------------------------------------------
# (id, call(mesh, body, array), argument name, a valid array the bad entry is put into)
ARRAYS = [
    ("Mesh.dissect", lambda m, b, a: m.dissect(a.reshape(1, 2)), "faces", [4, 8]),
    ("Mesh.add_vertex", lambda m, b, a: m.add_vertex(a, [0.5, 0.5]), "parents", [0, 8]),
    ("Mesh.move_vertex", lambda m, b, a: m.move_vertex(4, a, [0.5, 0.5]), "parents", [4, 8]),
    ("Mesh.snap_vertex", lambda m, b, a: m.snap_vertex(4, a, [0.5, 0.5]), "parents", [4, 8]),
    ("Body.fix", lambda m, b, a: b.fix(a), "vertices", [0, 8]),
    ("Body.slide", lambda m, b, a: b.slide(a, (1.0, 0.0)), "vertices", [0, 8]),
    ("Body.release", lambda m, b, a: b.release(a), "vertices", [0, 8]),
    ("Body.add_nodal_force", lambda m, b, a: b.add_nodal_force(a, (1.0, 0.0)), "vertices", [0, 8]),
    ("Body.set_nodal_forces", lambda m, b, a: b.set_nodal_forces(a, (1.0, 0.0)), "vertices", [0, 8]),
]
ARRAY_IDS = [a[0] for a in ARRAYS]


def position(name: str, entry: str) -> str:
    return f"{name}[0, 1]" if entry == "Mesh.dissect" else f"{name}[1]"


@pytest.mark.parametrize("entry, call, name, good", ARRAYS, ids=ARRAY_IDS)
@pytest.mark.parametrize("bad, dtype", [(BEYOND_INT64, np.uint64), (2**64 - 1, np.uint64), (BIG, np.int64),
                                        (-1, np.int64), (-(2**63), np.int64), (-1, np.int8), (9, np.uint64),
                                        (9, np.int32)], ids=repr)
def test_an_id_array_names_the_first_bad_entry_its_position_and_real_value(entry, call, name, good, bad, dtype):
    mesh, body = sheet()
    before = mesh.cells.copy()
    array = np.array([good[0], bad], dtype=dtype)
    message = refused(lambda: call(mesh, body, array), f"{position(name, entry)} = {bad} is", "not a vertex of the mesh")
    assert "-9223372036854775803" not in message or bad == -9223372036854775803
    if bad > np.iinfo(np.int64).max:
        assert "beyond int64" in message
    np.testing.assert_array_equal(mesh.cells, before)


@pytest.mark.parametrize("entry, call, name, good", ARRAYS, ids=ARRAY_IDS)
@pytest.mark.parametrize("dtype", [np.float64, bool, object], ids=lambda d: np.dtype(d).name)
def test_an_id_array_that_is_no_integer_array_is_refused(entry, call, name, good, dtype):
    mesh, body = sheet()
    if dtype is bool and entry.startswith("Body."):
        pytest.skip("a Body takes a boolean vertex mask")
    refused(lambda: call(mesh, body, np.array(good, dtype=dtype)), name)


@pytest.mark.parametrize("entry, call, name, good", ARRAYS, ids=ARRAY_IDS)
@pytest.mark.parametrize("dtype", [np.uint64, np.uint8, np.int32, np.int64], ids=lambda d: np.dtype(d).name)
def test_id_arrays_within_range_still_work_in_any_integer_dtype(entry, call, name, good, dtype):
    mesh, body = sheet()
    call(mesh, body, np.array(good, dtype=dtype))  # 0 and the last vertex, 8
    mesh.validate()


def test_the_issue_cases():
    mesh, body = sheet()
    refused(lambda: mesh.refine_uniform(2**40), "levels", str(2**40), "0..27")
    refused(lambda: snede.StaticSolver(body, "cg", max_iterations=2**40), "max_iterations", str(2**40))
    message = refused(lambda: mesh.dissect(np.array([[0, 2**63 + 5]], dtype=np.uint64)),
                          "9223372036854775813", "not a vertex of the mesh")
    assert "-9223372036854775803" not in message
    refused(lambda: rectangle((1, 1), (2**40, 2)), "too large", "32-bit")


# -- the cells of a new mesh ----------------------------------------------------------------------
def test_cells_beyond_int64_are_named_with_their_real_value_and_position():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    message = refused(lambda: snede.Mesh(points, np.array([[0, 1, BEYOND_INT64]], dtype=np.uint64)),
                          "cells[0, 2] = 9223372036854775813", "int64")
    assert "-9223372036854775803" not in message
    refused(lambda: snede.Mesh(points, np.array([[0, 1, BIG]])), str(BIG), "cell 0")  # the engine's check
    assert snede.Mesh(points, np.array([[0, 1, 2]], dtype=np.uint64)).n_cells == 1


# -- the helpers themselves -----------------------------------------------------------------------
def test_count_helper():
    assert _checks.count(np.uint64(5), "n") == 5 and type(_checks.count(np.int16(5), "n")) is int
    assert _checks.count(0, "n") == 0 and _checks.count(INT32_MAX, "n") == INT32_MAX
    assert _checks.count(BIG, "n", 1, None) == BIG
    assert _checks.count(np.array(3), "n") == 3  # a 0-d array from numpy arithmetic
    refused(lambda: _checks.count(INT32_MAX + 1, "n"), "n must be at most 2147483647, got 2147483648", "0..2147483647")
    refused(lambda: _checks.count(np.bool_(True), "n"), "n must be a non-negative integer", "True")
    refused(lambda: _checks.count(5, "k", 1, 4, ": why"), "k must be at most 4, got 5 (a positive integer in 1..4: why)")


def test_index_array_helper():
    out = _checks.index_array(np.array([[1, 2], [3, 0]], dtype=np.uint32), "faces", 4)
    assert out.dtype == np.int64 and out.flags.c_contiguous and out.shape == (2, 2)
    assert _checks.index_array(np.array([2**63 - 1, 0], dtype=np.uint64), "x").tolist() == [2**63 - 1, 0]
    refused(lambda: _checks.index_array(np.array([[1, 2], [4, 0]]), "faces", 4, "a vertex"),
                "faces[1, 0] = 4 is not a vertex (faces must hold 0..3)")
    refused(lambda: _checks.index_array([0.0], "x"), "x must hold integer indices, got dtype float64")
    refused(lambda: _checks.index_array(np.array([0, BEYOND_INT64], dtype=np.uint64), "x"),
                "x[1] = 9223372036854775813 is beyond int64")


def test_size_helper():
    _checks.size(INT32_MAX, INT32_MAX, "divisions (1, 1)")
    refused(lambda: _checks.size(INT32_MAX + 1, 1, "divisions (7, 7)"), "divisions (7, 7) would make a mesh too large",
                "2147483648 vertices")
    refused(lambda: _checks.size(1, INT32_MAX + 1, "divisions (7, 7)"), "too large", "2147483648 cells")
