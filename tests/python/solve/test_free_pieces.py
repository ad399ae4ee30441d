"""Free pieces (issue 32 item 3): a static solve needs every piece of the body held, not just
the body as a whole. A piece cut free of every support has rigid motions, and the static
problem then has no unique solution: Newton spun to its iteration limit on such a plate and
linear CG stopped with an indefinite matrix. Every static method refuses it at once, with an
error naming the piece; after ``body.fix_free_pieces()`` (or fixing some of its vertices) it
solves. The pieces and their constrained components are checked against a count made here, and
the rigid motions their constraints stop against the rank of those constraints' rows computed
here (issue 48 item 1: a count of components let a piece held on a line turn about it)."""
import re

import numpy as np
import pytest

import snede

RIGID_MOTIONS = {2: 3, 3: 6}  # by the displacement dimension: membranes have 3D's six

NOT_HELD = re.compile(r"not held: piece (\d+) of (\d+) \((\d+) cells, vertex (\d+) among them\) has (\d+) constrained "
                      r"displacement components, which stop (\d+) of its (\d+) rigid motions")


def face_pieces(mesh):
    """Piece label per cell row, pieces being cells joined through shared faces (union-find)."""
    cells = mesh.cells
    parent = np.arange(len(cells))

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    faces = np.concatenate([np.sort(np.delete(cells, k, axis=1), axis=1) for k in range(cells.shape[1])])
    owners = np.tile(np.arange(len(cells)), cells.shape[1])
    order = np.lexsort(faces.T[::-1])
    faces, owners = faces[order], owners[order]
    for i in np.flatnonzero(np.all(faces[1:] == faces[:-1], axis=1)):
        parent[root(owners[i])] = root(owners[i + 1])
    return np.unique([root(i) for i in range(len(cells))], return_inverse=True)[1]


def vertex_pieces(mesh):
    """Piece label per cell row, pieces being cells joined through shared vertices."""
    cells = mesh.cells
    label = np.arange(len(cells))
    while True:  # each vertex takes the smallest label of its cells, each cell its vertices' smallest
        at_vertex = np.full(mesh.n_points, len(cells))
        np.minimum.at(at_vertex, cells.ravel(), np.repeat(label, cells.shape[1]))
        spread = at_vertex[cells].min(axis=1)
        if np.array_equal(spread, label):
            return np.unique(label, return_inverse=True)[1]
        label = spread


def constrained_components_per_piece(body, piece_of_cell):
    """Constrained displacement components per piece, from the body's own constraint table."""
    fixed, _, sliding = body._model.constraint_table()
    components = np.zeros(body.mesh.n_points, dtype=int)
    components[fixed] = body.dim
    components[sliding] = body.dim - 1
    count = np.zeros(piece_of_cell.max() + 1, dtype=int)
    for piece in range(len(count)):
        count[piece] = components[np.unique(body.mesh.cells[piece_of_cell == piece])].sum()
    return count


def refusal(body, method, preconditioner=None):
    """Solves and returns the error's parsed message; the displacement must be left as it was."""
    before = body.displacement
    with pytest.raises(ValueError) as error:
        snede.StaticSolver(body, method, preconditioner=preconditioner,
                           options_prefix=f"free_{method}_{preconditioner}_").solve()
    assert np.array_equal(body.displacement, before)
    message = str(error.value)
    assert "body.fix" in message and "fix_free_pieces" in message, message
    match = NOT_HELD.search(message)
    assert match, message
    piece, pieces, cells, vertex, components, stopped, needed = map(int, match.groups())
    return dict(piece=piece, pieces=pieces, cells=cells, vertex=vertex, components=components, stopped=stopped,
                needed=needed, message=message)


def rigid_motions_stopped(body, vertices, slides):
    """The rank of the constraints of `vertices` on the rigid motions: each fixed vertex (the
    body's constraint table) stops u(x) in every direction, a sliding one (`slides`: vertex →
    the direction the test gave it) in the directions normal to its line; u(x) = a + ω × x
    (a + ω (−y, x) in 2D). Rank by SVD."""
    fixed, _, sliding = body._model.constraint_table()
    assert set(np.intersect1d(vertices, sliding)) <= set(slides)
    rows = []
    for v in np.intersect1d(vertices, np.concatenate([fixed.ravel(), list(slides)]).astype(np.int64)):
        x = body.mesh.points[v] - body.mesh.points[vertices[0]]
        if body.dim == 2:
            motions = np.array([[1.0, 0.0, -x[1]], [0.0, 1.0, x[0]]])
        else:
            motions = np.hstack([np.eye(3), -np.cross(np.eye(3), x)])  # row k: e_k · (ω × x) = −(e_k × x) · ω
        if v in slides:
            direction = np.asarray(slides[v], dtype=float) / np.linalg.norm(slides[v])
            motions = motions - np.outer(direction, direction) @ motions
        rows.append(motions)
    return 0 if not rows else np.linalg.matrix_rank(np.vstack(rows), tol=1e-9 * np.abs(np.vstack(rows)).max())


def check_named_piece(body, named, slides={}):
    """The named piece against the count made here: its size, that the vertex is one of its
    cells', its constrained components, the rigid motions they stop, and that it is not held."""
    label = face_pieces(body.mesh)
    assert np.array_equal(label, vertex_pieces(body.mesh))  # dissect splits the vertices it cuts through
    assert named["pieces"] == label.max() + 1
    rows = np.flatnonzero(np.any(body.mesh.cells == named["vertex"], axis=1))
    piece = label[rows[0]]
    assert np.all(label[rows] == piece)
    assert named["cells"] == np.count_nonzero(label == piece)
    assert named["components"] == constrained_components_per_piece(body, label)[piece]
    assert named["stopped"] == rigid_motions_stopped(body, np.unique(body.mesh.cells[label == piece]), slides)
    assert named["needed"] == RIGID_MOTIONS[body.dim] > named["stopped"]
    return piece


def plate_with_a_free_half(material=None):
    """A 1 × 0.5 m plate (8 × 4 squares) fixed at x = 0, dissected along x = 0.5, under gravity:
    the right half (32 triangles) hangs from nothing."""
    mesh = snede.meshing.rectangle((1.0, 0.5), (8, 4))
    assert len(mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5)))) == 5
    body = snede.Body(mesh, material or snede.LinearElastic(1e4, 0.3), thickness=0.01)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81))
    return body


def right_half(body):
    """The vertices of the right half's cells (the copies the dissection made at x = 0.5 too)."""
    cells = body.mesh.cells
    return np.unique(cells[body.mesh.points[cells, 0].mean(axis=1) > 0.5])


@pytest.mark.parametrize("method, preconditioner", [
    ("cg", "none"), ("cg", "jacobi"), ("cg", "gamg"), ("cg", "mg"), ("cg", "icc"),
    ("newton", "none"), ("newton", "jacobi"), ("newton", "gamg"), ("newton", "mg"), ("ncg", None)])
def test_a_plate_with_a_free_half_is_refused_at_once_by_every_method(method, preconditioner):
    body = plate_with_a_free_half(snede.LinearElastic(1e4, 0.3) if method == "cg" else snede.NeoHookean(1e4, 0.3))
    # The whole body has plenty of constrained components: only counting per piece finds it.
    assert constrained_components_per_piece(body, np.zeros(body.mesh.n_cells, dtype=int))[0] >= 3
    named = refusal(body, method, preconditioner)
    piece = check_named_piece(body, named)
    assert (named["cells"], named["components"], named["needed"]) == (32, 0, 3)
    assert body.mesh.points[named["vertex"], 0] >= 0.5
    assert "1 of the 2 pieces is not held" in named["message"]
    assert piece == face_pieces(body.mesh)[np.flatnonzero(np.isin(body.mesh.cells, right_half(body)).all(axis=1))[0]]


def test_a_piece_held_by_too_few_components_is_refused():
    body = plate_with_a_free_half()
    corner = right_half(body)[np.argmax(body.mesh.points[right_half(body), 0])]
    body.fix([corner])  # two components: the half may still turn about it
    named = refusal(body, "cg", "none")
    check_named_piece(body, named)
    assert (named["components"], named["needed"]) == (2, 3)
    body.slide([right_half(body)[0]], (1.0, 0.0))  # a third component
    result = snede.StaticSolver(body, "cg", rtol=1e-8, options_prefix="free_slide_").solve()
    assert result.converged, result


def test_fix_free_pieces_fixes_the_free_half_where_it_is_and_the_solve_converges():
    body = plate_with_a_free_half(snede.NeoHookean(1e4, 0.3))
    shift = np.zeros_like(body.displacement)
    shift[right_half(body)] = (0.01, -0.02)  # the half was moved: fixed where it is, not at rest
    body.displacement = shift
    assert body.fix_free_pieces() == 1
    fixed, anchors, _ = body._model.constraint_table()
    newly = np.isin(fixed.ravel(), right_half(body))
    assert np.count_nonzero(newly) == 3  # one of its cells
    np.testing.assert_array_equal(anchors[newly], np.tile((0.01, -0.02), (3, 1)))
    assert body.fix_free_pieces() == 0  # every piece is held now
    for method in ("newton", "ncg"):
        result = snede.StaticSolver(body, method, rtol=1e-8, options_prefix=f"free_fixed_{method}_").solve()
        assert result.converged, result


def box_cut_in_two_held_on_the_left(material):
    """A 120-cell box dissected at x = 0.6 and fixed at x = 0, under gravity: its right 48 cells are free."""
    mesh = snede.meshing.box((1.0, 0.4, 0.4), (5, 2, 2))
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.6)))
    body = snede.Body(mesh, material)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


def test_a_box_cut_in_two_with_one_side_fixed_names_the_free_side():
    body = box_cut_in_two_held_on_the_left(snede.NeoHookean(1e4, 0.3))
    named = refusal(body, "newton")
    check_named_piece(body, named)
    assert (named["cells"], named["components"], named["needed"]) == (2 * 2 * 2 * 6, 0, 6)
    assert body.mesh.points[named["vertex"], 0] >= 0.6
    # Holding the free side properly (its far end) instead: the solve converges.
    body.fix(np.isclose(body.mesh.points[:, 0], 1.0))
    result = snede.StaticSolver(body, "newton", rtol=1e-8, options_prefix="free_box_held_").solve()
    assert result.converged, result


def test_of_three_pieces_the_first_not_held_is_named_with_the_count():
    mesh = snede.meshing.box((0.9, 0.3, 0.3), (6, 2, 2))
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.3) | np.isclose(x[:, 0], 0.6)))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3))
    x = mesh.points
    body.fix(np.isclose(x[:, 0], 0.0))
    middle = np.flatnonzero((x[:, 0] > 0.3 + 1e-9) & (x[:, 0] < 0.6 - 1e-9))
    body.fix(middle[:1])  # the middle slab: 3 components of 6
    body.slide(middle[1:2], (0.0, 0.0, 1.0))  # and 2 more
    label = face_pieces(mesh)
    assert label.max() == 2 and sorted(constrained_components_per_piece(body, label)) == [0, 5, 27]
    named = refusal(body, "cg", "none")
    check_named_piece(body, named, {middle[1]: (0.0, 0.0, 1.0)})
    assert "2 of the 3 pieces are not held" in named["message"]
    assert body.fix_free_pieces() == 2
    assert np.all(constrained_components_per_piece(body, label) >= 6)
    result = snede.StaticSolver(body, "cg", rtol=1e-8, options_prefix="free_three_fixed_").solve()
    assert result.converged, result


def test_a_membrane_with_a_free_half_needs_six_components_per_piece():
    sheet = snede.meshing.rectangle((1.0, 0.5), (8, 4))
    mesh = snede.meshing.lifted(sheet, lambda x, y: np.c_[x, y, 0.1 * x * y])
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5)))
    body = snede.Body(mesh, snede.NeoHookean(1e4, 0.3), thickness=0.001)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity()
    for method in ("newton", "ncg"):
        named = refusal(body, method)
        check_named_piece(body, named)
        assert (named["cells"], named["components"], named["needed"]) == (32, 0, 6)
    # One pinned vertex (3 components) is still too few on a membrane.
    body.fix(right_half(body)[:1])
    assert refusal(body, "newton")["components"] == 3


def test_a_body_whose_pieces_are_all_held_solves_as_before():
    body = plate_with_a_free_half()
    body.fix(np.isclose(body.mesh.points[:, 0], 1.0))
    result = snede.StaticSolver(body, "cg", rtol=1e-10, options_prefix="free_both_held_").solve()
    assert result.converged, result
    # The left half hangs from x = 0 alone: as a plate of that half, made on its own.
    half = snede.meshing.rectangle((0.5, 0.5), (4, 4))
    alone = snede.Body(half, snede.LinearElastic(1e4, 0.3), thickness=0.01)
    alone.fix(np.isclose(half.points[:, 0], 0.0))
    alone.add_gravity((0.0, -9.81))
    assert snede.StaticSolver(alone, "cg", rtol=1e-10, options_prefix="free_half_alone_").solve().converged
    by_point = {tuple(p): u for p, u in zip(half.points, alone.displacement)}
    on_left_piece = np.unique(body.mesh.cells[face_pieces(body.mesh) == face_pieces(body.mesh)[0]])
    for v in on_left_piece:
        np.testing.assert_allclose(body.displacement[v], by_point[tuple(body.mesh.points[v])], rtol=1e-6, atol=1e-12)


def test_a_tetrahedral_cut_that_frees_a_piece_without_fixing_it_is_refused():
    mesh = snede.meshing.box((1, 1, 1), (4, 4, 4))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.25))
    body.fix(np.where(mesh.points[:, 0] < 1e-9)[0])
    body.add_gravity()
    cutter = snede.TetrahedralCutter(body, fix_free_pieces=False)
    cutter.move([[0.6, -1, -1], [0.6, -1, 2]])
    assert cutter.move([[0.6, 2, -1], [0.6, 2, 2]]).free_pieces == 1
    named = refusal(body, "cg", "none")
    check_named_piece(body, named)
    assert body.fix_free_pieces() == 1
    result = snede.StaticSolver(body, "cg", rtol=1e-8, options_prefix="free_tet_fixed_").solve()
    assert result.converged, result


def test_a_solve_on_mpi_ranks_refuses_a_free_piece_as_the_serial_one():
    from mpi4py import MPI
    body = box_cut_in_two_held_on_the_left(snede.LinearElastic(1e4, 0.3))
    with pytest.raises(ValueError, match=r"piece 2 of 2 \(48 cells.*fix_free_pieces"):
        snede.StaticSolver(body, "cg", comm=MPI.COMM_WORLD).solve()
    body.fix_free_pieces()
    assert snede.StaticSolver(body, "cg", rtol=1e-8, comm=MPI.COMM_WORLD).solve().converged


ONE_PIECE = re.compile(r"not held: it is one piece of (\d+) cells with (\d+) constrained displacement components, "
                       r"which stop (\d+) of its (\d+) rigid motions")


def one_piece_refusal(body):
    """(components, stopped, needed) from the refusal of a one-piece body's linear CG solve."""
    with pytest.raises(ValueError) as error:
        snede.StaticSolver(body, "cg", options_prefix="free_one_piece_").solve()
    match = ONE_PIECE.search(str(error.value))
    assert match and int(match.group(1)) == body.mesh.n_cells, str(error.value)
    assert "vertices on one line leave a solid free to turn about it" in str(error.value)
    return tuple(map(int, match.groups()[1:]))


def test_a_box_held_on_a_line_is_refused_however_many_vertices_lie_on_it():
    """Two fixed vertices are six constrained components, as many as a body has rigid motions,
    but they leave the rotation about the line through them (issue 48 item 1: CG ran to its
    iteration limit with |u| ~ 1e29). More vertices on the line stop no more; one off it does."""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3))
    body.add_gravity((0.0, 0.0, -9.81))
    x = mesh.points
    on_edge = np.flatnonzero(np.isclose(x[:, 1], 0.0) & np.isclose(x[:, 2], 0.0))  # the x axis: 3 vertices
    assert len(on_edge) == 3
    for held in (on_edge[[0, 2]], on_edge):
        body.fix(held)
        components, stopped, needed = one_piece_refusal(body)
        assert (components, stopped, needed) == (3 * len(held), 5, 6)
        assert stopped == rigid_motions_stopped(body, np.arange(mesh.n_points), {})
    body.fix(np.flatnonzero(np.all(np.isclose(x, (0.0, 1.0, 0.0)), axis=1)))
    result = snede.StaticSolver(body, "cg", rtol=1e-8, options_prefix="free_line_held_").solve()
    assert result.converged, result


@pytest.mark.parametrize("direction, held", [((0.0, 1.0), False), ((1.0, 0.0), True)])
def test_a_plate_pinned_at_a_corner_is_held_by_a_slide_only_across_the_rotation(direction, held):
    """Pinned at (0, 0) and sliding at (1, 0): three components either way, but a slide along y
    lets the plate turn about the pin, and a slide along x stops it."""
    mesh = snede.meshing.rectangle((1.0, 0.5), (4, 2))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3), thickness=0.01)
    body.add_gravity((0.0, -9.81))
    corner = lambda p: np.flatnonzero(np.all(np.isclose(mesh.points, p), axis=1))
    body.fix(corner((0.0, 0.0)))
    body.slide(corner((1.0, 0.0)), direction)
    if held:
        assert snede.StaticSolver(body, "cg", rtol=1e-8, options_prefix="free_pin_slide_").solve().converged
        return
    components, stopped, needed = one_piece_refusal(body)
    assert (components, stopped, needed) == (3, 2, 3)
    assert stopped == rigid_motions_stopped(body, np.arange(mesh.n_points), {corner((1.0, 0.0))[0]: direction})


def test_fix_free_pieces_holds_a_piece_held_on_a_line():
    """The piece cut free at x = 0.6 has two vertices of its far end fixed: fix_free_pieces holds
    it on one of its cells, and the solve converges."""
    body = box_cut_in_two_held_on_the_left(snede.NeoHookean(1e4, 0.3))
    x = body.mesh.points
    body.fix(np.flatnonzero(np.isclose(x[:, 0], 1.0) & np.isclose(x[:, 1], 0.0))[:2])
    named = refusal(body, "newton")
    check_named_piece(body, named)
    assert (named["components"], named["stopped"]) == (6, 5)
    assert body.fix_free_pieces() == 1
    result = snede.StaticSolver(body, "newton", rtol=1e-8, options_prefix="free_line_fixed_").solve()
    assert result.converged, result
