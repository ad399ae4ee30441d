"""Scene files (issue 34 item 6): a scene declared in TOML runs like a built-in scene, with the
same output files (``python -m snede run my_scene.toml --out DIR``); the examples in examples/
cut and pierce a liver made from a surface. The mistakes a file can hold are in
test_scene_file_errors.py."""
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import snede
from snede.app import run_scene, scene_file
from snede.output import read_series

ROOT = Path(__file__).resolve().parents[3]
BOX = """
[mesh]
shape = "box"
size = [0.1, 0.04, 0.04]
divisions = [10, 4, 4]

[material]
name = "linear"
E = 3e4
nu = 0.3
"""


def write(folder: Path, text: str, name: str = "scene.toml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


def run_cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "snede", "--quiet", "run", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("example, name", [("liver_cut.toml", "liver-cut"), ("liver_needle.toml", "liver-needle")])
def test_the_example_scene_files_run_and_write_into_the_out_folder(example, name, tmp_path):
    out = run_cli(ROOT / "examples" / example, "--out", tmp_path / "mine", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert not (tmp_path / "out").exists()
    folder = tmp_path / "mine" / name
    assert {p.name for p in folder.iterdir()} == {f"{name}.{kind}" for kind in ("xdmf", "h5", "png", "gif")} | {
        "summary.json"}
    summary = json.loads((folder / "summary.json").read_text())
    steps = read_series(folder / f"{name}.xdmf")
    assert summary["converged"] and len(steps) == summary["frames"]
    assert steps[-1].mesh.n_cells == summary["cells"] > 3000
    if name == "liver-cut":  # the blade came down through the overhanging lobe, which sags open
        assert summary["incision_faces"] > 50 and summary["value"] > 0.01 and summary["components"] == 1
        assert steps[-1].cell_fields["incision"].sum() > 50
    else:  # 20 updates, the mesh refined along the shaft
        assert summary["updates"] == 20 and summary["needle_nodes"] > 10 and summary["cells"] > 6000
        assert (steps[-1].point_fields["needle_state"] > 0).sum() == summary["needle_nodes"]


def test_a_scene_file_without_tools_is_one_static_solve(tmp_path):
    text = BOX + """
[[hold]]
side = "x = min"

[loads]
gravity = [0.0, 0.0, -9.81]

[[loads.force]]
side = "x = max"
force = [0.0, 0.0, -2.0]
"""
    scene = scene_file.load(write(tmp_path, text))
    body = scene.body
    assert (scene.name, scene.default_method, scene.evolve) == ("scene", "cg", None)
    np.testing.assert_allclose(body.external_forces("nodal").sum(axis=0), [0.0, 0.0, -2.0])
    np.testing.assert_allclose(body.external_forces().sum(axis=0)[2], -2.0 - 1000 * 0.1 * 0.04 * 0.04 * 9.81)
    summary = run_scene.run(scene, None, None, tmp_path / "out", progress=False)
    assert summary["converged"] and summary["probe"] == "largest displacement [m]" and summary["value"] > 1e-3
    assert len(read_series(summary["files"]["xdmf"])) == 2 and Path(summary["files"]["png"]).is_file()
    held = np.isclose(body.mesh.points[:, 0], 0.0)
    assert np.all(body.displacement[held] == 0) and np.all(np.abs(body.displacement[~held]).max(axis=1) > 0)


@pytest.mark.parametrize("region, expected", [
    ('side = "x = min"', lambda x: np.isclose(x[:, 0], 0.0)),
    ('side = "z=max"\nwithin = 0.011', lambda x: x[:, 2] >= 0.029),
    ("box = {min = [0.0, 0.0, 0.0], max = [0.02, 0.04, 0.01]}", lambda x: (x[:, 0] <= 0.02) & (x[:, 2] <= 0.01)),
    ("plane = {point = [0.05, 0.0, 0.0], normal = [2.0, 0.0, 0.0]}", lambda x: np.isclose(x[:, 0], 0.05)),
    ("patch = {point = [0.1, 0.02, 0.02], radius = 0.011}",  # boundary vertices only: (0.09, 0.02, 0.02) is not
     lambda x: np.isclose(x[:, 0], 0.1) & (np.linalg.norm(x - [0.1, 0.02, 0.02], axis=1) <= 0.011)),
])
def test_each_kind_of_region_holds_the_vertices_it_names(region, expected, tmp_path):
    scene = scene_file.load(write(tmp_path, BOX + f"\n[[hold]]\n{region}\ndisplacement = [0.001, 0.0, 0.0]\n"))
    x = scene.body.mesh.points
    held = np.flatnonzero(np.all(scene.body.displacement == [0.001, 0.0, 0.0], axis=1))
    np.testing.assert_array_equal(held, np.flatnonzero(expected(x)))
    assert scene.fixed(x).sum() == len(held)


def test_the_mesh_comes_from_a_file_a_surface_or_a_shape_moved_and_refined(tmp_path):
    hold = '\n[[hold]]\nside = "z = min"\n'
    material = '\n[material]\nname = "neohookean"\nE = 3e3\nnu = 0.3\n'
    meshes = {
        "file": f'[mesh]\nfile = "{ROOT / "meshes" / "box_2x2x2.msh"}"\nscale = 0.1\ntranslate = [1.0, 0.0, 0.0]\n'
                'target_cells = 100\n',
        "surface": f'[mesh]\nsurface = "{ROOT / "meshes" / "liver2_surface.obj"}"\nsize = 0.25\n',
        "shape": '[mesh]\nshape = "ellipsoid"\nradii = [0.05, 0.03, 0.02]\nh = 0.01\n',
    }
    made = {source: scene_file.load(write(tmp_path, text + material + hold, f"{source}.toml")).body.mesh
            for source, text in meshes.items()}
    np.testing.assert_allclose(made["file"].points.min(axis=0), [1.0, 0.0, 0.0])
    np.testing.assert_allclose(made["file"].points.max(axis=0), [1.1, 0.1, 0.1])
    assert made["file"].n_cells == 192  # 48 tetrahedra bisected twice
    assert made["surface"].cell_dim == 3 and 300 < made["surface"].n_cells < 2000
    assert made["surface"].n_cells == scene_file.load(tmp_path / "surface.toml").body.mesh.n_cells  # seeded
    assert np.allclose(np.ptp(made["shape"].points, axis=0), [0.1, 0.06, 0.04], rtol=0.02)


def test_the_solver_section_reaches_the_solver(tmp_path):
    text = BOX.replace('"linear"', '"stvk"') + """
[[hold]]
side = "x = min"

[solver]
method = "ncg"
rtol = 1e-7
preconditioner = "jacobi"
max_iterations = 500
petsc = {snes_linesearch_type = "snede_newton", snes_monitor = true, snes_converged_reason = false}
"""
    scene = scene_file.load(write(tmp_path, text))
    assert (scene.default_method, scene.default_rtol) == ("ncg", 1e-7)
    assert scene.solver_options == {"preconditioner": "jacobi", "max_iterations": 500,
                                    "petsc_options": {"snes_linesearch_type": "snede_newton", "snes_monitor": None}}
    solver = run_scene.static_solver(scene, "newton", 1e-7)
    assert solver.preconditioner == "jacobi" and solver.snes.getTolerances()[3] == 500


def test_the_command_lines_material_and_method_replace_the_files(tmp_path):
    path = write(tmp_path, BOX + '\n[[hold]]\nside = "x = min"\n[loads]\ngravity = [0, 0, -9.81]\n')
    assert isinstance(scene_file.load(path, "veronda").body.material, snede.VerondaWestmann)
    out = run_cli(path, "--material", "neohookean", "--method", "ncg", "--out", tmp_path, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    summary = json.loads((tmp_path / "scene" / "summary.json").read_text())
    assert (summary["material"], summary["method"]) == ("NeoHookean", "ncg")


def test_a_needle_may_start_on_the_surface(tmp_path):
    """An entry on the surface (from Mesh.ray_hit, say), the needle going in, is outside the body."""
    tool = '[[tool]]\nkind = "needle"\nentry = [0.05, 0.0, 0.013]\ndirection = [0, 1, 0]\ndepth = 0.02\nsteps = 2\n'
    scene = scene_file.load(write(tmp_path, BOX + '\n[[hold]]\nside = "z = min"\n\n' + tool))
    assert run_scene.run(scene, None, None, tmp_path / "out", progress=False)["converged"]


def test_a_scalpel_then_a_needle_in_one_scene(tmp_path):
    """Tools run in order on the same body: the needle goes in beside the cut the blade made."""
    text = BOX + """
[[hold]]
side = "z = min"

[[tool]]
kind = "scalpel"
start = [[0.05, -0.01, 0.05], [0.05, 0.05, 0.05]]
end = [[0.05, -0.01, 0.02], [0.05, 0.05, 0.02]]
moves = 4

[[tool]]
kind = "needle"
entry = [-0.01, 0.021, 0.013]
direction = [1.0, 0.0, 0.0]
depth = 0.08
steps = 4
friction = 50.0
"""
    scene = scene_file.load(write(tmp_path, text))
    summary = run_scene.run(scene, None, None, tmp_path / "out", progress=False)
    assert summary["converged"] and summary["incision_faces"] > 0 and summary["updates"] == 4
    assert summary["frames"] == 2 + 4 + 4 and summary["probe"] == "needle force along shaft [N]"
    assert summary["value"] > 0  # the friction drags the body along the shaft


def test_the_guides_scene_file_loads(tmp_path):
    """docs/guide/meshes_and_scenes.md shows examples/liver_cut.toml abridged: it is a scene file."""
    guide = (ROOT / "docs" / "guide" / "meshes_and_scenes.md").read_text()
    (text,) = re.findall(r"```toml\n(.*?)```", guide, re.S)
    scene = scene_file.load(write(tmp_path, text.replace('"../meshes/', f'"{ROOT / "meshes"}/')))
    assert scene.name == "liver-cut" and scene.probe_name == "widest gap between the lips [m]"
