"""The needle3d scene (§6.9, Figure 6.14): a short, coarse insertion converges, refines along the
shaft, writes the series with the needle node state, the pictures (cube, needle surface), the
animation and the summary, and is listed by the command line."""
from pathlib import Path

import h5py
import numpy as np
import pytest
from PIL import Image

from snede.app.scenes import builders, needle3d

from test_needle_scene import assert_insertion_converged
from test_scenes import built_and_run, not_blank


@pytest.fixture(scope="module")
def inserted(tmp_path_factory):
    """h_ref = 0.1 m / 32, one h_ref per update: about 25 updates, a few seconds."""
    return built_and_run(needle3d, "needle3d", tmp_path_factory, 32, speed=1.0)


def test_insertion_converges_refines_and_reports(inserted):
    scene, summary, _ = inserted
    assert_insertion_converged(summary, 20)
    assert summary["tetrahedra"] > 384  # refined from the 384-tetrahedron start mesh
    assert summary["mean_iterations"] < 30  # multigrid on the needle's refinement


def test_files_are_written(inserted):
    scene, summary, _ = inserted
    files = {kind: Path(path) for kind, path in summary["files"].items()}
    assert {"xdmf", "h5", "png", "gif", "needle_surface"} <= set(files)
    assert all(path.exists() for path in files.values())
    assert not_blank(files["png"]) and not_blank(files["needle_surface"])
    with Image.open(files["gif"]) as gif:
        assert gif.n_frames == summary["frames"]
    steps = Path(files["xdmf"]).read_text().count('<Grid Name="step')
    assert steps == summary["frames"]
    with h5py.File(files["h5"], "r") as f:
        state = f[f"/step/{steps - 1}/needle_state"][...]
    assert np.array_equal(state, scene.evolve.__self__.needle.node_state())


def test_the_needle_surface_is_the_boundary_of_the_needle_tetrahedra():
    # Two tetrahedra sharing a face, all vertices needle nodes: 6 outer faces; plus a face
    # elsewhere with only two needle nodes, which is not part of it.
    cells = np.array([[0, 1, 2, 3], [1, 2, 3, 4], [3, 4, 5, 6]])
    faces = needle3d.needle_faces(cells, np.array([0, 1, 2, 3, 4]))
    assert len(faces) == 6
    assert not any(set(f) == {1, 2, 3} for f in faces.tolist())
    # No needle tetrahedron (h_ref above the radius): the faces with three needle nodes.
    assert len(needle3d.needle_faces(cells, np.array([1, 2, 3]))) == 1


def test_the_scene_is_listed():
    assert "needle3d" in builders()
