"""snede.Mesh(points, cells): every kind of bad input is refused with a ValueError that names
the problem and the offending index or value; inverted cells are re-oriented."""
import math
import re
import sys

import numpy as np
import pytest

import snede

TET = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
TRI = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def signed_volumes(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """det[x1 - x0, ..., xd - x0] / d! for each row, computed here independently of the engine."""
    points = np.asarray(points, dtype=float)
    corners = points[cells]  # (n, d+1, d)
    edges = corners[:, 1:, :] - corners[:, :1, :]
    dim = points.shape[1]
    return np.linalg.det(edges) / (2.0 if dim == 2 else 6.0)


def raises_value_error(points, cells, *fragments):
    """Mesh(points, cells) raises ValueError whose message contains every fragment."""
    with pytest.raises(ValueError) as info:
        snede.Mesh(points, cells)
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
    return message


# -- shapes ---------------------------------------------------------------------------------
def test_points_one_dimensional():
    raises_value_error(np.zeros(6), [[0, 1, 2]], "points", "shape", "(6,)")


def test_points_with_four_columns():
    raises_value_error(np.zeros((4, 4)), [[0, 1, 2, 3]], "points", "(4, 4)")


def test_points_with_one_column():
    raises_value_error(np.zeros((4, 1)), [[0, 1]], "points", "(4, 1)")


@pytest.mark.parametrize(
    "points, cells, expected_columns",
    [(TET, [[0, 1]], 4), (TET, [[0, 1, 2, 3, 0]], 4), (TRI, [[0, 1, 2, 0]], 3), (TRI, [[0, 1]], 3)],
)
def test_cells_with_wrong_column_count(points, cells, expected_columns):
    given = np.asarray(cells).shape
    raises_value_error(points, cells, "cells", f"(n_cells, {expected_columns})", str(given))


def test_cells_one_dimensional():
    raises_value_error(TET, [0, 1, 2, 3], "cells", "(4,)")


# -- dtypes ---------------------------------------------------------------------------------
def test_cells_float():
    raises_value_error(TET, np.array([[0.0, 1.0, 2.0, 3.0]]), "cells", "integer", "float64")


def test_cells_bool():
    raises_value_error(TET, np.ones((1, 4), dtype=bool), "cells", "integer", "bool")


@pytest.mark.parametrize("dtype, name", [(complex, "complex128"), (object, "object"), (str, "<U"), (bool, "bool")])
def test_points_non_real_dtype(dtype, name):
    raises_value_error(TET.astype(dtype), [[0, 1, 2, 3]], "points", "real", name)


def test_integer_points_are_accepted():
    mesh = snede.Mesh(TET.astype(np.int32), [[0, 1, 2, 3]])
    assert mesh.points.dtype == np.float64
    np.testing.assert_array_equal(mesh.points, TET)


def test_integer_cell_dtypes_are_accepted():
    for dtype in (np.int32, np.uint16, np.int64, np.uint64):
        mesh = snede.Mesh(TET, np.array([[0, 1, 2, 3]], dtype=dtype))
        assert mesh.n_cells == 1


# -- indices --------------------------------------------------------------------------------
def test_negative_vertex_index():
    cells = [[0, 1, 2, 3], [0, 1, -2, 3]]
    points = np.vstack([TET, [[1.0, 1.0, 1.0]]])
    message = raises_value_error(points, cells, "-2")
    assert re.search(r"\bcell 1\b", message), message


def test_too_large_vertex_index():
    points = np.vstack([TET, [[1.0, 1.0, 1.0]]])  # 5 points: valid ids 0..4
    message = raises_value_error(points, [[0, 1, 2, 3], [1, 2, 3, 4], [0, 2, 5, 3]], "5", "0..4")
    assert re.search(r"\bcell 2\b", message), message


def test_vertex_index_equal_to_n_points_in_2d():
    message = raises_value_error(TRI, [[0, 1, 3]], "3", "0..2")
    assert re.search(r"\bcell 0\b", message), message


def test_vertex_index_beyond_int64():
    raises_value_error(TET, np.array([[0, 1, 2, 2**63 + 5]], dtype=np.uint64), "int64")


def test_repeated_vertex_in_a_cell():
    message = raises_value_error(np.vstack([TET, [[1.0, 1.0, 1.0]]]), [[1, 2, 3, 4], [0, 1, 2, 1]], "repeats", "1")
    assert re.search(r"\bcell 1\b", message), message


def test_repeated_vertex_in_a_triangle():
    raises_value_error(TRI, [[2, 0, 2]], "cell 0", "repeats vertex 2")


# -- coordinates ----------------------------------------------------------------------------
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_coordinate(bad):
    points = TET.copy()
    points[2, 1] = bad
    message = raises_value_error(points, [[0, 1, 2, 3]], "point 2", "non-finite")
    assert ("nan" in message) if np.isnan(bad) else ("inf" in message)


def test_non_finite_coordinate_in_unused_point():
    """A non-finite point is refused even when no cell uses it (it would poison a Vec)."""
    points = np.vstack([TRI, [[np.nan, 0.0]]])
    raises_value_error(points, [[0, 1, 2]], "point 3")


# -- degenerate cells -----------------------------------------------------------------------
def test_collinear_triangle():
    points = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [0.0, 1.0]])
    message = raises_value_error(points, [[0, 1, 3], [0, 1, 2]], "zero area")
    assert re.search(r"\bcell 1\b", message), message


def test_coplanar_tetrahedron():
    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0, 0, 1.0]])
    message = raises_value_error(points, [[0, 1, 2, 4], [0, 1, 2, 3]], "zero volume")
    assert re.search(r"\bcell 1\b", message), message


def test_nearly_coplanar_tetrahedron_within_rounding_is_refused():
    points = TET.copy()
    points[3] = [0.25, 0.25, 1e-17]
    raises_value_error(points, [[0, 1, 2, 3]], "cell 0", "zero volume")


def test_thin_but_real_tetrahedron_is_kept():
    points = TET.copy()
    points[3] = [0.25, 0.25, 1e-6]
    mesh = snede.Mesh(points, [[0, 1, 2, 3]])
    np.testing.assert_allclose(mesh.quality().volume, [1e-6 / 6], rtol=1e-9)


# -- empty ----------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "points, cells, fragment",
    [
        (np.zeros((0, 3)), np.zeros((0, 4), dtype=np.int64), "points is empty"),
        (TET, np.zeros((0, 4), dtype=np.int64), "cells is empty"),
        (TRI, np.zeros((0, 3), dtype=np.int64), "cells is empty"),
        ([], [], "points"),
    ],
)
def test_empty_arrays(points, cells, fragment):
    raises_value_error(points, cells, fragment)


# -- connectivity ---------------------------------------------------------------------------
def test_face_shared_by_three_triangles():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1.0], [0.5, -1.0], [0.7, 2.0]])
    message = raises_value_error(points, [[0, 1, 2], [1, 0, 3], [0, 1, 4]], "shared by 3 cells", "manifold")
    assert re.search(r"<0 1>", message), message  # the face, by its vertices


def test_face_shared_by_three_tetrahedra():
    points = np.vstack([TET, [[0.2, 0.2, -1.0], [0.3, 0.3, 2.0]]])
    # Face (0, 1, 2) belongs to all three cells.
    message = raises_value_error(points, [[0, 1, 2, 3], [0, 2, 1, 4], [0, 1, 2, 5]], "shared by 3 cells")
    assert re.search(r"<0 1 2>", message), message


def test_triangles_overlapping_across_shared_edge():
    # Both apexes above the edge 0-1: the triangles overlap.
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1.0], [0.3, 2.0]])
    message = raises_value_error(points, [[0, 1, 2], [0, 1, 3]], "overlap", "cells 0 and 1")
    assert re.search(r"<0 1>", message), message


def test_triangles_overlapping_even_when_one_was_given_clockwise():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 1.0], [0.3, 2.0]])
    raises_value_error(points, [[0, 1, 2], [1, 0, 3]], "overlap")


def test_tetrahedra_overlapping_across_shared_face():
    points = np.vstack([TET, [[0.1, 0.1, 2.0]]])
    raises_value_error(points, [[0, 1, 2, 3], [0, 1, 2, 4]], "overlap", "cells 0 and 1")


@pytest.mark.parametrize(
    "points, cells",
    [
        (TET, [[0, 1, 2, 3], [0, 1, 2, 3]]),
        (TET, [[0, 1, 2, 3], [1, 0, 2, 3]]),  # same cell, other orientation
        (TET, [[0, 1, 2, 3], [2, 3, 0, 1]]),
        (SQUARE, [[0, 1, 2], [2, 1, 0]]),
    ],
)
def test_duplicated_cell(points, cells):
    message = raises_value_error(points, cells, "same vertices")
    assert re.search(r"cells \d+ and \d+", message), message


def test_triangles_on_either_side_of_an_edge_are_fine():
    mesh = snede.Mesh(SQUARE, [[0, 1, 2], [0, 2, 3]])
    assert mesh.n_cells == 2 and mesh.n_reoriented == 0
    mesh.validate()


# -- orientation ----------------------------------------------------------------------------
def test_negative_tetrahedron_is_reoriented():
    cells = np.array([[1, 0, 2, 3]])
    assert signed_volumes(TET, cells)[0] < 0  # the input really is inverted
    mesh = snede.Mesh(TET, cells)
    assert mesh.n_reoriented == 1
    assert sorted(mesh.cells[0]) == [0, 1, 2, 3]
    np.testing.assert_allclose(signed_volumes(mesh.points, mesh.cells), [1 / 6], rtol=1e-14)
    np.testing.assert_allclose(mesh.quality().volume, [1 / 6], rtol=1e-14)
    mesh.validate()


def test_negative_triangle_is_reoriented():
    cells = np.array([[0, 2, 1]])
    assert signed_volumes(TRI, cells)[0] < 0
    mesh = snede.Mesh(TRI, cells)
    assert mesh.n_reoriented == 1
    np.testing.assert_allclose(signed_volumes(mesh.points, mesh.cells), [0.5], rtol=1e-14)
    assert mesh.quality().volume[0] == pytest.approx(0.5)


@pytest.mark.parametrize("dim", [2, 3])
def test_mixed_orientations_in_a_structured_mesh(dim):
    """Flip a random half of the cells of a structured mesh: exactly those are counted, every
    output row is positive, and the cells are the same vertex sets as before."""
    base = snede.meshing.box((1, 1, 1), (3, 3, 3)) if dim == 3 else snede.meshing.rectangle((1, 1), (5, 4))
    cells = base.cells.copy()
    assert np.all(signed_volumes(base.points, cells) > 0)
    flip = np.random.default_rng(7).random(len(cells)) < 0.5
    cells[flip, 0], cells[flip, 1] = cells[flip, 1], cells[flip, 0].copy()
    assert np.all((signed_volumes(base.points, cells) < 0) == flip)

    mesh = snede.Mesh(base.points, cells)
    assert mesh.n_reoriented == int(flip.sum()) > 0
    volumes = signed_volumes(mesh.points, mesh.cells)
    assert np.all(volumes > 0)
    assert np.all(mesh.quality().volume > 0)
    np.testing.assert_allclose(np.sort(volumes), np.sort(signed_volumes(base.points, base.cells)), rtol=1e-12)
    as_sets = lambda c: sorted(map(tuple, np.sort(c, axis=1)))  # noqa: E731
    assert as_sets(mesh.cells) == as_sets(base.cells)
    mesh.validate()


def test_positive_cells_are_not_counted():
    mesh = snede.meshing.box((1, 1, 1), (2, 2, 2))
    again = snede.Mesh(mesh.points, mesh.cells)
    assert again.n_reoriented == 0
    np.testing.assert_array_equal(again.cells, mesh.cells)


def test_input_arrays_are_not_modified():
    points = TET.copy()
    cells = np.array([[1, 0, 2, 3]])
    snede.Mesh(points, cells)
    np.testing.assert_array_equal(cells, [[1, 0, 2, 3]])
    np.testing.assert_array_equal(points, TET)


@pytest.mark.parametrize("dim", [2, 3])
def test_duplicated_cell_inside_a_mesh_is_named_as_a_duplicate(dim):
    """A copy of cell 0 appended to a structured mesh: both rows are named."""
    base = snede.meshing.box((1, 1, 1), (2, 2, 2)) if dim == 3 else snede.meshing.rectangle((1, 1), (3, 3))
    cells = np.vstack([base.cells, base.cells[:1]])
    message = raises_value_error(base.points, cells, "same vertices")
    n = len(base.cells)
    assert re.search(rf"cells ({n} and 0|0 and {n})\b", message), message


@pytest.mark.parametrize("dim", [2, 3])
def test_duplicated_interior_cell_is_named_as_a_duplicate(dim):
    base = snede.meshing.box((1, 1, 1), (2, 2, 2)) if dim == 3 else snede.meshing.rectangle((1, 1), (3, 3))
    cells = np.vstack([base.cells, base.cells[5:6]])
    raises_value_error(base.points, cells, "same vertices", "5", str(len(base.cells)))


UNIT_CELLS = {  # cell dimension: (corners, measure of the unit cell)
    2: (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), 0.5),
    3: (np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), 1.0 / 6.0),
}


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("scale", [1e-310, 1e-200, 1e-150, 1e-100, 1.0, 1e100, 1e150, 1e200, 1e300])
def test_a_mesh_is_accepted_where_its_measures_are_doubles_and_refused_with_the_reason_elsewhere(scale, dim):
    corners, unit_measure = UNIT_CELLS[dim]
    # Independent of the engine: whether scale^dim · unit measure is a normal double, in logarithms.
    log_measure = dim * math.log10(scale) + math.log10(unit_measure)
    representable = math.log10(sys.float_info.min) < log_measure < math.log10(sys.float_info.max)
    if representable:
        mesh = snede.Mesh(scale * corners, [list(range(dim + 1))])
        mesh.validate()
        assert mesh.quality().volume[0] == pytest.approx(unit_measure * scale**dim, rel=1e-12)
    else:
        units = "smaller" if log_measure < 0 else "larger"
        with pytest.raises(ValueError, match=f"cell 0's (area|volume) is too .* in {units} units"):
            snede.Mesh(scale * corners, [list(range(dim + 1))])
    flat = scale * np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    with pytest.raises(ValueError, match="zero"):
        snede.Mesh(flat, [[0, 1, 2]])
