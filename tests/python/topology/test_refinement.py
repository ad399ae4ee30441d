"""Conforming bisection refinement (§6.5, Figures 6.8 and 6.13) through the Python API:
conformity, volume, similarity classes, aspect ratios, growth, state transfer in a body."""
import itertools

import numpy as np
import pytest

import snede


# -- independent checks ------------------------------------------------------------------
def total_volume(mesh) -> float:
    return float(mesh.quality().volume.sum())


def hanging_vertices(mesh) -> int:
    """Cell edges whose midpoint is a vertex of the mesh, found by coordinates."""
    points = mesh.points
    positions = {tuple(p) for p in points}
    hanging = 0
    for a, b in itertools.combinations(range(mesh.dim + 1), 2):
        middles = 0.5 * points[mesh.cells[:, a]] + 0.5 * points[mesh.cells[:, b]]
        hanging += sum(tuple(m) in positions for m in middles)
    return hanging


def similarity_classes(mesh) -> set:
    """Classes of cells congruent up to scaling: sorted squared edge lengths over the largest."""
    points = mesh.points[mesh.cells]
    squared = np.stack([((points[:, a] - points[:, b]) ** 2).sum(axis=1)
                        for a, b in itertools.combinations(range(mesh.dim + 1), 2)], axis=1)
    squared.sort(axis=1)
    return {tuple(row) for row in np.round(squared / squared[:, -1:], 8)}


def cells_containing(mesh, x) -> np.ndarray:
    """Rows of the cells whose closure contains x, by barycentric coordinates."""
    corners = mesh.points[mesh.cells]
    edges = corners[:, 1:] - corners[:, :1]
    mu = np.linalg.solve(np.transpose(edges, (0, 2, 1)), (x - corners[:, 0])[:, :, None])[:, :, 0]
    barycentric = np.column_stack([1 - mu.sum(axis=1), mu])
    return np.flatnonzero(barycentric.min(axis=1) >= -1e-10)


def longest_edges(mesh, rows) -> np.ndarray:
    points = mesh.points[mesh.cells[rows]]
    return np.max([np.linalg.norm(points[:, a] - points[:, b], axis=1)
                   for a, b in itertools.combinations(range(mesh.dim + 1), 2)], axis=0)


def assert_conforming(mesh, volume):
    mesh.validate()
    assert hanging_vertices(mesh) == 0
    assert total_volume(mesh) == pytest.approx(volume, rel=1e-13)


# -- uniform refinement ------------------------------------------------------------------
@pytest.mark.parametrize("make, n_start", [(lambda: snede.meshing.rectangle((2.0, 1.0), (4, 2)), 16),
                                           (lambda: snede.meshing.box((1.0, 2.0, 1.0), (2, 2, 2)), 48)])
def test_uniform_refinement_doubles_every_level_and_keeps_the_volume(make, n_start):
    mesh = make()
    volume = total_volume(mesh)
    assert mesh.n_cells == n_start
    for level in range(1, 5):
        assert mesh.refine_uniform() == n_start << (level - 1)
        assert mesh.n_cells == n_start << level
        assert_conforming(mesh, volume)
    assert mesh.refine_uniform(levels=2) == (n_start << 4) + (n_start << 5)
    assert mesh.n_cells == n_start << 6
    assert_conforming(mesh, volume)
    assert mesh.refine_uniform(levels=0) == 0


# -- refine-around -------------------------------------------------------------------------
def refine_in_halvings(mesh, x, k_max):
    """Refine around x to h = size / 2^k for k = 1..k_max; returns the cell count after each."""
    volume = total_volume(mesh)
    counts = []
    for k in range(1, k_max + 1):
        h = 2.0 ** -k
        before = mesh.n_cells
        assert mesh.refine_around(x, h) == mesh.n_cells - before  # each split adds one cell
        rows = cells_containing(mesh, x)
        assert len(rows) > 0 and np.all(longest_edges(mesh, rows) <= h)
        assert_conforming(mesh, volume)
        counts.append(mesh.n_cells)
    return counts


def test_refine_around_in_2d_keeps_one_right_triangle_shape_and_grows_logarithmically():
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    start_aspect = mesh.quality().aspect_ratio.min()
    counts = refine_in_halvings(mesh, np.array([0.3, 0.55]), 20)  # about 40 bisection levels
    # §6.5: every triangle is congruent to the starting ones (newest-vertex bisection allows 4).
    classes = similarity_classes(mesh)
    assert len(classes) == 1 and len(classes) <= 4
    assert mesh.quality().aspect_ratio.min() == pytest.approx(start_aspect, rel=1e-12)
    # Cells added per halving of h are the same for h = 2^-4..2^-12 as for 2^-12..2^-20:
    # growth like log(size / h); uniform refinement would multiply them by 4 per halving.
    assert (counts[19] - counts[11]) / (counts[11] - counts[3]) == pytest.approx(1.0, abs=0.25)
    assert mesh.n_cells < 1000


def test_refine_around_in_3d_keeps_three_classes_like_figure_6_13():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    start_aspect = mesh.quality().aspect_ratio.min()
    counts = refine_in_halvings(mesh, np.array([0.3, 0.55, 0.7]), 9)  # about 27 bisection levels
    # Maubach bisection of the Kuhn simplex: 3 classes (aspect ratios 0.408, 0.354, 0.354).
    assert len(similarity_classes(mesh)) == 3
    assert mesh.quality().aspect_ratio.min() == pytest.approx(start_aspect * np.sqrt(3) / 2, rel=1e-9)
    increments = np.diff(counts)
    # Once the refinement front is settled, each pair of halvings of h adds the same number
    # of cells: growth like log(size / h), where uniform refinement would multiply by 8 each.
    assert increments[4] + increments[5] == pytest.approx(increments[6] + increments[7], rel=0.1)
    assert mesh.n_cells < 5000  # uniform refinement to h = 2^-9 needs 48 · 2^24 cells


def test_refine_around_an_unstructured_tetrahedral_mesh_stays_conforming_and_bounded():
    mesh = snede.meshing.cylinder(length=0.1, radius=0.03, h=0.015, seed=1)
    n_start = mesh.n_cells
    start_aspect = mesh.quality().aspect_ratio.min()
    volume = total_volume(mesh)
    x = np.array([0.05, 0.01, 0.0])
    split = mesh.refine_around(x, 0.015 / 2 ** 5)
    assert split > 0
    assert_conforming(mesh, volume)
    assert np.all(longest_edges(mesh, cells_containing(mesh, x)) <= 0.015 / 2 ** 5)
    assert len(similarity_classes(mesh)) <= 36 * n_start  # Arnold–Mukherjee–Pouly's bound per starting cell
    assert mesh.quality().aspect_ratio.min() >= start_aspect / 10


@pytest.mark.parametrize("point, h, message", [
    ((0.5, 0.5), 0.0, "h must be positive and finite"),
    ((0.5, 0.5), -0.1, "h must be positive and finite"),
    ((0.5, 0.5), float("nan"), "h must be positive and finite"),
    ((0.5, 0.5), float("inf"), "h must be positive and finite"),
    ((0.5, 0.5, 0.5), 0.1, r"point must have shape \(2,\)"),
    ((0.5, float("nan")), 0.1, "point must be finite"),
    ((1.5, 0.5), 0.1, "outside the mesh"),
])
def test_refine_around_rejects_bad_arguments_and_leaves_the_mesh_alone(point, h, message):
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    with pytest.raises(ValueError, match=message):
        mesh.refine_around(point, h)
    assert mesh.n_cells == 8


def test_refine_uniform_rejects_negative_levels():
    with pytest.raises(ValueError, match="non-negative integer"):
        snede.meshing.rectangle((1.0, 1.0), (1, 1)).refine_uniform(-1)


# -- state in a body ---------------------------------------------------------------------------
@pytest.mark.parametrize("material", [snede.LinearElastic(1e4, 0.3), snede.NeoHookean(1e4, 0.3)],
                         ids=["linear", "neo-hookean"])
def test_a_linear_displacement_keeps_its_energy_through_refinement(material):
    mesh = snede.meshing.box((0.1, 0.05, 0.05), (4, 2, 2))
    body = snede.Body(mesh, material)
    A = np.array([[0.02, 0.01, 0.0], [-0.01, 0.03, 0.005], [0.0, 0.004, -0.02]])
    body.displacement = mesh.points @ A.T
    energy = body.energy(body.displacement)
    assert body.refine_around((0.031, 0.022, 0.017), 0.05 / 16) > 0
    mesh.validate()
    # The midpoint average of a linear field is the field: u = A·x at every new vertex.
    np.testing.assert_allclose(body.displacement, mesh.points @ A.T, atol=1e-15)
    assert body.energy(body.displacement) == pytest.approx(energy, rel=1e-12)


def test_a_body_refined_mid_simulation_keeps_its_solution_and_solves_on():
    mesh = snede.meshing.box((0.1, 0.02, 0.02), (8, 2, 2))
    body = snede.Body(mesh, snede.NeoHookean(3e4, 0.3))
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "newton", rtol=1e-9, options_prefix="refine_coarse_").solve().converged
    coarse_points, coarse_u = mesh.points, body.displacement
    internal_energy = body.energy(coarse_u)

    assert body.refine_around((0.02, 0.01, 0.01), 0.02 / 8) > 0
    u = body.displacement
    assert u.shape == (mesh.n_points, 3)
    np.testing.assert_array_equal(u[:len(coarse_u)], coarse_u)  # old vertices keep theirs
    # The refined mesh represents the coarse piecewise-linear field exactly (nested spaces):
    # the same deformation, hence the same internal energy.
    assert body.energy(u) == pytest.approx(internal_energy, rel=1e-12)
    np.testing.assert_array_equal(mesh.points[:len(coarse_points)], coarse_points)
    assert np.all(u[np.isclose(mesh.points[:, 0], 0.0)] == 0)  # new vertices on the support are fixed

    def potential_energy(b):
        return b.energy(b.displacement) - float((b.external_forces() * b.displacement).sum())

    carried_over = potential_energy(body)
    warm = snede.StaticSolver(body, "newton", rtol=1e-7, options_prefix="refine_warm_").solve()
    assert warm.converged, warm
    cold_body = snede.Body(snede.Mesh(mesh.points, mesh.cells), snede.NeoHookean(3e4, 0.3))
    cold_body.fix(np.isclose(mesh.points[:, 0], 0.0))
    cold_body.add_gravity((0.0, 0.0, -9.81))
    cold = snede.StaticSolver(cold_body, "newton", rtol=1e-7, options_prefix="refine_cold_").solve()
    assert cold.converged, cold
    # Starting from the carried-over state beats starting from zero, to the same solution:
    # it is far closer in energy than zero (the refined space is larger, so the minimum
    # drops a little further) and Newton needs fewer steps.
    minimum = potential_energy(body)
    assert minimum < carried_over < 0.0
    assert carried_over - minimum < 0.5 * (0.0 - minimum)
    assert warm.iterations < cold.iterations
    np.testing.assert_allclose(body.displacement, cold_body.displacement, atol=1e-6 * np.abs(coarse_u).max())


# -- bisection after other edits (issue 38 item 3) ------------------------------------------
def interior_edges(mesh) -> list[tuple[int, int]]:
    uses: dict[tuple[int, int], int] = {}
    for cell in mesh.cells:
        for a, b in itertools.combinations(sorted(int(v) for v in cell), 2):
            uses[(a, b)] = uses.get((a, b), 0) + 1
    return [edge for edge, n in uses.items() if n == 2]


# A triangle is flat to rounding when area ≤ 64ε·(longest edge)², the mesh's documented test.
FLAT_TO_ROUNDING = 64 * np.finfo(float).eps


def smallest_relative_area(mesh) -> float:
    """min over triangles of area / (longest edge)², in numpy: 0 for a flat triangle."""
    corners = mesh.points[mesh.cells]
    u, w = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    doubled = np.cross(u, w)
    area = 0.5 * (np.abs(doubled) if mesh.space_dim == 2 else np.linalg.norm(doubled, axis=1))
    longest = np.max([np.linalg.norm(corners[:, a] - corners[:, b], axis=1) for a, b in [(0, 1), (1, 2), (2, 0)]], axis=0)
    return float((area / longest**2).min())


@pytest.mark.parametrize("make, edits", [
    # The probe's sequences: each flip put a triangle back onto an edge the first refinement had
    # split (flat to rounding but exactly non-collinear); the next refinement inverted its children.
    (lambda: snede.meshing.gaussian_bell(divisions=10), [("refine",), ("flip", 69, 183), ("refine",)]),
    (lambda: snede.meshing.rectangle((1, 1), (5, 6)),
     [("split", 10, 17, 1e-12), ("refine",), ("flip", 25, 59), ("refine",)]),
])
def test_a_flip_onto_a_bisected_edge_is_refused_and_the_next_refinement_stays_valid(make, edits):
    mesh = make()
    for edit in edits:
        if edit[0] == "refine":
            mesh.refine_uniform(1)
        elif edit[0] == "split":
            mesh.split_edge(*edit[1:])
        else:
            result = mesh.flip_edge(*edit[1:])
            assert not result and "collinear to rounding" in result.reason
        mesh.validate()
        assert smallest_relative_area(mesh) > FLAT_TO_ROUNDING


@pytest.mark.parametrize("make", [lambda: snede.meshing.rectangle((1.0, 1.0), (4, 5)),
                                  lambda: snede.meshing.gaussian_bell(divisions=6)])
@pytest.mark.parametrize("seed", range(4))
def test_random_flips_splits_and_refinements_keep_the_mesh_valid(make, seed):
    rng = np.random.default_rng(seed)
    mesh = make()
    area = total_volume(mesh)
    for step in range(40):
        kind = rng.choice(["flip", "flip", "split", "refine"], p=[0.4, 0.2, 0.3, 0.1])
        if kind == "refine" and mesh.n_cells < 2000:
            mesh.refine_uniform(1)
        elif kind == "split":
            a, b = interior_edges(mesh)[rng.integers(len(interior_edges(mesh)))]
            mesh.split_edge(a, b, float(rng.choice([1e-12, 1e-6, 0.5, rng.uniform(0.01, 0.99)])))
        else:
            edges = interior_edges(mesh)
            mesh.flip_edge(*edges[rng.integers(len(edges))])
        mesh.validate()
        assert smallest_relative_area(mesh) > FLAT_TO_ROUNDING, f"step {step}: {kind}"
        if not mesh.is_surface:
            assert total_volume(mesh) == pytest.approx(area, rel=1e-12)
