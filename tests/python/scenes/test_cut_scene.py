"""The cut scene: a scalpel comes down into a beam sagging under gravity in steps, with a static
relaxation after each. Every relaxation converges, the cut stays a notch (one piece), the
series follows the cut meshes and marks the incision, the picture and the animation show it in
red, and the load opens it: the lips, made from the same vertices, are apart in the deformed
beam, widest at the mouth. Also the command line and the example script examples/scalpel_cut.py."""
import json
import re
from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest
from PIL import Image

from snede.app import run_scene
from snede.app.scenes import cut

from test_scenes import ROOT, assert_gif_shows_the_cut, built_and_run, not_blank, red_pixels, run_cli, run_cutting_scene_cli, written_files

DIVISIONS = 12  # 12 × 3 × 3 cubes, 4 moves of the blade: about 2 seconds


@pytest.fixture(scope="module")
def cut_beam(tmp_path_factory):
    return built_and_run(cut, "cut", tmp_path_factory, DIVISIONS)


def lips(scene):
    """The vertex pairs the cut made: (reference z, deformed gap vector) of each pair of incision
    vertices at the same reference position."""
    mesh, u = scene.body.mesh, scene.body.displacement
    vertices = np.unique(scene.evolve.__self__.faces())
    pairs = {}
    for v in vertices:
        pairs.setdefault(tuple(mesh.points[v]), []).append(v)
    return [(key[2], (mesh.points[b] + u[b]) - (mesh.points[a] + u[a]))
            for key, group in pairs.items() if len(group) == 2 for a, b in [group]]


def test_every_relaxation_converges_and_the_notch_leaves_one_valid_piece(cut_beam):
    scene, summary, out = cut_beam
    results = scene.evolve.__self__.results
    assert summary["converged"], summary
    assert results[-1].converged and results[-1].reason.startswith("CONVERGED")  # the final solve
    assert all(r.converged for r in results) and summary["reason"] == results[-1].reason
    assert summary["moves"] >= 3 and summary["solves"] == summary["moves"] + 1  # the sag, then one per move
    assert summary["method"] == "newton" and summary["material"] == "NeoHookean"
    assert summary["components"] == 1 and summary["free_pieces"] == 0  # 70 % deep: a notch, not two pieces
    scene.body.mesh.validate()
    assert len(scene.body.inverted_elements(scene.body.displacement)) == 0
    saved = json.loads((out / "cut" / "summary.json").read_text())
    assert saved["incision_faces"] == summary["incision_faces"] and saved["opening_m"] == summary["opening_m"]


def test_the_incision_is_a_notch_under_the_blade(cut_beam):
    scene, summary, _ = cut_beam
    faces = scene.evolve.__self__.faces()
    assert len(faces) > 0 and len(faces) == summary["incision_faces"] == 2 * summary["faces_dissected"]
    boundary = {tuple(sorted(f)) for f in scene.body.mesh.boundary_faces()}
    assert {tuple(sorted(f)) for f in faces} <= boundary  # the lips are boundary faces now
    h = cut.LENGTH / DIVISIONS
    blade = (round(cut.AT * DIVISIONS) + cut.OFFSET) * h
    reference = scene.body.mesh.points[np.unique(faces)]
    assert np.abs(reference[:, 0] - blade).max() < h  # snapped onto the blade, which the sag moved
    assert reference[:, 2].max() == pytest.approx(cut.HEIGHT)  # entered through the top
    # Down to DEPTH of the height, where the blade stopped, lagging it by at most an element
    # (Figure 3.4); the reference and deformed depths differ by the sag's strain, less than h/2.
    assert (1 - cut.DEPTH) * cut.HEIGHT - h / 2 <= reference[:, 2].min() <= (1 - cut.DEPTH) * cut.HEIGHT + h


def test_the_load_opens_the_cut(cut_beam):
    scene, summary, _ = cut_beam
    pairs = lips(scene)
    assert len(pairs) >= 4
    depth, gap = np.array([z for z, _ in pairs]), np.array([d for _, d in pairs])
    width = np.linalg.norm(gap, axis=1)
    mouth = np.argmax(depth)
    assert width[mouth] > 5e-3  # the stretched top opens: millimetres, not round-off
    assert width[mouth] > width[np.argmin(depth)]  # a V: widest at the mouth, closing towards the tip
    assert abs(gap[mouth, 0]) > 0.5 * width[mouth]  # the lips part along the beam
    assert summary["opening_m"] == summary["value"] == pytest.approx(width.max())
    assert summary["tip_sag_after_m"] > 1.1 * summary["tip_sag_before_m"] > 0  # the cut beam sags more


def test_files_are_written_and_show_the_incision(cut_beam):
    _, summary, _ = cut_beam
    files = written_files(summary)
    with Image.open(files["png"]) as png:
        assert red_pixels(png) > 100
    assert summary["frames"] == summary["moves"] + 2  # unloaded, sagging, each move
    assert_gif_shows_the_cut(files["gif"], summary["frames"], 20)


def test_series_follows_the_cut_meshes_and_marks_the_incision(cut_beam):
    scene, summary, _ = cut_beam
    xdmf = Path(summary["files"]["xdmf"])
    steps = xdmf.read_text().count('<Grid Name="step')
    assert steps == summary["frames"]
    with h5py.File(summary["files"]["h5"], "r") as f:
        assert len(f["/mesh"]) > 1  # the cut changed the mesh: new meshes in the series
        last = f[f"/step/{steps - 1}/incision"][...]
        displacement = f[f"/step/{steps - 1}/displacement"][...]
    mesh = scene.body.mesh
    np.testing.assert_array_equal(last, cut.incision_cells(mesh, scene.evolve.__self__.faces()))
    np.testing.assert_array_equal(displacement, scene.body.displacement)
    marked = []
    with meshio.xdmf.TimeSeriesReader(xdmf) as reader:
        reader.read_points_cells()
        for k in range(reader.num_steps):
            _, _, cell_data = reader.read_data(k)
            values = np.concatenate(cell_data["incision"])
            assert set(np.unique(values)) <= {0.0, 1.0}
            marked.append(int(values.sum()))
    assert marked[:3] == [0, 0, 0]  # unloaded, sagging, the blade's first move above the top
    assert marked[-1] == int(last.sum()) > 0 and marked == sorted(marked)  # the cut only grows


def test_cli_runs_the_cut_with_a_line_per_step(tmp_path):
    out = run_cutting_scene_cli("cut", 8, tmp_path, "blade .*faces dissected.*", "sagging under gravity", "NeoHookean", "newton")
    assert "widest gap between the lips" in out.stdout


@pytest.mark.parametrize("args, message", [
    (("--divisions", "6"), "multiple of 4"),
    (("--method", "dynamic"), "cg, ncg, newton"),
    (("--speed", "1"), "--speed does not apply to the cut scene"),
    (("--mesh-size", "0.01"), "--mesh-size does not apply to the cut scene"),
])
def test_bad_cut_options_give_a_message(args, message, tmp_path):
    out = run_cli("run", "cut", *args, "--out", str(tmp_path))
    assert out.returncode == 2 and message in out.stderr and "Traceback" not in out.stderr


def test_example_script_cuts_and_relaxes_in_turn(tmp_path):
    out = run_cli("run", str(ROOT / "examples" / "scalpel_cut.py"), cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    reports = re.findall(r"^move \d+, blade at y = .*: \d+ faces dissected \(\d+ vertices snapped", out.stdout, re.M)
    relaxed = re.findall(r"^    relaxed: converged \(CONVERGED_\w+\) after \d+ iterations", out.stdout, re.M)
    assert len(reports) == len(relaxed) == 8 and "NOT converged" not in out.stdout, out.stdout
    mouth = float(re.search(r"the mouth is ([\d.]+) mm wide", out.stdout).group(1))
    assert mouth > 2.0  # the pull opens the cut by millimetres
    folder = tmp_path / "out" / "scalpel_cut"
    assert not_blank(folder / "scalpel_cut.png")
    with h5py.File(folder / "scalpel_cut.h5", "r") as f:
        assert len(f["/mesh"]) > 1


def test_picture_shows_the_cut_the_supports_and_gravity(cut_beam, request):
    """Issue 14 item 9: the incision's faces in red on the deformed beam, the held end marked,
    gravity's arrow, axes to scale."""
    import numpy.testing as npt

    from snede.app.plotting import draw_body, highlighted
    import matplotlib.pyplot as plt
    from test_pictures import one, to_scale

    scene, summary, _ = cut_beam
    body = scene.body
    arguments = run_scene.picture_arguments(scene, summary["method"])
    fig, ax = draw_body(body, **arguments)
    request.addfinalizer(lambda: plt.close(fig))
    faces = body.mesh.boundary_faces()
    surface = one(ax, "surface")
    r, g, b = surface.get_facecolor()[:, :3].T  # the incision's red, shaded by the light
    red = (r > 2.5 * g) & (r > 2.5 * b)
    assert red.sum() == highlighted(faces, scene.evolve.__self__.faces()).sum() == summary["incision_faces"]
    assert f"incision ({summary['incision_faces']} faces)" in [t.get_text() for t in ax.get_legend().get_texts()]
    assert len(one(ax, "fixed")._offsets3d[0]) == arguments["fixed"].sum() == body._model.n_constrained
    assert one(ax, "gravity-label").get_text().strip() == "g = 9.81 m/s²"
    assert "to scale" in ax.get_title()
    npt.assert_allclose(to_scale(ax), np.eye(2), atol=2e-3)
