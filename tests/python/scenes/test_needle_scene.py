"""The needle scene: a short insertion writes a series whose steps follow the refined mesh and
carry the needle node state, a picture, an animation and a summary."""
import json
import re
from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest
from PIL import Image

from snede.app import run_scene
from snede.app.scenes import needle

from test_scenes import built_and_run, run_cli, written_files


@pytest.fixture(scope="module")
def inserted(tmp_path_factory):
    """h_start = h2, one h_ref per update: 45 updates, a couple of seconds."""
    return built_and_run(needle, "needle", tmp_path_factory, 4, speed=1.0)


def assert_insertion_converged(summary, fewest_updates):
    """What a needle scene's summary says of its insertion: converged, by CG to rtol 1e-3, at
    least `fewest_updates` updates each rearranging the mesh, needle nodes that stick or slip,
    and a positive force along the shaft (friction drags the body along the insertion)."""
    assert summary["converged"], summary
    assert summary["method"] == "cg" and summary["rtol"] == 1e-3
    assert summary["updates"] >= fewest_updates and summary["rearrangements"] >= summary["updates"]
    assert summary["needle_nodes"] == summary["stick"] + summary["slip"] > 0
    assert summary["value"] > 0


def test_insertion_converges_and_reports_rates(inserted):
    scene, summary, out = inserted
    assert_insertion_converged(summary, 45)
    assert summary["updates"] == 45 and summary["update_rate_hz"] > 0
    assert json.loads((out / "needle" / "summary.json").read_text())["rearrangements"] == summary["rearrangements"]


def test_files_are_written(inserted):
    _, summary, _ = inserted
    files = written_files(summary)
    with Image.open(files["gif"]) as gif:
        assert gif.n_frames == summary["frames"]


def test_series_follows_the_refined_mesh_with_the_node_state(inserted):
    scene, summary, _ = inserted
    xdmf = Path(summary["files"]["xdmf"])
    steps = xdmf.read_text().count('<Grid Name="step')
    assert steps == summary["frames"] and 10 <= steps <= 52  # every few updates, plus start and end
    with h5py.File(summary["files"]["h5"], "r") as f:
        assert len(f["/mesh"]) > 1  # the mesh was refined at the tip: new meshes in the series
        state = f[f"/step/{steps - 1}/needle_state"][...]
    assert np.array_equal(state, scene.evolve.__self__.needle.node_state())
    assert (state == 1).sum() == summary["stick"] and (state == 2).sum() == summary["slip"]
    points = [int(n) for n in re.findall(r'<DataItem Dimensions="(\d+) 3"[^>]*>[^<]*/points<', xdmf.read_text())]
    with meshio.xdmf.TimeSeriesReader(xdmf) as reader:
        reader.read_points_cells()
        for k in range(reader.num_steps):
            depth, point_data, _ = reader.read_data(k)
            assert point_data["needle_state"].shape == (points[k],)
            assert set(np.unique(point_data["needle_state"])) <= {0.0, 1.0, 2.0}
    assert depth == pytest.approx(0.07) and points[-1] == summary["points"]


def test_cli_runs_the_needle(tmp_path):
    out = run_cli("--quiet", "run", "needle", "--divisions", "4", "--speed", "3", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    assert "needle force along shaft" in out.stdout and "rearrangements" in out.stdout
    assert (tmp_path / "needle" / "needle.gif").exists()


@pytest.mark.parametrize("args, message", [
    (("--method", "dynamic"), "cg, ncg, newton"),
    (("--divisions", "6"), "power of 2"),
    (("--speed", "0"), "must be positive"),
])
def test_bad_needle_options_give_a_message(args, message, tmp_path):
    out = run_cli("run", "needle", *args, "--out", str(tmp_path))
    assert out.returncode != 0 and message in out.stderr and "Traceback" not in out.stderr


def test_picture_shows_the_refined_mesh_the_supports_and_the_needle(inserted, request):
    """Issue 14 item 9: the mesh's edges (the refined mesh's), the held side marked, to scale."""
    from snede.app.plotting import draw_body, mesh_edges
    import matplotlib.pyplot as plt
    from test_pictures import by_gid, one

    scene, summary, _ = inserted
    body = scene.body
    arguments = run_scene.picture_arguments(scene, summary["method"])
    fig, ax = draw_body(body, **arguments)
    request.addfinalizer(lambda: plt.close(fig))
    assert "to scale" in ax.get_title() and ax.get_aspect() == 1.0
    assert len(one(ax, "mesh-edges").get_segments()) == len(mesh_edges(body.mesh.cells))
    # The engine counts the needle's nodes too (held or sliding along the needle).
    assert len(one(ax, "fixed").get_xdata()) == arguments["fixed"].sum() == 2 ** 2 + 1
    assert arguments["fixed"].sum() + summary["needle_nodes"] == body._model.n_constrained
    assert not by_gid(ax, "loads")  # the needle and its nodes show the friction
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert f"stick ({summary['stick']})" in labels and f"slip ({summary['slip']})" in labels
