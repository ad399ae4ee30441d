"""Multiple incisions on surfaces (§5.3.2): a segment scalpel cutting a curved surface in
several places. A fold cut once gives two incisions; a crest met from outside branches
(Figure 5.12c, 5.14); incisions that meet end together (annihilation, Figure 5.13); a path
crossing its own incision leaves and enters again. The outcome is checked by what the
surface becomes: which pieces it falls into and on which side of the scalpel's sweep each
piece lies. Random scalpels over folds keep every triangle touching at most one active node."""
import numpy as np
import pytest

import snede
from surface_checks import (along, bell_normal, check_surface, components, folded,
                            mean_edge, up, vertical_scalpels)


def graph_normal(slope_x):
    """The upward normal of z = f(x) (slope_x = f')."""
    return lambda p: np.c_[-slope_x(p[:, 0]), np.zeros(len(p)), np.ones(len(p))]


def cut_checked(mesh, scalpels, normal):
    cutter = snede.SurfaceCutter(mesh)
    h = mean_edge(mesh)
    total = snede.PlanarCutResult()
    for scalpel in scalpels:
        total = total + cutter.move(scalpel)
        check_surface(mesh, cutter, normal, h)
    return cutter, total


def split_by_plane_y(mesh, cutter, y0):
    """The surface falls into two pieces, one on each side of the plane y = y0. The lips are
    on the plane to within ε_entry: an entry or exit within ε_entry (ε_exit) of a vertex
    starts or ends there (the thesis's fix-up), and a move cut short leaves the active node
    behind the scalpel."""
    pieces = components(mesh)
    assert len(pieces) == 2
    y = [mesh.points[p, 1] for p in pieces]
    lower, upper = sorted(y, key=np.mean)
    slack = max(cutter.eps_entry, cutter.eps_exit)
    assert lower.max() <= y0 + slack and upper.min() >= y0 - slack


def test_folded_sheet_cut_once_gives_two_incisions():
    """A vertical scalpel crossing the fold pierces both layers: two entries at once, two
    incisions, two exits; the lower layer, the upper layer's tail and the rest (joined by the
    crease) come apart."""
    mesh = folded()
    path = along(np.array([[0.2, -0.2], [0.25, 0.5], [0.2, 1.2]]), snede.SurfaceCutter(folded()).eps_edge)
    cutter, total = cut_checked(mesh, [[[x, y, 1.0], [x, y, -1.0]] for x, y in path], None)
    assert (total.entries, total.exits) == (2, 2)
    # Each incision stays in its layer to rounding (the nodes' heights are interpolated, so
    # 0.3 may come out an ulp either side): every height within 1e-12 of a layer, both layers cut.
    heights = mesh.points[np.unique(cutter.incision_edges()), 2]
    layer = np.abs(heights[:, None] - [0.0, 0.3]).argmin(axis=1)
    np.testing.assert_allclose(heights, np.array([0.0, 0.3])[layer], rtol=0, atol=1e-12)
    assert set(layer) == {0, 1}
    assert len(components(mesh)) == 3


@pytest.mark.parametrize("y0", [0.45, 0.5], ids=["between-vertices", "through-vertices"])
def test_fold_met_at_its_crease_branches_onto_both_layers(y0):
    """Figure 5.14: a vertical scalpel pushed towards the fold's crease from outside meets it
    (Figure 5.12c), branches onto the upper and the lower layer, and both branches leave
    through the free edges: the sheet falls into two pieces either side of the plane y = y0.
    The sheet is twice as fine as folded()'s: on that one, whose crease is three triangles
    across, the lower branch at y0 = 0.5 sticks where the crease's long triangles meet the
    layer (a known limit)."""
    mesh = snede.meshing.folded_sheet(divisions=(20, 16))
    scalpels = [[[x, y0, -1.0], [x, y0, 1.0]] for x in np.linspace(0.8, -0.2, 100)]
    cutter, total = cut_checked(mesh, scalpels, None)
    assert (total.entries, total.branches, total.exits, total.annihilations) == (1, 1, 2, 0)
    split_by_plane_y(mesh, cutter, y0)


@pytest.mark.parametrize("y0", [0.47, 0.5], ids=["between-vertices", "through-vertices"])
def test_crest_met_from_outside_branches(y0):
    """A horizontal scalpel lowered onto a ridge z = 0.3 − 1.2 (x − ½)² meets its crest from
    outside (Figure 5.12c): one entry, which branches down both flanks and leaves through
    both sides; the ridge falls into two pieces either side of the plane y = y0."""
    mesh = snede.meshing.height_field(lambda x, y: 0.3 - 1.2 * (x - 0.5) ** 2, divisions=(16, 16))
    scalpels = [[[-0.1, y0, z], [1.1, y0, z]] for z in np.linspace(0.5, -0.1, 80)]
    cutter, total = cut_checked(mesh, scalpels, graph_normal(lambda x: -2.4 * (x - 0.5)))
    assert (total.entries, total.branches, total.exits, total.annihilations) == (1, 1, 2, 0)
    split_by_plane_y(mesh, cutter, y0)


@pytest.mark.parametrize("y0", [0.47, 0.5], ids=["between-vertices", "through-vertices"])
def test_incisions_meeting_in_a_valley_annihilate(y0):
    """The same scalpel lowered into a valley z = 1.2 (x − ½)² enters at both rims; the two
    incisions meet at the bottom and end there together (Figure 5.13): one boundary across."""
    mesh = snede.meshing.height_field(lambda x, y: 1.2 * (x - 0.5) ** 2, divisions=(16, 16))
    scalpels = [[[-0.1, y0, z], [1.1, y0, z]] for z in np.linspace(0.5, -0.1, 80)]
    cutter, total = cut_checked(mesh, scalpels, graph_normal(lambda x: 2.4 * (x - 0.5)))
    assert (total.entries, total.branches, total.exits, total.annihilations) == (2, 0, 0, 1)
    assert cutter.active_nodes == []
    split_by_plane_y(mesh, cutter, y0)


def test_horizontal_scalpel_cuts_the_cap_off_the_bell():
    """A horizontal scalpel at height 0.2 pushed across Figure 5.19's bell meets its front
    flank from outside, branches around it and the branches meet behind: the cap above the
    level z = 0.2 comes off, every one of its vertices at or above that level and every other
    vertex at or below it."""
    mesh = snede.meshing.gaussian_bell()
    scalpels = [[[-0.1, y, 0.2], [1.1, y, 0.2]] for y in np.linspace(-0.2, 1.2, 120)]
    cutter, total = cut_checked(mesh, scalpels, bell_normal)
    assert (total.entries, total.branches, total.annihilations) == (1, 1, 1)
    pieces = sorted(components(mesh), key=len)
    assert len(pieces) == 2
    cap, base = (mesh.points[p, 2] for p in pieces)
    assert cap.min() >= 0.2 - 1e-12 and base.max() <= 0.2 + 1e-12


def test_path_crossing_its_own_incision_leaves_and_enters_again():
    """A vertical scalpel on a flat square: in from the left, up, left and down across its own
    first leg, out at the bottom. It leaves through the first incision's lip and enters
    through the other lip, so the loop it closed cuts out the square it enclosed, and the
    bottom-left corner comes off too: three pieces. Their corners are where the path turns
    to within its sampling step (an incision turns along a chord)."""
    mesh = snede.meshing.height_field(lambda x, y: 0 * x, divisions=(12, 12))
    path = along(np.array([[-0.2, 0.3], [0.7, 0.3], [0.7, 0.7], [0.3, 0.7], [0.3, -0.2]]), 0.02)
    cutter, total = cut_checked(mesh, vertical_scalpels(path), up)
    assert total.entries == 2 and total.exits == 2
    pieces = components(mesh)
    assert len(pieces) == 3
    boxes = sorted((np.r_[mesh.points[p, :2].min(0), mesh.points[p, :2].max(0)] for p in pieces), key=np.sum)
    np.testing.assert_allclose(boxes[0], [0, 0, 0.3, 0.3], atol=0.02)  # the corner
    np.testing.assert_allclose(boxes[1], [0.3, 0.3, 0.7, 0.7], atol=0.02)  # the enclosed square
    np.testing.assert_allclose(boxes[2], [0, 0, 1, 1], atol=1e-12)


def ridge():
    return snede.meshing.height_field(lambda x, y: 0.3 - 1.2 * (x - 0.5) ** 2, divisions=(16, 16))


def random_sweep(rng, step):
    """Both ends of the scalpel along random polylines through a box around the unit square,
    at most `step` apart from one position to the next: scalpels at every slant, lying on the
    surface, crossing folds, crests and earlier incisions."""
    corners = rng.uniform([-0.3, -0.3, -0.3], [1.3, 1.3, 0.6], (2, 5, 3))
    ends = [along(c, step) for c in corners]
    n = min(map(len, ends))
    return np.stack([ends[0][:n], ends[1][:n]], axis=1)


@pytest.mark.parametrize("surface, normal", [(snede.meshing.gaussian_bell, bell_normal),
                                             (ridge, graph_normal(lambda x: -2.4 * (x - 0.5))), (folded, None)],
                         ids=["bell", "ridge", "fold"])
@pytest.mark.parametrize("seed", range(8))
def test_random_scalpels_keep_the_surface_valid(surface, normal, seed):
    """Every move of a random scalpel keeps the surface valid, unfolded, with incisions on the
    boundary and no triangle touching two active nodes; the runs enter, and cut."""
    mesh = surface()
    cutter = snede.SurfaceCutter(mesh)
    scalpels = [s for s in random_sweep(np.random.default_rng(seed), cutter.eps_edge) if not np.allclose(s[0], s[1])]
    h = mean_edge(mesh)
    total = snede.PlanarCutResult()
    for scalpel in scalpels:
        total = total + cutter.move(scalpel)
        check_surface(mesh, cutter, normal, h)
    assert total.moves == len(scalpels) and total.entries >= 1


def rotation(axis, angle):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def test_a_membrane_moved_rigidly_is_cut_as_it_lies():
    """The cut works in deformed coordinates: a bell membrane whose state is a rigid motion
    (turned 40° about a slanted axis and shifted), cut by the bell-cap scalpels moved the same
    way, is cut exactly as the bare bell is by the unmoved scalpels: the same events, the same
    triangles on the same reference points (to rounding), and the displacement it carries is
    still the rigid motion at every vertex, new ones included."""
    turn, shift = rotation([1.0, 2.0, 0.5], np.radians(40)), np.array([0.3, -0.2, 0.7])
    scalpels = np.array([[[-0.1, y, 0.2], [1.1, y, 0.2]] for y in np.linspace(-0.2, 1.2, 120)])
    bare = snede.meshing.gaussian_bell()
    _, expected = cut_checked(bare, scalpels, bell_normal)

    mesh = snede.meshing.gaussian_bell()
    body = snede.Body(mesh, snede.NeoHookean(1e4, 0.3), thickness=1e-3)
    body.displacement = mesh.points @ turn.T + shift - mesh.points
    cutter = snede.SurfaceCutter(body)
    total = snede.PlanarCutResult()
    for scalpel in scalpels @ turn.T + shift:
        total = total + cutter.move(scalpel)
    for event in ("entries", "branches", "annihilations", "exits", "flips", "nodes_removed", "nodes_inserted"):
        assert getattr(total, event) == getattr(expected, event), event
    assert mesh.n_cells == bare.n_cells
    ours = np.sort(np.round(mesh.points[mesh.cells], 9).reshape(len(mesh.cells), -1), axis=0)
    theirs = np.sort(np.round(bare.points[bare.cells], 9).reshape(len(bare.cells), -1), axis=0)
    np.testing.assert_allclose(ours, theirs, atol=1e-8)
    live = mesh.live_vertices
    np.testing.assert_allclose(body.displacement[live], mesh.points[live] @ turn.T + shift - mesh.points[live], atol=1e-12)
