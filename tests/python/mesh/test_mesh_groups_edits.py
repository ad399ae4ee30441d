"""Adversarial tests of named groups (issue 34; python/snede/mesh_groups.py) through random,
seeded sequences of mesh edits, bad input and edge cases (the cutters' groups:
cutting/test_cutters_keep_groups.py; bodies loaded by groups: fem/test_group_loads.py).

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
from mesh_group_checks import boundary_keys, cell_measure, check, face_measure, interior_on_plane, label_partition


def edges_of(mesh):
    k = mesh.cell_dim + 1
    pairs = np.concatenate([mesh.cells[:, [i, j]] for i, j in itertools.combinations(range(k), 2)])
    return np.unique(np.sort(pairs, axis=1), axis=0)


def boundary_vertices(mesh):
    return np.unique(mesh.boundary_faces())


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
