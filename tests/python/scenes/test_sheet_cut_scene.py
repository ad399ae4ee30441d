"""The sheet-cut scene: a stretched plane-stress sheet cut along an S-curve by the Delaunay
cutter (§5.2), relaxed after every move. Every solve converges, the mesh grows by a few
triangles and stays valid, the series follows the cut meshes, and the tension opens the cut:
measured here from the written files alone (the lips are boundary vertices that share a
reference position, found from the cells, not from the cutter), by millimetres, along the
path. Also the pictures, the command line, a solve that does not converge, and neo-Hookean."""
import json
import math
import re
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest
from PIL import Image

from snede.app import run_scene
from snede.app.scenes import sheet_cut

from test_scenes import assert_gif_shows_the_cut, built_and_run, red_pixels, run_cli, run_cutting_scene_cli, written_files

DIVISIONS = 20  # 20 × 12 squares, 38 moves: about 4 seconds with the animation


@pytest.fixture(scope="module")
def sheet(tmp_path_factory):
    return built_and_run(sheet_cut, "sheet-cut", tmp_path_factory, DIVISIONS)[:2]


def written_steps(summary):
    """[(time, points, cells, displacement)] of each step of the series, as the XDMF file
    points to them in the HDF5 file (each step names its own mesh)."""
    xdmf = Path(summary["files"]["xdmf"])
    steps = []
    with h5py.File(summary["files"]["h5"], "r") as h5:
        for grid in ElementTree.parse(xdmf).getroot().iter("Grid"):
            if grid.get("GridType") != "Uniform":
                continue

            def read(path: str):
                return h5[path.split(":", 1)[1].strip()][...]

            steps.append((float(grid.find("Time").get("Value")), read(grid.find("Geometry/DataItem").text),
                          read(grid.find("Topology/DataItem").text),
                          read(grid.find("Attribute[@Name='displacement']/DataItem").text)))
    return steps


def lip_pairs(points, cells):
    """Pairs of boundary vertices at the same reference position: the two lips of a cut (the
    uncut sheet has none). Boundary edges are those of one triangle only."""
    edges = np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    at = {}
    for v in np.unique(unique[count == 1]):
        at.setdefault(tuple(points[v]), []).append(v)
    return [group for group in at.values() if len(group) == 2]


def widest_gap(points, cells, displacement) -> float:
    deformed = points + displacement
    pairs = lip_pairs(points, cells)
    return max((float(np.linalg.norm(deformed[a] - deformed[b])) for a, b in pairs), default=0.0)


def test_every_solve_converges_and_the_cut_adds_a_few_triangles(sheet):
    scene, summary = sheet
    run = scene.evolve.__self__
    assert summary["converged"], summary
    assert all(r.converged and r.reason.startswith("CONVERGED") for r in run.results)
    assert summary["method"] == "cg" and summary["material"] == "LinearElastic"
    assert summary["solves"] == summary["moves"] + 1 == len(run.path) + 1  # the stretch, then one per move
    assert summary["entries"] == 1 and summary["exits"] == 0 and summary["stuck"] == 0
    assert summary["triangles_before"] == 2 * DIVISIONS * (3 * DIVISIONS // 5)
    assert summary["triangles_after"] == summary["cells"] > summary["triangles_before"]
    assert summary["nodes_inserted"] > summary["nodes_removed"] and summary["flips"] > 0
    assert summary["cut_seconds"] > 0 and summary["solve_seconds"] > 0
    mesh = scene.body.mesh
    mesh.validate()
    assert mesh.connected_components()[0] == 1  # the cut stops inside: one piece
    assert len(scene.body.inverted_elements(scene.body.displacement)) == 0
    saved = json.loads((Path(summary["files"]["xdmf"]).parent / "summary.json").read_text())
    assert saved["opening_m"] == summary["opening_m"] and saved["triangles_after"] == summary["triangles_after"]


def test_the_tension_opens_the_incision_along_the_s_curve(sheet):
    _, summary = sheet
    steps = written_steps(summary)
    time, points, cells, displacement = steps[-1]
    assert time == summary["moves"]
    gap = widest_gap(points, cells, displacement)
    pull = sheet_cut.STRETCH * sheet_cut.LENGTH  # how far the grips moved apart
    assert gap > 0.5 * pull  # millimetres, not round-off
    assert summary["opening_m"] == summary["value"] == pytest.approx(gap)
    assert widest_gap(*steps[0][1:]) == 0.0  # stretched, not yet cut
    assert widest_gap(*steps[len(steps) // 2][1:]) < gap  # the cut opens as it grows

    # The lips follow the S-curve: in the reference configuration, within an element of it
    # (the path was given in deformed coordinates, where the sheet had moved by ~1 mm there).
    pairs = lip_pairs(points, cells)
    assert len(pairs) >= 8
    s = np.linspace(0, 1, 2001)
    curve = np.c_[0.5 * sheet_cut.LENGTH + sheet_cut.SWAY * sheet_cut.LENGTH * np.sin(2 * math.pi * s),
                  sheet_cut.HEIGHT * (1 - sheet_cut.DEPTH * s)]
    lips = points[[a for a, _ in pairs], :2]
    h = sheet_cut.LENGTH / DIVISIONS
    assert np.linalg.norm(lips[:, None] - curve[None], axis=2).min(axis=1).max() < h
    # Down to where the scalpel stopped (deformed), the tip lagging by at most an element; the
    # reference depth differs from the deformed one by the sheet's strain, less than h/2.
    deepest = sheet_cut.HEIGHT * (1 - sheet_cut.DEPTH)
    assert deepest - h / 2 <= lips[:, 1].min() < deepest + h
    assert lips[:, 1].max() == pytest.approx(sheet_cut.HEIGHT)  # entered through the top edge


def test_series_has_a_frame_every_few_moves_that_meshio_reads(sheet):
    _, summary = sheet
    steps = written_steps(summary)
    assert len(steps) == summary["frames"] > 10
    times = [t for t, *_ in steps]
    assert times[0] == 0.0 and times == sorted(times)
    with h5py.File(summary["files"]["h5"], "r") as f:
        assert len(f["/mesh"]) > 1  # the cut changed the mesh: new meshes in the series
    marked = []
    with meshio.xdmf.TimeSeriesReader(summary["files"]["xdmf"]) as reader:
        reader.read_points_cells()
        assert reader.num_steps == len(steps)
        for k in range(reader.num_steps):
            _, point_data, cell_data = reader.read_data(k)
            assert point_data["displacement"].shape == steps[k][3].shape
            values = np.concatenate(cell_data["incision"])
            assert len(values) == len(steps[k][2]) and set(np.unique(values)) <= {0.0, 1.0}
            marked.append(int(values.sum()))
    assert marked[0] == 0 and marked[-1] > 0
    # The last step marks the triangles along the lips found from its cells: every one with a
    # boundary edge between two lip vertices, and besides them only the two at the tip (the
    # active node, one vertex, not a pair).
    _, points, cells, _ = steps[-1]
    lips = {v for pair in lip_pairs(points, cells) for v in pair}
    edges = np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]])
    keys, count = np.unique(np.sort(edges, axis=1), axis=0, return_counts=True)
    boundary = {tuple(e) for e in keys[count == 1]}
    along = np.array([any(tuple(sorted(e)) in boundary and set(e) <= lips for e in (t[[0, 1]], t[[1, 2]], t[[2, 0]]))
                      for t in cells])
    with h5py.File(summary["files"]["h5"], "r") as f:
        incision = f[f"/step/{len(steps) - 1}/incision"][...] == 1.0
    assert along.sum() > 0 and np.all(incision[along]) and incision.sum() <= along.sum() + 2


def test_picture_and_animation_show_the_incision(sheet):
    _, summary = sheet
    files = written_files(summary)
    with Image.open(files["png"]) as png:
        assert red_pixels(png) > 100
    assert_gif_shows_the_cut(files["gif"], summary["frames"], 20)


def test_cli_prints_a_line_per_move_with_the_solve_reason(tmp_path):
    out = run_cutting_scene_cli("sheet-cut", 10, tmp_path, "scalpel at .*", "stretched 8% by the grips", "LinearElastic", "cg")
    assert re.search(r"\d+ → \d+ triangles in [\d.]+ ms; \d+ solves in [\d.]+ s; the lips open by up to [\d.]+ mm",
                     out.stdout)


def test_a_solve_that_does_not_converge_is_reported_and_stops_the_cut(tmp_path):
    # The stretch takes 39 CG iterations on 10 × 6 squares, the solves after the scalpel
    # enters about 50: 45 lets the first through and stops a later one.
    out = run_cli("run", "sheet-cut", "--divisions", "10", "--out", str(tmp_path), "-static_ksp_max_it", "45")
    assert out.returncode == 1, out.stdout
    failed = re.search(r"^sheet-cut: move +(\d+)/\d+, .*relaxed: NOT converged \(DIVERGED_ITS\)", out.stdout, re.M)
    assert failed, out.stdout
    assert f"stopped before move {int(failed.group(1)) + 1}/" in out.stdout
    assert "did not converge: DIVERGED_ITS" in out.stderr
    summary = json.loads((tmp_path / "sheet-cut" / "summary.json").read_text())
    assert not summary["converged"] and summary["reason"] == "DIVERGED_ITS"
    assert summary["moves"] == int(failed.group(1))


def test_neo_hookean_sheet_is_cut_with_newton(tmp_path):
    out = run_cli("--quiet", "run", "sheet-cut", "--divisions", "10", "--material", "neohookean",
                  "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    assert re.search(r"^sheet-cut\s+\d+\s+NeoHookean\s+newton\s+\d+\s+CONVERGED_\w+\s", out.stdout, re.M), out.stdout
    summary = json.loads((tmp_path / "sheet-cut" / "summary.json").read_text())
    assert summary["opening_m"] > 0.5 * sheet_cut.STRETCH * sheet_cut.LENGTH


@pytest.mark.parametrize("args, message", [
    (("--divisions", "12"), "multiple of 5"),
    (("--method", "dynamic"), "cg, ncg, newton"),
    (("--material", "neohookean", "--method", "cg"), "LinearElastic"),
    (("--speed", "1"), "--speed does not apply to the sheet-cut scene"),
    (("--mesh-size", "0.01"), "--mesh-size does not apply to the sheet-cut scene"),
])
def test_bad_sheet_cut_options_give_a_message(args, message, tmp_path):
    out = run_cli("run", "sheet-cut", *args, "--out", str(tmp_path))
    assert out.returncode == 2 and message in out.stderr and "Traceback" not in out.stderr


def test_picture_marks_the_grips(sheet, request):
    """Issue 14 item 9: the vertices the grips hold, where they pulled them."""
    from snede.app.plotting import draw_body
    import matplotlib.pyplot as plt
    from test_pictures import one

    scene, summary = sheet
    body = scene.body
    arguments = run_scene.picture_arguments(scene, summary["method"])
    fig, ax = draw_body(body, **arguments)
    request.addfinalizer(lambda: plt.close(fig))
    fixed = one(ax, "fixed")
    held = np.flatnonzero(arguments["fixed"])
    assert len(held) == body._model.n_constrained
    x = body.mesh.points[held] + body.displacement[held]
    np.testing.assert_allclose(np.c_[fixed.get_xdata(), fixed.get_ydata()], x)
    pull = 0.5 * sheet_cut.STRETCH * sheet_cut.LENGTH
    np.testing.assert_allclose(np.abs(x[:, 0] - 0.5 * sheet_cut.LENGTH), 0.5 * sheet_cut.LENGTH + pull)
    assert "to scale" in ax.get_title() and ax.get_aspect() == 1.0
