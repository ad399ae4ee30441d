"""Adversarial tests of named groups (issue 34; python/snede/mesh_groups.py) through random,
seeded sequences of mesh edits, the cutters, bad input, edge cases and bodies.

The invariants a group keeps: a boundary group's measure (area, length in 2D) is unchanged by
edits that keep the boundary's geometry (refinement, splits, insertions, dissection, collapses of
an interior vertex with t = 0), a cell group's measure by edits that keep each cell inside one old
cell (refinement, splits, insertions, dissection); groups that partitioned the cells still do after
every edit; boundary groups hold only boundary faces; "incision" measures twice the dissected
faces; group_vertices are live vertices."""
import itertools

import numpy as np
import pytest

import snede


# -- measures ----------------------------------------------------------------------------------
def simplex_measure(corners):
    """(n, k, d) corners → (n,) measures of the simplices (k − 1 dimensional) in d-space."""
    corners = np.asarray(corners, dtype=float)
    if len(corners) == 0:
        return np.zeros(0)
    edges = corners[:, 1:] - corners[:, :1]
    gram = np.einsum("nid,njd->nij", edges, edges)
    k = corners.shape[1] - 1
    return np.sqrt(np.maximum(np.linalg.det(gram), 0.0)) / float(np.prod(np.arange(1, k + 1)))


def face_measure(mesh, faces):
    return simplex_measure(mesh.points[np.asarray(faces, dtype=np.int64).reshape(-1, mesh.cell_dim)]).sum()


def cell_measure(mesh, rows):
    return simplex_measure(mesh.points[mesh.cells[np.asarray(rows, dtype=np.int64)]]).sum()


def boundary_keys(mesh):
    return {tuple(f) for f in np.sort(mesh.boundary_faces(), axis=1).tolist()}


# -- invariant checks --------------------------------------------------------------------------
def check(mesh, partition, face_expect, cell_expect, incision_expect=None, rel=1e-12):
    """Every invariant named in the module docstring; ``partition`` names cell groups that cover
    the cells once; ``face_expect`` / ``cell_expect`` map names to expected measures (None: not
    checked this time)."""
    cells, faces = mesh.cell_groups, mesh.boundary_groups
    keys = boundary_keys(mesh)
    live = np.flatnonzero(mesh.live_vertices)
    for name, group in faces.items():
        assert group.ndim == 2 and group.shape[1] == mesh.cell_dim, name
        missing = {tuple(f) for f in np.sort(group, axis=1).tolist()} - keys
        assert not missing, f"boundary group {name!r} holds non-boundary faces {sorted(missing)[:3]}"
        assert np.all(np.isin(mesh.group_vertices(name), live)), name
    for name, rows in cells.items():
        assert rows.ndim == 1 and (len(rows) == 0 or (rows.min() >= 0 and rows.max() < mesh.n_cells)), name
        assert np.all(np.isin(mesh.group_vertices(name), live)), name
    if partition:
        together = np.concatenate([cells[name] for name in partition])
        assert len(together) == mesh.n_cells == len(np.unique(together)), "cell groups no longer partition the mesh"
    for name, expected in face_expect.items():
        if expected is not None:
            assert face_measure(mesh, faces[name]) == pytest.approx(expected, rel=rel, abs=1e-14), name
    for name, expected in cell_expect.items():
        if expected is not None:
            assert cell_measure(mesh, cells[name]) == pytest.approx(expected, rel=rel, abs=1e-14), name
    if incision_expect is not None:
        assert face_measure(mesh, faces["incision"]) == pytest.approx(incision_expect, rel=rel, abs=1e-14)


def edges_of(mesh):
    k = mesh.cell_dim + 1
    pairs = np.concatenate([mesh.cells[:, [i, j]] for i, j in itertools.combinations(range(k), 2)])
    return np.unique(np.sort(pairs, axis=1), axis=0)


def boundary_vertices(mesh):
    return np.unique(mesh.boundary_faces())


def interior_on_plane(mesh, axis, value, extra=None):
    """Interior faces lying on the plane x[axis] = value (optionally further restricted)."""
    def inside(x):
        keep = np.isclose(x[:, axis], value, atol=1e-12)
        return keep if extra is None else keep & extra(x)
    return mesh.faces_where(inside)


def label_partition(mesh, rng, n_groups=3):
    """Cell groups "g0".."g{n-1}" partitioning the cells by a random split of the centroid's
    first coordinate, and returns their names."""
    centroid = mesh.points[mesh.cells].mean(axis=1)
    cuts = np.sort(rng.uniform(centroid[:, 0].min(), centroid[:, 0].max(), n_groups - 1))
    which = np.searchsorted(cuts, centroid[:, 0])
    names = [f"g{k}" for k in range(n_groups)]
    for k, name in enumerate(names):
        mesh.add_cell_group(name, which == k)
    return names


# -- random edit sequences ---------------------------------------------------------------------
class Sequence:
    """Applies random edits, tracking which invariants each must keep."""

    def __init__(self, mesh, rng, partition, faces, cells):
        self.mesh, self.rng, self.partition = mesh, rng, partition
        self.faces = {name: face_measure(mesh, mesh.boundary_groups[name]) for name in faces}
        self.cells = {name: cell_measure(mesh, mesh.cell_groups[name]) for name in cells}
        self.incision = 0.0
        self.log = []

    def check(self):
        """The invariants, and "incision" is exactly the boundary faces on the plane x = 0.5
        (every dissection here is on it; the outer boundary has none there), at most twice the
        area dissected (a dissected face at the cut's front whose corners no split reaches stays
        closed: then less)."""
        try:
            check(self.mesh, self.partition, self.faces, self.cells)
            m = self.mesh
            on_plane = m.faces_where(lambda x: np.isclose(x[:, 0], 0.5, atol=1e-12), interior=False)
            lips = {tuple(f) for f in np.sort(on_plane, axis=1).tolist()} & boundary_keys(m)
            incision = m.boundary_groups["incision"]
            assert {tuple(f) for f in np.sort(incision, axis=1).tolist()} == lips
            assert face_measure(m, incision) <= self.incision * (1 + 1e-12) + 1e-14
        except AssertionError as error:
            raise AssertionError(f"after edits {self.log}: {error}") from None

    def cell_volumes_changed(self):
        """After an edit whose new cells straddle old ones (a collapse, a flip) the groups'
        measures change, and keep changing with later refinement until a re-basing
        (see test_refinement_after_a_non_nesting_edit_keeps_group_volumes): from here on only
        the partition is checked, until ``rebase``."""
        self.cells = {name: None for name in self.cells}

    def rebase(self):
        """Adding a group makes the mesh as it is the reference: every measure must be kept
        from here on, those of the groups before too."""
        m = self.mesh
        before = {name: rows.copy() for name, rows in m.cell_groups.items()}
        faces_before = {name: np.sort(np.sort(f, axis=1), axis=0) for name, f in m.boundary_groups.items()}
        m.add_cell_group("rebased", [int(self.rng.integers(m.n_cells))])
        for name, rows in before.items():
            if name == "rebased":
                continue
            np.testing.assert_array_equal(m.cell_groups[name], rows)
        for name, faces in faces_before.items():
            np.testing.assert_array_equal(np.sort(np.sort(m.boundary_groups[name], axis=1), axis=0), faces)
        self.cells = {name: cell_measure(m, m.cell_groups[name]) for name in set(self.cells) | {"rebased"}}
        return True

    # The edits.  Each returns whether it changed the mesh.
    def refine_uniform(self):
        if self.mesh.n_cells > 1500:
            return False
        return self.mesh.refine_uniform(1) > 0

    def refine_around(self):
        m = self.mesh
        lo, hi = m.points[m.live_vertices].min(axis=0), m.points[m.live_vertices].max(axis=0)
        point = self.rng.uniform(lo, hi)
        if m.is_surface:  # a point on the surface: a random cell's centroid
            point = m.points[m.cells[self.rng.integers(m.n_cells)]].mean(axis=0)
        return m.refine_around(point, float(self.rng.uniform(0.15, 0.4)) * (hi - lo).max()) > 0

    def refine_near_segment(self):
        m = self.mesh
        lo, hi = m.points[m.live_vertices].min(axis=0), m.points[m.live_vertices].max(axis=0)
        a, b = self.rng.uniform(lo, hi), self.rng.uniform(lo, hi)
        return m.refine_near_segment(a, b, 0.3 * (hi - lo).max(), 0.05) > 0

    def split_edge(self):
        m = self.mesh
        edges = edges_of(m)
        a, b = edges[self.rng.integers(len(edges))]
        return bool(m.split_edge(int(a), int(b), float(self.rng.uniform(0.2, 0.8))))

    def insert_vertex(self):
        m = self.mesh
        row = int(self.rng.integers(m.n_cells))
        w = self.rng.uniform(0.2, 1.0, m.cell_dim + 1)
        return bool(m.insert_vertex(int(m.cell_ids[row]), w / w.sum()))

    def flip_edge(self):
        m = self.mesh
        if m.cell_dim != 2:
            return False
        edges = edges_of(m)
        for a, b in edges[self.rng.permutation(len(edges))[:20]]:
            if m.is_surface and not self.flat_around(a, b):
                continue  # a flip across a crease changes the surface (test_a_flip_across_a_crease_...)
            if m.flip_edge(int(a), int(b)):
                self.cell_volumes_changed()
                return True
        return False

    def flat_around(self, a, b):
        m = self.mesh
        pair = m.cells[np.sum((m.cells == a) | (m.cells == b), axis=1) == 2]
        corners = m.points[pair]
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        return len(pair) == 2 and np.linalg.norm(np.cross(normals[0], normals[1])) < 1e-12

    def collapse_edge(self):
        """Collapse an edge whose ``gone`` end is interior, keeping ``keep`` in place: the
        boundary's geometry stays, the cells' groups may change."""
        m = self.mesh
        on_boundary = np.zeros(m.n_points, dtype=bool)
        on_boundary[boundary_vertices(m)] = True
        if m.is_surface:
            return False
        edges = edges_of(m)
        for a, b in edges[self.rng.permutation(len(edges))[:30]]:
            for keep, gone in ((a, b), (b, a)):
                if not on_boundary[gone] and m.collapse_edge(int(keep), int(gone), 0.0):
                    assert not m.live_vertices[gone]
                    self.cell_volumes_changed()
                    return True
        return False

    def add_and_remove_vertex(self):
        m = self.mesh
        cell = m.cells[self.rng.integers(m.n_cells)]
        vertex = m.add_vertex(cell, np.full(len(cell), 1.0 / len(cell)))
        m.remove_vertex(vertex)
        return True

    def dissect(self):
        """Dissect the interior faces on a grid plane (the plane x = 0.5 of the unit boxes and
        rectangles), a random half of the domain in y."""
        m = self.mesh
        cut = float(self.rng.uniform(0.3, 0.7))
        faces = interior_on_plane(m, 0, 0.5, lambda x: x[:, 1] > cut)
        if len(faces) == 0:
            return False
        measure = face_measure(m, faces)
        m.dissect(faces)
        self.incision += 2 * measure
        return True

    def batch(self):
        with self.mesh.batch():
            a = self.split_edge()
            b = self.insert_vertex()
            c = self.refine_around()
        return a or b or c


def run_sequence(mesh, seed, steps, edits, partition, faces, cells):
    rng = np.random.default_rng(seed)
    sequence = Sequence(mesh, rng, partition, faces, cells)
    sequence.check()
    for _ in range(steps):
        edit = edits[rng.integers(len(edits))]
        getattr(sequence, edit)()
        sequence.log.append(edit)
        sequence.check()
    return sequence


VOLUME_EDITS = ["refine_uniform", "refine_around", "refine_near_segment", "split_edge", "insert_vertex",
                "collapse_edge", "add_and_remove_vertex", "dissect", "batch", "split_edge", "insert_vertex", "rebase"]


@pytest.mark.parametrize("seed", range(1, 9))
def test_random_edits_of_a_box_keep_its_groups(seed):
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 2], 0.0), interior=False))
    mesh.add_boundary_group("left", mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.0), interior=False))
    # A group of scattered boundary faces (not a whole side).
    boundary = mesh.boundary_faces()
    mesh.add_boundary_group("scattered", boundary[np.random.default_rng(seed).permutation(len(boundary))[:7]])
    partition = label_partition(mesh, np.random.default_rng(seed))
    mesh.add_cell_group("odd", np.arange(1, mesh.n_cells, 2))  # overlaps the partition
    sequence = run_sequence(mesh, seed, 16, VOLUME_EDITS, partition,
                            ["bottom", "left", "scattered"], partition + ["odd"])
    assert face_measure(mesh, mesh.boundary_groups["bottom"]) == pytest.approx(1.0, rel=1e-12)
    assert face_measure(mesh, mesh.boundary_groups["left"]) == pytest.approx(1.0, rel=1e-12)
    assert mesh.n_cells > 48 and len(sequence.log) == 16


@pytest.mark.parametrize("seed", range(11, 19))
def test_random_edits_of_a_rectangle_keep_its_groups(seed):
    mesh = snede.meshing.rectangle((1.0, 1.0), (4, 4))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 1], 0.0), interior=False))
    mesh.add_boundary_group("right", mesh.faces_where(lambda x: np.isclose(x[:, 0], 1.0), interior=False))
    partition = label_partition(mesh, np.random.default_rng(seed), 4)
    edits = VOLUME_EDITS + ["flip_edge", "flip_edge"]
    run_sequence(mesh, seed, 20, edits, partition, ["bottom", "right"], partition)
    assert face_measure(mesh, mesh.boundary_groups["bottom"]) == pytest.approx(1.0, rel=1e-12)
    assert face_measure(mesh, mesh.boundary_groups["right"]) == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("seed", range(21, 25))
def test_random_edits_of_a_surface_keep_its_cell_groups(seed):
    surface, _ = snede.meshing.boundary_surface(snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)))
    assert len(surface.boundary_faces()) == 0  # closed: only cell groups
    partition = label_partition(surface, np.random.default_rng(seed))
    top = surface.points[surface.cells].mean(axis=1)[:, 2] > 1 - 1e-9
    surface.add_cell_group("top", top)
    edits = ["refine_uniform", "split_edge", "insert_vertex", "add_and_remove_vertex", "flip_edge", "rebase"]
    run_sequence(surface, seed, 10, edits, partition, [], partition + ["top"])
    assert cell_measure(surface, surface.cell_groups["top"]) == pytest.approx(1.0, rel=1e-12)
    assert cell_measure(surface, np.arange(surface.n_cells)) == pytest.approx(6.0, rel=1e-12)


def test_remove_vertex_by_flips_keeps_a_partition_of_a_rectangle():
    mesh = snede.meshing.rectangle((1.0, 1.0), (4, 4))
    mesh.add_boundary_group("top", mesh.faces_where(lambda x: np.isclose(x[:, 1], 1.0), interior=False))
    partition = label_partition(mesh, np.random.default_rng(9), 2)
    interior = np.setdiff1d(np.arange(mesh.n_points), boundary_vertices(mesh))
    removed = 0
    for vertex in interior[:4]:
        removed += bool(mesh.remove_vertex_by_flips(int(vertex)))
        check(mesh, partition, {"top": 1.0}, {})
    assert removed > 0
    assert cell_measure(mesh, np.concatenate([mesh.cell_groups[n] for n in partition])) == pytest.approx(1.0)


def test_refinement_after_a_collapse_keeps_group_volumes():
    """Groups resolved after a collapse (whose cells straddle the reference's) become the
    reference: a later refinement keeps the group's volume. (Without a query between the two
    edits the children would fall back into the stale reference cells: 0.375 -> 0.5.)"""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    mesh.add_cell_group("low", mesh.points[mesh.cells].mean(axis=1)[:, 2] < 0.5)
    np.testing.assert_array_equal(mesh.points[13], (0.5, 0.5, 0.5))
    assert mesh.collapse_edge(0, 13, 0.0)
    before = cell_measure(mesh, mesh.cell_groups["low"])
    mesh.refine_uniform(1)
    assert cell_measure(mesh, mesh.cell_groups["low"]) == pytest.approx(before, rel=1e-12)


def test_refinement_after_a_flip_keeps_group_areas():
    """As for a collapse: resolved after the flip, the group keeps its area through refinement."""
    sheet = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    sheet.add_cell_group("a", [0])
    assert sheet.flip_edge(0, 4)
    before = cell_measure(sheet, sheet.cell_groups["a"])
    sheet.refine_uniform(2)
    assert cell_measure(sheet, sheet.cell_groups["a"]) == pytest.approx(before, rel=1e-12)


def test_a_flip_across_a_crease_keeps_every_surface_cell_in_a_group():
    surface, _ = snede.meshing.boundary_surface(snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)))
    surface.add_cell_group("all", np.ones(surface.n_cells, dtype=bool))
    assert surface.flip_edge(0, 4)
    surface.refine_uniform(1)
    np.testing.assert_array_equal(surface.points[[0, 1]], [[0.0, 0.0, 0.0], [0.0, 0.0, 0.5]])
    assert surface.flip_edge(0, 1)
    assert len(surface.cell_groups["all"]) == surface.n_cells


def test_dissection_of_a_box_forms_incision_of_twice_the_area_and_survives_refinement():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (4, 4, 4))
    mesh.add_boundary_group("top", mesh.faces_where(lambda x: np.isclose(x[:, 2], 1.0), interior=False))
    partition = label_partition(mesh, np.random.default_rng(10), 2)
    faces = interior_on_plane(mesh, 0, 0.5, lambda x: x[:, 2] > 0.5 - 1e-9)
    dissected = face_measure(mesh, faces)
    assert dissected == pytest.approx(0.5)  # the upper half of the plane, all but the outer rim's
    mesh.dissect(faces)
    check(mesh, partition, {"top": 1.0}, {}, 2 * dissected)
    assert len(mesh.boundary_groups["incision"]) == 2 * len(faces)
    mesh.refine_uniform(1)
    check(mesh, partition, {"top": 1.0}, {}, 2 * dissected)
    # Adding a group after the cut (a re-basing) keeps the incision and the others.
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 2], 0.0), interior=False))
    check(mesh, partition, {"top": 1.0, "bottom": 1.0}, {}, 2 * dissected)
    more = interior_on_plane(mesh, 0, 0.5, lambda x: x[:, 2] < 0.25)
    mesh.dissect(more)
    check(mesh, partition, {"top": 1.0, "bottom": 1.0}, {}, 2 * dissected + 2 * face_measure(mesh, more))


# -- cutters -----------------------------------------------------------------------------------
def test_tetrahedral_cutter_opens_an_incision_and_keeps_the_user_groups():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (6, 6, 6))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 2], 0.0), interior=False))
    mesh.add_boundary_group("back", mesh.faces_where(lambda x: np.isclose(x[:, 1], 1.0), interior=False))
    partition = label_partition(mesh, np.random.default_rng(11), 2)
    volumes = {name: cell_measure(mesh, mesh.cell_groups[name]) for name in partition}
    cutter = snede.TetrahedralCutter(mesh)
    # The scalpel enters through y = 0 and stops at y = 0.6, cutting the plane x = 0.43.
    report = cutter.cut([np.array([[0.43, y, -1.0], [0.43, y, 2.0]]) for y in (-0.5, 0.2, 0.6)])
    assert report.faces_dissected > 0
    incision = mesh.boundary_groups["incision"]
    assert len(incision) > 0
    # The cutter's own incision faces and the group are the same faces.
    assert {tuple(f) for f in np.sort(incision, axis=1).tolist()} == \
        {tuple(f) for f in np.sort(cutter.incision_faces(), axis=1).tolist()}
    check(mesh, partition, {"bottom": 1.0, "back": 1.0}, {})
    # Snapping moves vertices onto the plane: the total volume stays, each group's up to the
    # slabs the snaps moved (a cell keeps its group by its centroid's old place).
    assert cell_measure(mesh, np.arange(mesh.n_cells)) == pytest.approx(1.0, rel=1e-12)
    for name in partition:
        assert cell_measure(mesh, mesh.cell_groups[name]) == pytest.approx(volumes[name], abs=2.0 / 6)
    assert np.all(np.abs(mesh.points[np.unique(incision), 0] - 0.43) < 1e-12)


def test_delaunay_cutter_opens_an_incision_and_keeps_the_user_groups():
    mesh = snede.meshing.rectangle((1.0, 1.0), (8, 8))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 1], 0.0), interior=False))
    mesh.add_boundary_group("left", mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.0), interior=False))
    partition = label_partition(mesh, np.random.default_rng(12), 2)
    cutter = snede.DelaunayCutter(mesh)
    for y in np.linspace(1.2, 0.45, 40):  # enters through y = 1 and stops inside
        cutter.move([0.43, y])
    incision = mesh.boundary_groups["incision"]
    assert len(incision) > 0
    length = face_measure(mesh, incision)
    assert length > 2 * 0.4  # both lips, about 0.55 long each
    check(mesh, partition, {"bottom": 1.0, "left": 1.0}, {})
    assert cell_measure(mesh, np.arange(mesh.n_cells)) == pytest.approx(1.0, rel=1e-12)


def test_tetrahedral_cutter_on_a_curved_body_puts_only_the_lips_in_incision():
    mesh = snede.meshing.ellipsoid(h=0.012, seed=1)
    mesh.add_boundary_group("skin", mesh.boundary_faces())
    cutter = snede.TetrahedralCutter(mesh)
    report = cutter.cut([np.array([[0.005, y, -0.1], [0.005, y, 0.1]]) for y in (-0.06, 0.0, 0.01)])
    assert report.faces_dissected > 0
    keys = lambda faces: {tuple(f) for f in np.sort(faces, axis=1).tolist()}  # noqa: E731
    assert keys(mesh.boundary_groups["incision"]) == keys(cutter.incision_faces())
    assert keys(mesh.boundary_groups["skin"]) == keys(mesh.boundary_faces()) - keys(cutter.incision_faces())


def test_a_moved_boundary_vertex_keeps_its_faces_in_their_group():
    sheet = snede.meshing.rectangle((1.0, 1.0), (4, 4))
    sheet.add_boundary_group("bottom", sheet.faces_where(lambda x: np.isclose(x[:, 1], 0.0), interior=False))
    vertex = int(np.flatnonzero(np.isclose(sheet.points[:, 1], 0.0) & np.isclose(sheet.points[:, 0], 0.5))[0])
    sheet.move_vertex(vertex, point=(0.5, -0.05))
    assert len(sheet.boundary_groups["incision"]) == 0
    assert len(sheet.boundary_groups["bottom"]) == 4


# -- bad input ---------------------------------------------------------------------------------
@pytest.fixture
def box():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 2], 0.0), interior=False))
    return mesh


@pytest.mark.parametrize("name", [3, None, b"bytes", ("a",), ""])
def test_names_must_be_non_empty_strings(box, name):
    with pytest.raises(ValueError, match="non-empty string"):
        box.add_cell_group(name, [0])
    with pytest.raises(ValueError, match="non-empty string"):
        box.add_boundary_group(name, box.boundary_faces()[:1])


@pytest.mark.parametrize("rows, match", [
    ([48], "indices into the 48"), ([-1], "indices into the 48"), ([0.5], "indices into the 48"),
    ([[0, 1]], "indices into the 48"), ("abc", "indices into the 48"), (None, "indices into the 48"),
    (np.ones(47, dtype=bool), r"boolean mask must have shape \(48,\)"),
    ([True, False], r"boolean mask must have shape \(48,\)"),
])
def test_bad_rows_name_the_group_and_the_problem(box, rows, match):
    with pytest.raises(ValueError, match=f"cell group 'x'.*{match}"):
        box.add_cell_group("x", rows)
    assert "x" not in box.cell_groups


@pytest.mark.parametrize("faces, match", [
    ([[0, 1, 10 ** 12]], "not boundary faces"), ([[-1, 0, 1]], "not boundary faces"),
    ([[0.0, 1.0, 2.0]], r"must be \(n, 3\) vertex indices"), ([0, 1, 2], r"must be \(n, 3\) vertex indices"),
    (np.ones((2, 3), dtype=bool), r"must be \(n, 3\) vertex indices"), ([[0, 1]], r"must be \(n, 3\) vertex indices"),
])
def test_bad_faces_name_the_group_and_the_problem(box, faces, match):
    with pytest.raises(ValueError, match=f"boundary group 'x'.*{match}"):
        box.add_boundary_group("x", faces)
    assert "x" not in box.boundary_groups


def test_interior_faces_and_incision_are_refused_and_leave_the_groups_as_they_were(box):
    before = {name: faces.copy() for name, faces in box.boundary_groups.items()}
    interior = box.faces_where(lambda x: np.isclose(x[:, 0], 0.5))
    with pytest.raises(ValueError, match="'inner'.*not boundary faces"):
        box.add_boundary_group("inner", np.vstack([box.boundary_faces()[:2], interior[:1]]))
    with pytest.raises(ValueError, match="'incision' is the group of the faces cuts open"):
        box.add_boundary_group("incision", box.boundary_faces()[:1])
    after = box.boundary_groups
    assert set(after) == set(before) == {"bottom", "incision"}
    for name in before:
        np.testing.assert_array_equal(after[name], before[name])


def test_missing_groups_are_key_errors_listing_the_known_ones(box):
    body = snede.Body(box, snede.LinearElastic(1e6, 0.3))
    for call in (lambda: box.group_vertices("top"), lambda: body.fix("top"),
                 lambda: body.add_nodal_force("top", (0.0, 0.0, 1.0))):
        with pytest.raises(KeyError, match="no group 'top'.*bottom, incision"):
            call()
    box.add_cell_group("core", [0, 1])
    with pytest.raises(KeyError, match="no boundary group 'core'"):
        body.add_traction("core", (0.0, 0.0, 1.0))


def test_a_cell_group_named_incision_is_refused_or_reachable(box):
    try:
        box.add_cell_group("incision", [0])
    except ValueError:
        return
    np.testing.assert_array_equal(box.group_vertices("incision"), np.sort(box.cells[0]))


def test_a_name_shared_by_a_cell_and_a_boundary_group_is_refused(box):
    box.add_cell_group("a", [0])
    with pytest.raises(ValueError):
        box.add_boundary_group("a", box.boundary_faces()[:1])


# -- edge cases --------------------------------------------------------------------------------
def test_groups_added_after_vertex_removal_and_edits_keep_the_old_ones():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (3, 3, 3))
    mesh.add_cell_group("low", mesh.points[mesh.cells].mean(axis=1)[:, 2] < 1 / 3)
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 2], 0.0), interior=False))
    mesh.refine_around((0.5, 0.5, 0.1), 0.2)
    interior = np.setdiff1d(np.arange(mesh.n_points), boundary_vertices(mesh))
    collapsed = 0
    for gone in interior:  # collapse an interior vertex away: a removed id the groups must skip
        neighbours = np.unique(mesh.cells[np.any(mesh.cells == gone, axis=1)])
        if any(mesh.collapse_edge(int(keep), int(gone), 0.0) for keep in neighbours if keep != gone):
            collapsed += 1
            break
    v = mesh.add_vertex([0, 1], [0.5, 0.5])
    mesh.remove_vertex(v)
    assert collapsed and mesh.n_live_points < mesh.n_points
    low = cell_measure(mesh, mesh.cell_groups["low"])
    # A group added now re-bases: the old ones survive, measures kept.
    mesh.add_boundary_group("top", mesh.faces_where(lambda x: np.isclose(x[:, 2], 1.0), interior=False))
    mesh.add_cell_group("high", mesh.points[mesh.cells].mean(axis=1)[:, 2] > 2 / 3)
    check(mesh, ["low"] * 0, {"bottom": 1.0, "top": 1.0}, {"low": low, "high": 1 / 3})
    mesh.refine_uniform(1)
    check(mesh, [], {"bottom": 1.0, "top": 1.0}, {"low": low, "high": 1 / 3})
    assert set(mesh.cell_groups) == {"low", "high"}
    assert set(mesh.boundary_groups) == {"bottom", "top", "incision"}


def test_re_adding_a_group_replaces_it_and_keeps_the_others():
    mesh = snede.meshing.rectangle((1.0, 1.0), (4, 4))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 1], 0.0), interior=False))
    mesh.add_cell_group("all", np.ones(mesh.n_cells, dtype=bool))
    mesh.refine_uniform(2)
    mesh.add_cell_group("all", [0])  # replaced
    assert len(mesh.cell_groups["all"]) == 1
    mesh.refine_uniform(1)
    assert cell_measure(mesh, mesh.cell_groups["all"]) == pytest.approx(1 / 32 / 4, rel=1e-12)
    assert face_measure(mesh, mesh.boundary_groups["bottom"]) == pytest.approx(1.0, rel=1e-12)


def test_empty_groups_stay_empty_and_listed():
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    mesh.add_cell_group("none", np.zeros(mesh.n_cells, dtype=bool))
    mesh.add_cell_group("none either", np.zeros(0, dtype=np.int64))
    mesh.add_boundary_group("no faces", np.zeros((0, 2), dtype=np.int64))
    mesh.refine_uniform(2)
    assert len(mesh.cell_groups["none"]) == len(mesh.cell_groups["none either"]) == 0
    assert mesh.boundary_groups["no faces"].shape == (0, 2)
    assert len(mesh.group_vertices("none")) == 0
    body = snede.Body(mesh, snede.LinearElastic(1e6, 0.3), thickness=0.01)
    body.add_traction("no faces", (1.0, 0.0))
    assert np.abs(body.external_forces()).max() == 0


@pytest.mark.parametrize("dim", [2, 3])
def test_groups_on_a_single_cell(dim):
    points = np.vstack([np.zeros(dim), np.eye(dim)])
    mesh = snede.Mesh(points, np.arange(dim + 1)[None])
    mesh.add_cell_group("only", [0])
    mesh.add_boundary_group("one", mesh.boundary_faces()[:1])
    face = face_measure(mesh, mesh.boundary_groups["one"])
    cell = cell_measure(mesh, [0])
    mesh.refine_uniform(3)
    check(mesh, ["only"], {"one": face}, {"only": cell})
    assert len(mesh.boundary_groups["one"]) > 1 and len(mesh.boundary_groups["incision"]) == 0


def test_meshes_without_groups_and_copies_have_none():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    assert mesh.cell_groups == {} and mesh.boundary_groups == {}
    mesh.refine_uniform(1)
    assert mesh.cell_groups == {} and mesh.boundary_groups == {}
    with pytest.raises(KeyError, match="none"):
        mesh.group_vertices("anything")
    mesh.add_cell_group("half", np.arange(mesh.n_cells // 2))
    surface, _ = snede.meshing.boundary_surface(mesh)
    assert surface.cell_groups == {} and surface.boundary_groups == {}
    sheet = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    sheet.add_cell_group("a", [0])
    assert snede.meshing.lifted(sheet, lambda x, y: np.c_[x, y, np.zeros(len(x))]).cell_groups == {}
    assert snede.Mesh(mesh.points, mesh.cells).cell_groups == {}


# -- bodies ------------------------------------------------------------------------------------
@pytest.mark.parametrize("formulation", ["p1", "smoothed"])
def test_a_box_body_is_held_and_loaded_by_groups_after_refinement(formulation):
    mesh = snede.meshing.box((1.0, 0.25, 0.25), (4, 1, 1))
    mesh.add_boundary_group("clamped", mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.0), interior=False))
    mesh.add_boundary_group("loaded", mesh.faces_where(lambda x: np.isclose(x[:, 0], 1.0), interior=False))
    mesh.refine_around((1.0, 0.125, 0.125), 0.1)
    body = snede.Body(mesh, snede.LinearElastic(1e6, 0.3), formulation=formulation)
    body.fix("clamped")
    body.add_traction("loaded", (0.0, 0.0, -160.0))  # 160 Pa on 0.0625 m²: 10 N
    np.testing.assert_allclose(body.external_forces().sum(axis=0), (0.0, 0.0, -10.0), atol=1e-12)
    result = snede.StaticSolver(body, "cg", rtol=1e-8).solve()
    assert result.converged
    clamped = mesh.group_vertices("clamped")
    assert len(clamped) >= 4 and np.all(body.displacement[clamped] == 0)
    assert body.displacement[mesh.group_vertices("loaded"), 2].max() < 0


@pytest.mark.parametrize("formulation", ["p1", "smoothed"])
def test_a_plane_stress_sheet_is_loaded_by_length_times_thickness(formulation):
    sheet = snede.meshing.rectangle((2.0, 0.5), (8, 2))
    sheet.add_boundary_group("left", sheet.faces_where(lambda x: np.isclose(x[:, 0], 0.0), interior=False))
    sheet.add_boundary_group("right", sheet.faces_where(lambda x: np.isclose(x[:, 0], 2.0), interior=False))
    sheet.refine_uniform(1)
    body = snede.Body(sheet, snede.LinearElastic(1e6, 0.3), thickness=0.01, formulation=formulation)
    body.fix("left")
    body.add_traction("right", (3000.0, -1000.0))  # on 0.5 m × 0.01 m: (15, −5) N
    np.testing.assert_allclose(body.external_forces().sum(axis=0), (15.0, -5.0), atol=1e-12)
    result = snede.StaticSolver(body, "cg", rtol=1e-8).solve()
    assert result.converged
    assert np.all(body.displacement[sheet.group_vertices("left")] == 0)
    right = sheet.group_vertices("right")
    assert np.sum(body.external_forces()[right] * body.displacement[right]) > 0  # the load does work


def test_a_body_is_loaded_by_its_group_after_a_dissection():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (4, 4, 4))
    mesh.add_boundary_group("bottom", mesh.faces_where(lambda x: np.isclose(x[:, 2], 0.0), interior=False))
    body = snede.Body(mesh, snede.LinearElastic(1e6, 0.3), formulation="smoothed")
    mesh.dissect(interior_on_plane(mesh, 0, 0.5, lambda x: x[:, 2] > 0.5 - 1e-9))
    body.fix("bottom")
    body.add_traction("incision", (0.0, 0.0, -1.0))
    total = face_measure(mesh, mesh.boundary_groups["incision"])
    assert total == pytest.approx(1.0, rel=1e-12)  # both lips of the 0.5 m² cut
    np.testing.assert_allclose(body.external_forces().sum(axis=0), (0.0, 0.0, -total), atol=1e-12)
    assert snede.StaticSolver(body, "cg", rtol=1e-8).solve().converged
