"""The membrane-cut scene (§5.3, Figures 5.14 and 5.19): the stretched bell membrane cut twice
and along a loop that crosses itself, relaxed every few moves, and the folded sheet cut across
with a branching cut. Every solve converges; the cuts count the entries, exits and branches the
paths make; the lips open (measured from the written series alone: boundary vertices sharing a
reference position); the loop cuts a piece out; the fold falls into two pieces; the files and
pictures are written; the command line prints a line per move and refuses bad options."""
import re

import numpy as np
import pytest
from PIL import Image

from snede.output import read_series
from snede.app.scenes import membrane_cut

from test_scenes import assert_gif_shows_the_cut, built_and_run, not_blank, red_pixels, run_cli, written_files
from test_sheet_cut_scene import lip_pairs, widest_gap

DIVISIONS = 10  # 200 triangles: about 3 seconds with the pictures


@pytest.fixture(scope="module")
def membrane(tmp_path_factory):
    return built_and_run(membrane_cut, "membrane-cut", tmp_path_factory, DIVISIONS)[:2]


def test_every_relaxation_converges(membrane):
    scene, summary = membrane
    run = scene.evolve.__self__
    assert summary["converged"] and summary["method"] == "newton" and summary["material"] == "NeoHookean"
    assert all(r.converged and r.reason.startswith("CONVERGED") for r in run.results)
    # the stretch, then one solve every RELAX_EVERY moves and at the end of each path
    per_path = [-(-c["moves"] // membrane_cut.RELAX_EVERY) for c in summary["cuts"].values()]
    assert summary["solves"] == 1 + sum(per_path) == len(run.results)
    assert summary["moves"] == sum(c["moves"] for c in summary["cuts"].values())
    mesh = scene.body.mesh
    mesh.validate()
    assert len(scene.body.inverted_elements(scene.body.displacement)) == 0
    assert summary["cut_seconds"] > 0 and summary["solve_seconds"] > 0


def test_the_cuts_enter_and_leave_where_the_paths_say(membrane):
    _, summary = membrane
    events = {name: (c["entries"], c["exits"], c["branches"], c["annihilations"], c["stuck"])
              for name, c in summary["cuts"].items()}
    # Two cuts in from the rim that stop inside; the loop enters, leaves through its own lip
    # and enters again through the other (§5.3.2).
    assert events == {"first cut": (1, 0, 0, 0, 0), "second cut": (1, 0, 0, 0, 0), "loop": (2, 1, 0, 0, 0)}
    assert (summary["entries"], summary["exits"]) == (4, 1)
    assert summary["triangles_before"] == 2 * DIVISIONS ** 2 < summary["triangles_after"] == summary["cells"]
    # The loop cut out the piece it enclosed, which is held; the rest is one piece.
    assert summary["pieces"] == 2 and summary["pieces_held"] == 1


def test_the_tension_opens_the_lips(membrane):
    _, summary = membrane
    steps = read_series(summary["files"]["xdmf"])
    assert len(steps) == summary["frames"] - len([f for f in membrane[0].evolve.__self__.frames if f.part == "fold"])
    first, last = steps[0], steps[-1]
    assert widest_gap(first.mesh.points, first.mesh.cells, first.displacement) == 0.0  # stretched, not yet cut
    gap = widest_gap(last.mesh.points, last.mesh.cells, last.displacement)
    assert gap > 0.02  # centimetres on the unit square, not round-off
    assert summary["opening_m"] == summary["value"] == pytest.approx(gap)
    assert len(lip_pairs(last.mesh.points, last.mesh.cells)) >= 10
    assert last.cell_fields["incision"].sum() > 0 and first.cell_fields["incision"].sum() == 0
    assert len({id(s.mesh) for s in steps}) > 3  # the series follows the mesh as the cuts change it


def test_the_fold_branches_and_falls_in_two(membrane):
    scene, summary = membrane
    fold = summary["fold"]
    assert (fold["entries"], fold["branches"], fold["exits"], fold["annihilations"]) == (1, 1, 2, 0)
    assert fold["pieces"] == 2 and fold["triangles_after"] > fold["triangles_before"] == 160
    steps = read_series(summary["files"]["fold_xdmf"])
    assert steps[0].mesh.connected_components()[0] == 1
    assert steps[-1].mesh.connected_components()[0] == 2
    # Both layers are cut: lips at the lower layer's height and at the upper one's.
    run = scene.evolve.__self__
    heights = run.fold.points[np.unique(run.fold_cutter.incision_edges()), 2]
    assert heights.min() < 0.01 and heights.max() > 0.29


def test_files_and_pictures(membrane):
    _, summary = membrane
    files = written_files(summary, ("xdmf", "h5", "png", "gif", "fold_png", "fold_xdmf", "fold_h5"))
    for png in (files["png"], files["fold_png"]):
        assert not_blank(png)
        with Image.open(png) as image:
            assert red_pixels(image) > 50  # the lips
    assert_gif_shows_the_cut(files["gif"], summary["frames"], 10)


def test_cli_prints_a_line_per_move(tmp_path):
    out = run_cli("run", "membrane-cut", "--divisions", str(DIVISIONS), "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    for name in ("first cut", "second cut", "loop"):
        moves = re.findall(rf"^membrane-cut: {name} move +(\d+)/(\d+), scalpel at ", out.stdout, re.M)
        assert moves and [int(k) for k, _ in moves] == list(range(1, int(moves[0][1]) + 1)), name
    assert re.search(r"relaxed: converged \(CONVERGED_\w+\)", out.stdout)
    assert len(re.findall(r"^membrane-cut: fold move +\d+/\d+", out.stdout, re.M)) > 10
    assert re.search(r"^membrane-cut\s+\d+\s+NeoHookean\s+newton\s+\d+\s+CONVERGED_\w+\s", out.stdout, re.M)
    assert "1 entries, 2 exits, 1 branches, 0 annihilations" in out.stdout


@pytest.mark.parametrize("args, message", [
    (("--divisions", "5"), "at least 8"),
    (("--material", "linear"), "nonlinear material"),
    (("--method", "cg"), "solves with newton"),
    (("--speed", "1"), "--speed does not apply to the membrane-cut scene"),
    (("--formulation", "smoothed"), "--formulation does not apply to the membrane-cut scene"),
])
def test_bad_options_give_a_message(args, message, tmp_path):
    out = run_cli("run", "membrane-cut", *args, "--out", str(tmp_path))
    assert out.returncode == 2 and message in out.stderr and "Traceback" not in out.stderr
