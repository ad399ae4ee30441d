"""The §6.8 needle experiment's quick version (Tables 6.1–6.6, Figures 6.10 and 6.12): it writes
its results page and its numbers behave as the thesis says they should; plus independent checks
of the pieces it is built from (the line load, the field comparison, the tip's reference point)."""
import csv

import numpy as np
import pytest

import snede
from studies.experiments import needle as experiment
from snede.app.scenes.needle_slab import DEPTH, SIZE, h


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("needle")
    return experiment.main(["--quick", "--out", str(out)]), out


def test_the_line_load_is_the_profile_on_the_line_nodes_and_the_support_balances_it():
    body, nodes, _ = experiment.line_load_body(2, 4)
    points = body.mesh.points
    on_line = np.flatnonzero(np.isclose(points[:, 1], 0.05) & (points[:, 0] <= DEPTH + 1e-12))
    assert sorted(nodes) == sorted(on_line)
    assert np.all(np.diff(points[nodes, 0]) > 0)
    spacing = np.diff(points[nodes, 0])
    assert spacing.max() <= h(4) + 1e-12  # the line is made of edges no longer than h_ref
    forces = body.external_forces()
    profile = snede.FrictionProfile.figure_6_4()
    assert forces[:, 0].sum() == pytest.approx(profile.integral(0.0, DEPTH), rel=1e-12)
    assert np.abs(forces[:, 1]).max() == 0.0
    # the node at the tip carries the tip bulge: more than its neighbour halfway along the shaft
    assert forces[nodes[-1], 0] / spacing[-1] > forces[nodes[len(nodes) // 2], 0] / spacing[len(nodes) // 2]
    experiment.solve(body, 1e-10, "test_balance")
    reaction = body.reaction_forces()
    held = np.isclose(points[:, 0], SIZE)
    assert reaction[held].sum(axis=0) == pytest.approx(-forces.sum(axis=0), abs=1e-8)
    assert np.abs(body.displacement[held]).max() == 0.0


def test_a_tilted_line_selects_the_nearest_ends_of_crossed_edges_and_relocation_puts_them_on_it():
    degrees = 15.0
    body, nodes, info = experiment.line_load_body(3, 4, degrees, relocated=True)
    direction = experiment.unit(degrees)
    normal = np.array([-direction[1], direction[0]])
    offsets = np.abs((body.mesh.points[nodes] - np.array([0.0, 0.05])) @ normal)
    assert info["moved"] > 0 and info["moved"] + info["refused"] <= len(nodes)
    assert np.sum(offsets < 1e-12) >= info["moved"]  # every moved node is on the line
    body.mesh.validate()
    assert body.mesh.quality().volume.min() > 0  # snap_vertex refused every flattening move
    plain, plain_nodes, _ = experiment.line_load_body(3, 4, degrees)
    assert len(plain_nodes) == len(nodes)
    plain_offsets = np.abs((plain.mesh.points[plain_nodes] - np.array([0.0, 0.05])) @ normal)
    assert plain_offsets.max() <= h(4) / 2 + 1e-12  # the nearer end of an edge of length ≤ h_ref
    assert body.external_forces() @ direction == pytest.approx(plain.external_forces() @ direction)


def test_fields_are_compared_by_barycentric_interpolation():
    body, _, _ = experiment.line_load_body(2, 3)
    linear = np.column_stack([2 * body.mesh.points[:, 0] - body.mesh.points[:, 1], 0.5 * body.mesh.points[:, 1]])
    field = experiment.Field(body.mesh.points, body.mesh.cells, linear)
    fine, _, _ = experiment.reference_body(4)
    x = fine.mesh.points
    np.testing.assert_allclose(field.at(x), np.column_stack([2 * x[:, 0] - x[:, 1], 0.5 * x[:, 1]]), atol=1e-15)
    assert experiment.errors_mm(field.at(x), field.at(x)) == (0.0, 0.0)


def test_the_tip_reference_location_inverts_the_deformation():
    body = experiment.slab_body(2)
    x = body.mesh.points
    body.displacement = np.column_stack([0.1 * x[:, 1], 0.05 * x[:, 0]])  # an affine map: exactly representable
    material = np.array([0.031, 0.047])
    deformed = material + np.array([0.1 * material[1], 0.05 * material[0]])
    np.testing.assert_allclose(experiment.tip_reference_location(body, deformed), material, atol=1e-14)
    assert experiment.tip_reference_location(body, np.array([0.5, 0.5])) is None


def test_table_6_1_error_falls_as_the_tolerance_tightens(quick):
    rows = quick[0]["table_6_1"]
    assert [row["rtol"] for row in rows] == list(experiment.TOLERANCES)
    means = [row["mean_error_mm"] for row in rows]
    maxima = [row["max_error_mm"] for row in rows]
    assert all(b <= a for a, b in zip(means, means[1:])), means
    assert all(b <= a for a, b in zip(maxima, maxima[1:])), maxima
    assert means[-1] < means[0] / 20
    assert all(row["iterations"] < row["reference_iterations"] for row in rows)
    iterations = [row["iterations"] for row in rows]
    assert iterations == sorted(iterations)
    assert rows[0]["max_error_mm"] < 0.2 * rows[0]["max_displacement_mm"]


def test_tables_6_2_and_6_3_refinement_lowers_the_error_and_raises_the_iterations(quick):
    results = quick[0]
    settings = results["settings"]
    rows = {(r["h_start"], r["h_ref"]): r for r in results["tables_6_2_6_3"]}
    assert set(rows) == {(a, b) for a in settings.starts for b in settings.refs if b >= a}
    for (a, b), row in rows.items():
        if (a, b + 1) in rows:  # finer h_ref: more nodes, more CG iterations, no larger error
            assert rows[(a, b + 1)]["nodes"] > row["nodes"]
            assert rows[(a, b + 1)]["iterations"] > row["iterations"]
            assert rows[(a, b + 1)]["mean_error_mm"] <= row["mean_error_mm"] * 1.0001
        if (a + 1, b) in rows:  # finer h_start
            assert rows[(a + 1, b)]["mean_error_mm"] < row["mean_error_mm"]
            assert rows[(a + 1, b)]["iterations"] > row["iterations"]
        # the working tolerance adds little to the discretisation error
        assert abs(row["mean_error_at_working_rtol_mm"] - row["mean_error_mm"]) < 0.2 * row["mean_error_mm"]
    coarsest = rows[(settings.starts[0], settings.refs[0])]
    finest = rows[(settings.starts[-1], settings.refs[-1])]
    assert finest["mean_error_mm"] < coarsest["mean_error_mm"] / 5
    assert finest["max_error_mm"] < coarsest["max_error_mm"] / 3
    assert finest["nodes"] < results["reference"]["nodes"]


def test_tables_6_4_and_6_5_insertions_converge_and_slower_is_cheaper_per_solve_and_more_accurate(quick):
    results = quick[0]
    rows = results["insertion"]
    settings = results["settings"]
    assert all(row["converged"] for row in rows), [row["reason"] for row in rows if not row["converged"]]
    assert sum(row["reference"] for row in rows) == 1
    runs = sorted((row for row in rows if not row["reference"]), key=lambda r: -r["speed"])
    assert [row["speed"] for row in runs] == list(settings.speeds)
    for row in rows:
        assert row["updates"] == int(np.ceil(DEPTH / (row["speed"] * h(row["h_ref"])) - 1e-9))
        assert row["rearrangements"] >= row["updates"]
        assert row["update_rate_hz"] == pytest.approx(row["rearrangements"] / row["cpu_seconds"])
        assert row["needle_nodes"] > DEPTH / h(row["h_start"])
        assert 0 < row["mean_iterations"] <= row["max_iterations"]
    rearrangements = [row["rearrangements"] for row in runs]
    assert rearrangements == sorted(rearrangements)  # slower: more solves
    assert runs[-1]["mean_iterations"] < runs[0]["mean_iterations"]  # ...each cheaper (coherence)
    assert runs[-1]["mean_error_mm"] < runs[0]["mean_error_mm"]
    assert runs[-1]["max_error_mm"] < runs[0]["max_error_mm"]
    static = next(r for r in results["tables_6_2_6_3"] if (r["h_start"], r["h_ref"]) == (settings.h_start, settings.h_ref))
    assert runs[-1]["mean_error_mm"] < 3 * static["mean_error_mm"]  # the order of the discretisation error


def test_table_6_6_relocation_changes_less_than_the_discretisation_error(quick):
    rows = {row["comparison"]: row for row in quick[0]["table_6_6"]}
    assert set(rows) == {"relocation_vs_none", "with_relocation", "without_relocation", "reference_relocation_vs_none"}
    difference = rows["relocation_vs_none"]["mean_error_mm"]
    assert 0 < difference < rows["with_relocation"]["mean_error_mm"]
    assert difference < rows["without_relocation"]["mean_error_mm"]
    assert rows["with_relocation"]["relocated"] > 0


def test_figure_6_12_linear_and_neo_hookean_tips_end_on_different_material_points(quick):
    rows = quick[0]["figure_6_12"]
    assert {row["material"] for row in rows} == {"LinearElastic", "NeoHookean"}
    for row in rows:
        assert row["converged"], row["reason"]
        assert row["inverted_elements"] == 0
        assert row["tip_x"] == pytest.approx(DEPTH) and row["tip_y"] == pytest.approx(0.05)
        assert row["tip_reference_x"] is not None and row["tip_reference_x"] < DEPTH  # dragged along +x
        assert row["tip_node_reference_x"] <= DEPTH
    linear, neo = rows
    assert linear["tip_reference_distance_mm"] == pytest.approx(
        1e3 * np.hypot(linear["tip_reference_x"] - neo["tip_reference_x"], linear["tip_reference_y"] - neo["tip_reference_y"]))
    assert 0 < linear["tip_reference_distance_mm"] < 20


def test_the_results_page_and_files_are_written(quick):
    _, out = quick
    for name in ("needle.md", "needle.csv", "needle_errors.png", "needle_rates.png", "needle_nonlinear.png"):
        path = out / name
        assert path.is_file() and path.stat().st_size > 0, path
    text = (out / "needle.md").read_text()
    assert "python -m studies.experiments.needle" in text
    for heading in ("## Table 6.1", "## Table 6.2", "## Table 6.3", "## Figure 6.10", "## Table 6.4", "## Table 6.5",
                    "## Table 6.6", "## Figure 6.12"):
        assert heading in text, heading
    assert "stand-in" in text and "Quick run" in text
    assert "| 0.3 | " in text and "| 0.001 | " in text  # Table 6.1's rows
    with open(out / "needle.csv") as stream:
        parts = {row["part"] for row in csv.DictReader(stream)}
    assert parts == {"reference", "table_6_1", "tables_6_2_6_3", "tables_6_4_6_5", "table_6_5", "table_6_6",
                     "figure_6_12"}


def test_table_6_5_is_timed_in_the_haptic_loop_at_both_tolerances(quick):
    rows = quick[0]["table_6_5"]
    assert {row["rtol"] for row in rows} == set(experiment.TIMING_TOLERANCES)
    for row in rows:
        assert row["converged"], row["reason"]
        assert row["rearrangements"] == row["updates"]  # one solve per update (§6.7)
        assert row["update_rate_hz"] == pytest.approx(row["rearrangements"] / row["cpu_seconds"])
    by = {(row["rtol"], row["speed"]): row["mean_iterations"] for row in rows}
    for speed in {row["speed"] for row in rows}:  # the looser ε needs fewer CG iterations
        assert by[(experiment.THESIS_CG_TOLERANCE, speed)] < by[(experiment.ISSUE_TOLERANCE, speed)]


def test_the_table_6_5_section_is_replaced_alone():
    page = "# page\n\n## Table 6.4: x\n\nfour\n\n## Table 6.5: timings\n\nold\n\n## Table 6.6: y\n\nsix\n"
    new = experiment.replace_table_6_5(page, ["## Table 6.5: timings", "", "new", ""])
    assert new == "# page\n\n## Table 6.4: x\n\nfour\n\n## Table 6.5: timings\n\nnew\n\n## Table 6.6: y\n\nsix\n"
