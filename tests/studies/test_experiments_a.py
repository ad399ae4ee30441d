"""The experiments' quick versions (cantilever, tradeoff, extremes): they write their outputs
and their numbers agree with independent references."""
import numpy as np
import pytest

import snede
from studies.experiments import cantilever, extremes, tradeoff

# §3.3: y = 4F/(Ed)(l/h)³ with F = 3 N, E = 1e6 Pa, l = 1.2, h = 0.2, d = 0.3 m.
BEAM_DEFLECTION = 4 * 3.0 / (1e6 * 0.3) * (1.2 / 0.2) ** 3
# with shear deformation (Timoshenko, κ = 5/6, G = E/2 at ν = 0): + F l/(κ G h d)
SHEAR_BEAM_DEFLECTION = BEAM_DEFLECTION + 3.0 * 1.2 / (5 / 6 * 0.5e6 * 0.2 * 0.3)


def assert_written(folder, name, suffixes):
    for suffix in suffixes:
        path = folder / f"{name}.{suffix}"
        assert path.is_file() and path.stat().st_size > 0, path
    assert f"python -m studies.experiments.{name}" in (folder / f"{name}.md").read_text()


def test_cantilever_approaches_beam_theory_from_below_as_the_mesh_is_refined(tmp_path):
    results = cantilever.main(["--quick", "--out", str(tmp_path)])
    assert BEAM_DEFLECTION == pytest.approx(8.64e-3)
    table = results["table_3_1"]
    assert [row["n"] for row in table] == [8, 12, 16]
    for row in table:
        assert row["converged"] and row["reason"] == "CONVERGED_ATOL", row
        assert row["all_below_analytic"]  # the FEM is stiffer than the beam (Table 3.1's caption)
        assert row["avg_error_pct"] == pytest.approx(100 * (1 - row["tip_deflection"] / BEAM_DEFLECTION))
        assert row["nodes"] == (row["n"] + 1) * (row["n"] // 4 + 1) ** 2
    errors = [row["avg_error_pct"] for row in table]
    assert errors[0] > errors[1] > errors[2] > 0
    # Against the shear-corrected beam, halving h (8 -> 16) cuts the error by 2 or more (P1: ~h²).
    shear_errors = [1 - row["tip_deflection"] / SHEAR_BEAM_DEFLECTION for row in table]
    assert shear_errors[0] / shear_errors[2] > 2
    # 16 × 4 × 4 is Table 3.1's first row: same node count, error of the same size (29.0 % there).
    row16 = table[-1]
    assert row16["nodes"] == row16["thesis_nodes"] == 425
    assert 0.5 * 29.0 < row16["avg_error_pct"] < 29.0

    nonlinear = results["nonlinear"]
    assert nonlinear and all(row["converged"] for row in nonlinear), nonlinear
    for row in nonlinear:
        if row["load"] == 3.0:  # small strain: every material is its small-strain linear solid
            assert row["ratio_to_equivalent_linear"] == pytest.approx(1.0, abs=0.01), row
        if row["load"] == 3.0 and not row["material"].startswith("Veronda"):
            assert row["ratio_to_linear"] == pytest.approx(1.0, abs=0.01), row
        if row["load"] == 3.0:  # the exact large-deflection beam is linear at this load
            assert row["elastica_ratio"] == pytest.approx(1.0, abs=1e-3)
        if row["load"] == 300.0 and not row["material"].startswith("Veronda"):
            # geometric stiffening of the bent beam: α = Fl²/(EI) = 2.16, where the elastica deflects
            # 0.716 of the linear beam (Bisshopp and Drucker's table: 0.740 at α = 2); the coarse
            # mesh is stiffer in bending, which lifts its ratio towards 1.
            assert row["elastica_ratio"] == pytest.approx(0.716, abs=0.002)
            assert row["elastica_ratio"] < row["ratio_to_linear"] < 0.97, row
            assert row["tip_shortening"] > 0
    assert_written(tmp_path, "cantilever", ("md", "csv", "png"))


def dominates(a, b):
    return (a["seconds"] <= b["seconds"] and a["error_pct"] <= b["error_pct"]
            and (a["seconds"] < b["seconds"] or a["error_pct"] < b["error_pct"]))


def test_tradeoff_reference_is_tighter_than_every_run_and_the_pareto_set_is_non_dominated(tmp_path):
    results = tradeoff.main(["--quick", "--out", str(tmp_path)])
    rows = results["rows"]
    assert {row["scene"] for row in rows} == {"cantilever", "cylinder"}
    for scene, reference in results["references"].items():
        runs = [row for row in rows if row["scene"] == scene]
        assert results["reference_rtol"][scene] < min(row["rtol"] for row in runs)
        assert results["reference_h"][scene] < min(row["h"] for row in runs)
        values, limit = reference["values"], reference["limit"]
        assert abs(values[2] - limit) < abs(values[1] - limit) < abs(values[0] - limit)
        converged = [row for row in runs if row["converged"]]
        pareto = [row for row in runs if row["pareto"]]
        assert pareto and all(row["converged"] for row in pareto)
        for row in pareto:
            assert not any(dominates(other, row) for other in converged), row
        for row in converged:
            if not row["pareto"]:
                assert any(dominates(p, row) or (p["seconds"], p["error_pct"]) == (row["seconds"], row["error_pct"])
                           for p in pareto), row
    # independent check of the extrapolated cantilever reference: the shear-corrected beam
    assert results["references"]["cantilever"]["limit"] == pytest.approx(SHEAR_BEAM_DEFLECTION, rel=0.05)
    for pick in results["recommendations"]:
        if pick["error_pct"] is not None:
            assert pick["error_pct"] <= pick["target_pct"]
    assert_written(tmp_path, "tradeoff", ("md", "csv", "png"))


def test_extremes_every_run_ends_with_a_verdict_and_locking_is_measured_and_warned(tmp_path):
    with pytest.warns(snede.LockingWarning, match="of what beam theory predicts"):  # the measured warning
        rows = extremes.main(["--quick", "--out", str(tmp_path)])
    assert len({row["case"] for row in rows}) == 8
    for row in rows:
        assert row["converged"] is True or (isinstance(row["reason"], str) and row["reason"]), row
        if row["converged"]:
            assert row["reason"].startswith("CONVERGED"), row
    locking = {(row["setting"].split(",")[0], row["material"]): row for row in rows if row["case"].startswith("ν")}
    assert locking[("ν = 0.0", "LinearElastic")]["ratio"] == pytest.approx(1.0)
    assert locking[("ν = 0.3", "LinearElastic")]["ratio"] > 0.9
    assert locking[("ν = 0.499", "LinearElastic")]["ratio"] < 0.5
    assert "locks" in locking[("ν = 0.499", "LinearElastic")]["note"]
    steps = [row for row in rows if row["case"].startswith("time step")]
    for row in steps:
        if row["setting"].startswith("Δt = 0.5"):
            assert row["converged"] and row["ratio"] == pytest.approx(1.0, abs=0.01), row
        if row["setting"].startswith("Δt = 1.5"):
            assert not row["converged"], row
    for row in rows:
        if row["material"] == "NeoHookean" and row["converged"] and "inverted_elements" in row:
            assert row["inverted_elements"] == 0, row
    assert any(row["inverted_elements"] > 0 for row in rows
               if row["material"] == "StVenantKirchhoff" and "inverted_elements" in row)
    slivers = [row for row in rows if row["case"].startswith("aspect")]
    assert min(row["min_aspect_ratio"] for row in slivers) == pytest.approx(1e-4, rel=0.05)
    assert np.all([row["converged"] for row in slivers if row["solver"] == "cg"])
    assert_written(tmp_path, "extremes", ("md", "csv"))
