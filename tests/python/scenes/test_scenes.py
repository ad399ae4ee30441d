"""Scenes, the command line, output files and pictures."""
import json
import re
import subprocess
import sys
from pathlib import Path

import h5py
import meshio
import numpy as np
import pytest

import snede
from snede.app import run_scene
from snede.output import SeriesWriter
from snede.app.scenes import Parameters, builders

ROOT = Path(__file__).resolve().parents[3]
SMALL = {"cantilever": dict(divisions=8), "cylinder": dict(), "slab": dict(divisions=8)}


def options(**given):
    return Parameters(material=given.get("material"), divisions=given.get("divisions"),
                      mesh_size=given.get("mesh_size"))


def read_step(h5_path, step, mesh):
    with h5py.File(h5_path, "r") as f:
        return f[f"/step/{step}/displacement"][...], f[f"/mesh/{mesh}/cells"][...], f[f"/mesh/{mesh}/points"][...]


def not_blank(png_path):
    import matplotlib.image

    image = matplotlib.image.imread(png_path)
    return image.std() > 0.05 and len(np.unique(image.reshape(-1, image.shape[-1]), axis=0)) > 50


@pytest.mark.parametrize("name", ["cantilever", "cylinder", "slab"])
def test_builtin_scene_runs_and_writes_what_it_computed(name, tmp_path):
    scene = builders()[name].build(options(**SMALL[name]))
    summary = run_scene.run(scene, None, 1e-6, tmp_path, progress=False)
    assert summary["converged"], summary
    body = scene.body
    u, cells, points = read_step(summary["files"]["h5"], 1, 0)
    dim = body.dim
    assert np.array_equal(u[:, :dim], body.displacement)
    assert np.array_equal(cells, body.mesh.cells)
    assert np.array_equal(points[:, :dim], body.mesh.points)
    assert not_blank(summary["files"]["png"])
    saved = json.loads((tmp_path / name / "summary.json").read_text())
    assert saved["iterations"] == summary["iterations"] and saved["reason"] == summary["reason"]
    xdmf = Path(summary["files"]["xdmf"]).read_text()
    # The unloaded state and the solution, on the cells of the body's dimension. (This was one
    # assert `a and b if dim == 3 else c`, which checked only the cell name in 2D.)
    assert xdmf.count("<Grid Name=\"step") == 2
    assert ("Tetrahedron" if dim == 3 else "Triangle") in xdmf
    assert ("Triangle" if dim == 3 else "Tetrahedron") not in xdmf


def test_cantilever_scene_reports_error_against_beam_theory(tmp_path):
    scene = builders()["cantilever"].build(options(divisions=8))
    summary = run_scene.run(scene, "cg", 1e-8, tmp_path, progress=False)
    assert summary["analytic"] == pytest.approx(8.64e-3)
    assert summary["error_percent"] == pytest.approx(100 * (1 - summary["value"] / 8.64e-3))
    assert 0 < summary["error_percent"] < 60  # 8 × 2 × 2 cubes: coarse, stiffer than the beam


def test_formulation_option_reaches_the_body(tmp_path):
    """--formulation smoothed on the §3.3 cantilever: the body is built smoothed and its tip is
    closer to beam theory than p1's on the same mesh (P1 tetrahedra are stiff in bending)."""
    errors = {}
    for formulation in ("p1", "smoothed"):
        out = run_cli("run", "cantilever", "--formulation", formulation, "--out", str(tmp_path / formulation))
        assert out.returncode == 0, out.stderr
        summary = json.loads((tmp_path / formulation / "cantilever" / "summary.json").read_text())
        errors[formulation] = abs(summary["error_percent"])
    assert errors["smoothed"] < 0.5 * errors["p1"], errors


def test_series_follows_a_topology_change(tmp_path):
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = snede.Body(mesh, snede.LinearElastic(1e3, 0.3))
    writer = SeriesWriter(tmp_path / "cut")
    body.displacement = 0.01 * mesh.points
    writer.write(body, 0.0)
    writer.write(body, 0.5)  # same mesh: not written again
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5)))
    writer.write(body, 1.0)
    assert (writer.n_steps, writer.n_meshes) == (3, 2)
    u, cells, points = read_step(writer.h5_path, 2, 1)
    assert np.array_equal(u, body.displacement) and np.array_equal(cells, mesh.cells)
    assert len(points) == mesh.n_points == 27 + 9
    with h5py.File(writer.h5_path, "r") as f:
        assert len(f["/mesh/0/points"]) == 27 and "2" not in f["/mesh"]
    xdmf = writer.xdmf_path.read_text()
    assert xdmf.count("/mesh/0/cells") == 2 and xdmf.count("/mesh/1/cells") == 1


def test_series_writes_point_fields_that_meshio_reads_and_refuses_a_wrong_length(tmp_path):
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    writer = SeriesWriter(tmp_path / "points")
    writer.write_mesh(mesh, 0.0, point_fields={"height": mesh.points[:, 1]})
    with meshio.xdmf.TimeSeriesReader(str(writer.xdmf_path)) as reader:
        reader.read_points_cells()
        _, point_data, _ = reader.read_data(0)
    np.testing.assert_array_equal(point_data["height"], mesh.points[:, 1])
    with pytest.raises(ValueError, match="point field 'height' has 3 values for 9 points"):
        writer.write_mesh(mesh, 1.0, point_fields={"height": [1.0, 2.0, 3.0]})


def red_pixels(image) -> int:
    """Pixels of the incision's red (shaded), which the viridis colours of |u| never give."""
    rgb = np.asarray(image.convert("RGB"), dtype=float) / 255
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(((r > 0.35) & (r > 2.5 * g) & (r > 2.5 * b)).sum())


def assert_gif_shows_the_cut(path, frames: int, red_at_end: int) -> None:
    """The animation has `frames` frames, no incision red in the first and more than
    `red_at_end` red pixels in the last."""
    from PIL import Image

    with Image.open(path) as gif:
        assert gif.n_frames == frames
        gif.seek(0)
        assert red_pixels(gif) == 0  # not yet cut
        gif.seek(gif.n_frames - 1)
        assert red_pixels(gif) > red_at_end


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "snede", *args], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=300)


def written_files(summary, kinds=("xdmf", "h5", "png", "gif")):
    """The files a scene's summary lists, by kind, checked: exactly `kinds`, none empty, and
    the picture ("png") not blank."""
    files = {kind: Path(path) for kind, path in summary["files"].items()}
    assert set(files) == set(kinds)
    assert all(path.stat().st_size > 0 for path in files.values())
    assert not_blank(files["png"])
    return files


def built_and_run(module, folder, tmp_path_factory, divisions, speed=None):
    """The scene of `module` built with these options (no material or mesh size) and run into
    a fresh folder named `folder`: the scene, its summary and the folder."""
    out = tmp_path_factory.mktemp(folder)
    scene = module.build(Parameters(divisions=divisions, speed=speed))
    return scene, run_scene.run(scene, None, None, out, progress=False), out


def run_cutting_scene_cli(scene, divisions, out_dir, move, loaded, material, method):
    """Runs a cutting scene from the command line and checks what each prints: a line per move
    (numbered 1 to the last, `move` after the number, its relaxation converged), the loading
    solve's line (`loaded`, converged), the summary row (material, method, converged) and the
    four output files. Returns the finished process."""
    out = run_cli("run", scene, "--divisions", str(divisions), "--out", str(out_dir))
    assert out.returncode == 0, out.stderr
    moves = re.findall(rf"^{scene}: move +(\d+)/(\d+), {move}; relaxed: converged \(CONVERGED_\w+\)", out.stdout, re.M)
    assert moves and [int(k) for k, _ in moves] == list(range(1, int(moves[0][1]) + 1)), out.stdout
    assert re.search(rf"^{scene}: {loaded}: converged \(CONVERGED_\w+\)", out.stdout, re.M), out.stdout
    assert re.search(rf"^{scene}\s+\d+\s+{material}\s+{method}\s+\d+\s+CONVERGED_\w+\s", out.stdout, re.M), out.stdout
    assert all((out_dir / scene / f"{scene}.{kind}").exists() for kind in ("xdmf", "h5", "png", "gif"))
    return out


def test_list_and_help():
    listed = run_cli("list")
    assert listed.returncode == 0 and all(name in listed.stdout for name in ("cantilever", "cylinder", "slab"))
    helped = run_cli("run", "--help")
    assert helped.returncode == 0 and "--material" in helped.stdout and "PETSc" in run_cli("--help").stdout
    assert "--quiet" in helped.stdout  # also accepted after `run` (issue 14 item 4)


def test_single_dash_help_is_petscs_and_then_snedes():
    """`-help` was parsed by argparse as `-h elp`. Now it is PETSc's option: without a command,
    PETSc's general help and then snede's usage, exit 0."""
    out = run_cli("-help")
    assert out.returncode == 0, out.stderr
    assert "PETSc" in out.stdout and "usage: python -m snede" in out.stdout
    assert re.search(r"\{list,run,demo(,\w+)*\}", out.stdout), out.stdout  # snede's commands
    assert "elp" not in out.stderr and "Traceback" not in out.stderr


def test_single_dash_help_with_a_scene_lists_its_solvers_options(tmp_path):
    out = run_cli("--quiet", "run", "slab", "--divisions", "4", "--out", str(tmp_path), "-help")
    assert out.returncode == 0, out.stderr
    assert "-static_ksp_type" in out.stdout  # PETSc's help for the scene's KSP


def test_snede_arguments_do_not_reach_petscs_options_database(tmp_path):
    """petsc4py.init got all of sys.argv: `-m run` became the option -m, `--method cg` -method.
    A scene script run by the command line prints PETSc's database: only the PETSc option."""
    script = tmp_path / "show_options.py"
    script.write_text("import snede\nprint('OPTIONS', sorted(snede.PETSc.Options().getAll()))\n")
    out = run_cli("--quiet", "run", str(script), "--method", "cg", "-static_ksp_rtol", "-1e-3", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    line = next(l for l in out.stdout.splitlines() if l.startswith("OPTIONS"))
    names = eval(line[len("OPTIONS"):])
    assert "static_ksp_rtol" in names
    assert not {"m", "method", "run", "quiet"} & set(names), names


def test_misspelled_petsc_options_are_reported_at_the_end(tmp_path):
    out = run_cli("--quiet", "run", "slab", "--divisions", "4", "--out", str(tmp_path),
                  "-static_ksp_monitr", "-static_ksp_rtol", "1e-9", "-dynamic_ts_monitor", "-malloc_dump_x")
    assert out.returncode == 0, out.stderr
    assert "-static_ksp_monitr was not used" in out.stderr
    assert "-dynamic_ts_monitor was not used" in out.stderr  # the slab solves statically
    assert "static_ksp_rtol" not in out.stderr  # read by the KSP
    assert "-malloc_dump_x was not used" in out.stderr  # a global option too (issue 38 item 5)


def test_a_nonlinear_material_alone_chooses_newton(tmp_path):
    """--material neohookean on a scene whose default method is linear CG failed (CG refuses a
    nonlinear material); without --method the method now fits the material."""
    out = run_cli("--quiet", "run", "cantilever", "--divisions", "4", "--material", "neohookean",
                  "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    assert re.search(r"^cantilever\s+\d+\s+NeoHookean\s+newton\s+\d+\s+CONVERGED_\w+\s", out.stdout, re.M), out.stdout
    scene = builders()["slab"].build(options(divisions=4, material="stvk"))
    assert run_scene.fitting_method(scene) == "newton"
    assert run_scene.fitting_method(builders()["slab"].build(options(divisions=4))) == "cg"


@pytest.mark.parametrize("args, message", [
    (("run", "nosuchscene"), "unknown scene"),
    (("run", "cantilever", "--rtol", "-1"), "must be positive"),
    (("run", "cantilever", "--divisions", "5"), "multiple of 4"),
    (("run", "cantilever", "--material", "rubber"), "invalid choice"),
    (("run", "cylinder", "--method", "cg"), "LinearElastic"),
    (("run", "cantilever", "stray"), "unexpected argument"),
    # issue 14 item 4: a misspelled snede option was passed to PETSc and ignored
    (("run", "cantilever", "--materail", "veronda"), "unknown option(s): --materail"),
    (("run", "cantilever", "--divisions=8", "--quite"), "unknown option(s): --quite"),
    # a bad PETSc value: the message, not a traceback
    (("run", "cantilever", "--divisions", "4", "-static_ksp_type", "foo"), "Unable to find requested KSP type foo"),
    (("run", "cantilever", "--divisions", "4", "--method", "newton", "-static_snes_type", "foo"),
     "Unable to find requested SNES type foo"),
    # --divisions 0 was the default; -8 said "multiple of 4"
    (("run", "cantilever", "--divisions", "0"), "--divisions: must be positive, got 0"),
    (("run", "cantilever", "--divisions", "-8"), "--divisions: must be positive, got -8"),
    (("run", "needle", "--divisions", "0"), "--divisions: must be positive, got 0"),
    # options that do not apply to the scene were ignored
    (("run", "cylinder", "--divisions", "8"), "--divisions does not apply to the cylinder scene"),
    (("run", "cantilever", "--mesh-size", "0.05"), "--mesh-size does not apply to the cantilever scene"),
    (("run", "slab", "--mesh-size", "0.05"), "--mesh-size does not apply to the slab scene"),
    (("run", "needle", "--mesh-size", "0.05"), "--mesh-size does not apply to the needle scene"),
    (("run", "slab", "--speed", "1"), "--speed does not apply to the slab scene"),
])
def test_bad_input_gives_a_message_not_a_traceback(args, message, tmp_path):
    out = run_cli(*args, "--out", str(tmp_path)) if args[-1] != "stray" else run_cli(*args)
    assert out.returncode == 2, out.stderr
    assert message in out.stderr
    assert "Traceback" not in out.stderr


def test_cli_runs_a_scene_with_petsc_options(tmp_path):
    out = run_cli("--quiet", "run", "slab", "--divisions", "4", "--out", str(tmp_path), "-static_ksp_monitor")
    assert out.returncode == 0, out.stderr
    assert "KSP Residual norm" in out.stdout
    # The summary row's reason column, not any "CONVERGED" in the monitor output.
    assert re.search(r"^slab\s+\d+\s+LinearElastic\s+cg\s+\d+\s+CONVERGED_\w+\s", out.stdout, re.M), out.stdout
    assert (tmp_path / "slab" / "slab.xdmf").exists()


def test_user_scene_script_runs(tmp_path):
    script = ROOT / "examples" / "sagging_beam.py"
    out = run_cli("run", str(script), cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    # A script's exit status does not carry the solve's outcome, and "converged" is also in
    # "NOT converged": the line the script prints must start with it.
    assert re.search(r"^converged \(CONVERGED_\w+\) after \d+ iterations", out.stdout, re.M), out.stdout
    assert "NOT converged" not in out.stdout
    assert not_blank(tmp_path / "out" / "sagging_beam" / "sagging_beam.png")


def test_argv_split_gives_petsc_only_single_dash_options_and_their_values():
    from snede._argv import split

    others, petsc = split(["run", "cantilever", "--method", "cg", "-static_ksp_rtol", "-1e-8", "-log_view",
                           "--divisions", "-8", "-h", "-static_ksp_monitor", "-h", "--quiet"])
    assert petsc == ["-static_ksp_rtol", "-1e-8", "-log_view", "-static_ksp_monitor"]
    assert others == ["run", "cantilever", "--method", "cg", "--divisions", "-8", "-h", "-h", "--quiet"]
