"""Every kind of mistake in a scene file gives one line naming the file and the key (issue 34
item 6): a missing section, an unknown key (with the nearest known one), a wrong type, a bad
value, a missing mesh file, an unknown material, a region that picks nothing, a tool path that
misses the body or leaves it. On the command line: that line after ``python -m snede: error:``,
exit status 2, no traceback, nothing written."""
import subprocess
import sys

import pytest

from snede.app import scene_file
from test_scene_files import BOX, ROOT

GOOD = BOX + """
[[hold]]
side = "x = min"

[loads]
gravity = [0.0, 0.0, -9.81]
"""
BOX_SHAPE = 'shape = "box"\nsize = [0.1, 0.04, 0.04]\ndivisions = [10, 4, 4]'
SCALPEL = '\n[[tool]]\nkind = "scalpel"\nstart = [[0.05, -0.01, 0.03], [0.05, 0.03, 0.03]]\n' \
          'end = [[0.05, -0.01, 0.01], [0.05, 0.03, 0.01]]\nmoves = 3\n'
LIVER = ROOT / "meshes" / "liver2_surface.obj"
NEEDLE = '\n[[tool]]\nkind = "needle"\nentry = [0.05, -0.1, 0.01]\ndirection = [0, 1, 0]\ndepth = 0.01\nsteps = 3\n'


def edited(*changes) -> str:
    """GOOD with each (old, new) replaced, or a string appended."""
    text = GOOD
    for change in changes:
        if isinstance(change, str):
            text += change
        else:
            assert change[0] in text, change[0]
            text = text.replace(*change)
    return text


MISTAKES = {
    # missing sections
    "no mesh": (edited((f"[mesh]\n{BOX_SHAPE}\n", "")),
                "[mesh] is missing: a scene file needs [mesh], [material] and at least one [[hold]]"),
    "no material": (edited(('[material]\nname = "linear"\nE = 3e4\nnu = 0.3\n', "")), "[material] is missing"),
    "no hold": (edited(('[[hold]]\nside = "x = min"\n', "")), "[[hold]] is missing: a scene needs at least one"),
    "a required key": (edited(("nu = 0.3\n", "")), "material.nu is missing: Poisson's ratio, a number in (-1, 0.5)"),
    "a tool's required key": (edited(SCALPEL.replace("moves = 3\n", "")),
                              "tool[1].moves is missing: how many steps the blade takes from start to end"),
    # unknown keys, with the nearest known one
    "a misspelled section": (edited(("[material]", "[materail]")),
                             "materail is not a key of a scene file; did you mean material? (its keys: name, "
                             "description, mesh, material, hold, loads, solver, tool)"),
    "a misspelled key": (edited(("nu = 0.3", "nu = 0.3\ndensty = 900")),
                         "material.densty is not a key of [material]; did you mean material.density? (its keys: "
                         "name, E, nu, gamma, density, formulation)"),
    "a misspelled required key": (edited(("E = 3e4", "e = 3e4")),
                                  "material.e is not a key of [material]; did you mean material.E?"),
    "a key unlike any": (edited(("E = 3e4", "E = 3e4\nstiffness = 2")),
                         "material.stiffness is not a key of [material] (its keys: name, E, nu, gamma, density, "
                         "formulation)"),
    "a key of a region": (edited(('side = "x = min"', 'side = "x = min"\nwithn = 0.01')),
                          "hold[1].withn is not a key of [hold[1]]; did you mean hold[1].within?"),
    "a key of a tool": (edited(SCALPEL.replace("moves = 3", "moves = 3\nstrat = 2")),
                        "tool[1].strat is not a key of [tool[1]]; did you mean tool[1].start?"),
    "a key of the other source": (edited(("divisions = [10, 4, 4]", "divisions = [10, 4, 4]\nradii = [1, 1, 1]")),
                                  "mesh.radii is not a key of [mesh]"),
    # wrong types
    "a string for a number": (edited(("E = 3e4", 'E = "soft"')), 'material.E must be a positive number, got "soft"'),
    "a float for an integer": (edited(("[10, 4, 4]", "[10, 4.5, 4]")),
                               "mesh.divisions must be 3 positive integers, got [10, 4.5, 4]"),
    "a number for a vector": (edited(("gravity = [0.0, 0.0, -9.81]", "gravity = -9.81")),
                              "loads.gravity must be 3 numbers [x, y, z], got -9.81"),
    "a boolean for a number": (edited(("nu = 0.3", "nu = true")),
                               "material.nu must be a number in (-1, 0.5), got true"),
    "a table for an array of tables": (edited(("[[hold]]", "[hold]")),
                                       "hold must be an array of tables, each written [[hold]], got "
                                       '{side = "x = min"}'),
    "a value for a table": (edited(("[mesh]", 'solver = "newton"\n\n[mesh]')),
                            'solver must be a table ([solver] or {...}), got "newton"'),
    "not TOML at all": (edited(("E = 3e4", "E = ")), "not valid TOML: Invalid value (at line 9, column 5)"),
    "TOML nested 5 000 deep": (edited("x = " + "[" * 5000 + "]" * 5000 + "\n"),
                               "nests arrays or tables too deeply to be read"),
    # bad values
    "a negative modulus": (edited(("E = 3e4", "E = -3")), "material.E must be a positive number, got -3"),
    "an incompressible material": (edited(("nu = 0.3", "nu = 0.5")),
                                   "material.nu must be a number in (-1, 0.5), got 0.5"),
    "a side that is none": (edited(('"x = min"', '"left"')),
                            'hold[1].side must be a side such as "x = min" or "z = max", got "left"'),
    "two regions in one hold": (edited(("side", "patch = {point = [0, 0, 0], radius = 1}\nside")),
                                "hold[1] needs exactly one of side, box, plane, patch, group, got side, patch"),
    "an empty box": (edited(('side = "x = min"', "box = {min = [0, 0, 0], max = [1, -1, 1]}")),
                     "hold[1].box.max must be at least hold[1].box.min in every coordinate"),
    "a region that picks nothing": (edited(('side = "x = min"', "box = {min = [1, 1, 1], max = [2, 2, 2]}")),
                                    "hold[1].box (box from [1.0, 1.0, 1.0] to [2.0, 2.0, 2.0]) picks no vertex of "
                                    "the mesh (it spans [0.0, 0.0, 0.0] to [0.1, 0.04, 0.04])"),
    "a zero direction": (edited(NEEDLE.replace("[0, 1, 0]", "[0, 0, 0]")),
                         "tool[1].direction must be 3 numbers [x, y, z], not all 0, got [0, 0, 0]"),
    "a blade of no length": (edited(SCALPEL.replace("[[0.05, -0.01, 0.03], [0.05, 0.03, 0.03]]",
                                                    "[[0.05, -0.01, 0.03], [0.05, -0.01, 0.03]]")),
                             "tool[1].start must be two points [[x, y, z], [x, y, z]]"),
    "a friction that is none": (edited(NEEDLE + "friction = [[0.1, 3.0]]\n"),
                                "tool[1].friction must be a force per unit of shaft surface in N/m²"),
    "a method the material cannot take": (edited(('"linear"', '"neohookean"'), '\n[solver]\nmethod = "cg"\n'),
                                          'solver.method "cg" is linear CG, for name = "linear" only; the material '
                                          'is "neohookean"'),
    "a method a tool cannot take": (edited('\n[solver]\nmethod = "ncg"\n' + NEEDLE),
                                    'solver.method "ncg" cannot relax the needle of tool[1]: it takes cg or newton'),
    "a damping without dynamics": (edited('\n[solver]\ndamping = 3.0\n'),
                                   'solver.damping applies to method = "dynamic" only'),
    "a PETSc option with its dash": (edited('\n[solver]\npetsc = {"-ksp_monitor" = true}\n'),
                                     "solver.petsc.-ksp_monitor is not a PETSc option name"),
    "a gamma of another material": (edited(("nu = 0.3", "nu = 0.3\ngamma = 3")),
                                    'material.gamma is the nonlinearity of name = "veronda", not of "linear"'),
    "an unknown formulation": (edited(("nu = 0.3", 'nu = 0.3\nformulation = "p2"')),
                               'material.formulation must be one of "p1", "smoothed"'),
    "a needle before a scalpel": (edited(NEEDLE + SCALPEL),
                                  "tool[2] comes after the needle of tool[1]: a needle stays in the body"),
    "a shape gmsh cannot make": (edited((BOX_SHAPE, 'shape = "torus"\nradius = 0.01\ntube = 0.02')),
                                 'mesh.shape "torus" could not be made: tube (0.02) must be smaller than radius '
                                 '(0.01)'),
    "a name that is no folder": (edited(("[mesh]", 'name = "../up"\n\n[mesh]')),
                                 "name must be a name of letters, digits, '-', '_' or '.' (the output folder's), "
                                 'got "../up"'),
    # one number that would ask for unbounded work (issue 48, item 10)
    "a billion moves": (edited(SCALPEL.replace("moves = 3", "moves = 1000000000")),
                        "tool[1].moves must be a positive integer up to 1000 (each is a relaxation, a step of the "
                        "series and a frame of the GIF), got 1000000000"),
    "a billion steps": (edited(NEEDLE.replace("steps = 3", "steps = 1000000000")),
                        "tool[1].steps must be a positive integer up to 1000"),
    "a needle's h_ref in nanometres": (edited(NEEDLE + "h_ref = 1e-9\n"),
                                       "tool[1].h_ref 1e-09 m would make about 3e+20 tetrahedra (limit 10000000); "
                                       "give a larger h_ref (each halving makes 8 times as many), or raise "
                                       "mesh.max_cells if you mean it"),
    "a surface filled at a micrometre": (edited((BOX_SHAPE, f'surface = "{LIVER}"\nsize = 1e-6')),
                                         "mesh.surface could not be filled with tetrahedra: size = 1e-06 would make "
                                         "about "),
    "a gmsh shape at a nanometre": (edited((BOX_SHAPE, 'shape = "cylinder"\nh = 1e-9')),
                                    'mesh.shape "cylinder" could not be made: h = 1e-09 would make about 1.2e+24 '
                                    "tetrahedra (limit 10000000)"),
    "a box of a billion cubes": (edited(("[10, 4, 4]", "[1000, 1000, 1000]")),
                                 "mesh.divisions [1000, 1000, 1000] would make about 6e+09 tetrahedra (limit "
                                 "10000000); give fewer divisions, or raise mesh.max_cells if you mean it"),
    "a target beyond the limit": (edited(("[10, 4, 4]", "[10, 4, 4]\ntarget_cells = 20000\nmax_cells = 10000")),
                                  "mesh.target_cells 20000 would make about 2e+04 tetrahedra (limit 10000); give a "
                                  "smaller one, or raise mesh.max_cells if you mean it"),
    # missing files, unknown materials and shapes
    "a missing mesh file": (edited((BOX_SHAPE, 'file = "no_such.msh"')), "mesh.file names no file: "),
    "a missing surface": (edited((BOX_SHAPE, 'surface = "liver.stl"\nsize = 0.01')), "mesh.surface names no file: "),
    "an unknown material": (edited(('"linear"', '"rubber"')),
                            'material.name must be one of "linear", "stvk", "neohookean", "veronda", got "rubber"'),
    "an unknown shape": (edited(('"box"', '"sphere"')),
                         'mesh.shape must be one of "box", "ellipsoid", "cylinder", "torus", "lumpy", got "sphere"'),
    # tool paths that miss the body or leave it
    "a sweep that misses the body": (edited(SCALPEL.replace("[0.05, ", "[0.5, ")),
                                     "tool[1] never meets the body: the blade's sweep from start"),
    "a needle whose line misses the body": (edited(NEEDLE.replace("0.01]", "0.5]", 1)),
                                            "tool[1].entry [0.05, -0.1, 0.5] with direction [0.0, 1.0, 0.0]: the "
                                            "needle's line never meets the body"),
    "a needle that starts inside": (edited(NEEDLE.replace("[0.05, -0.1, 0.01]", "[0.05, 0.01, 0.01]")),
                                    "tool[1].entry [0.05, 0.01, 0.01] is inside the body"),
    "a needle that points out of the body": (edited(NEEDLE.replace("[0.05, -0.1, 0.01]", "[0.05, 0.0, 0.01]")
                                                    .replace("[0, 1, 0]", "[0, -1, 0]")),
                                             "tool[1].direction [0.0, -1.0, 0.0] points out of the body at the entry "
                                             "[0.05, 0.0, 0.01], which is on its surface"),
    "a needle that comes out the other side": (edited(NEEDLE.replace("depth = 0.01", "depth = 0.05")),
                                               "tool[1].depth 0.05 m takes the tip out of the body: the needle's line "
                                               "leaves it 0.04 m past the entry point [0.05, 0.0, 0.01]"),
}


@pytest.mark.parametrize("mistake", MISTAKES)
def test_a_mistake_is_one_line_naming_the_file_and_the_key(mistake, tmp_path):
    text, message = MISTAKES[mistake]
    path = tmp_path / "my_scene.toml"
    path.write_text(text)
    with pytest.raises(scene_file.SceneFileError) as raised:
        scene_file.load(path)
    line = str(raised.value)
    assert line.startswith(f"{path}: ") and "\n" not in line
    assert message in line, line


def test_the_good_file_of_these_mistakes_loads(tmp_path):
    for extra in ("", SCALPEL, NEEDLE):
        (tmp_path / "good.toml").write_text(GOOD + extra)
        scene_file.load(tmp_path / "good.toml")


def test_a_missing_scene_file_is_named(tmp_path):
    with pytest.raises(scene_file.SceneFileError, match=r"nothere\.toml: no such scene file$"):
        scene_file.load(tmp_path / "nothere.toml")


def test_max_cells_is_the_limit_a_user_can_raise(tmp_path):
    path = tmp_path / "fine.toml"
    path.write_text(edited(("[10, 4, 4]", "[10, 4, 4]\nmax_cells = 959")))  # the box has 960 tetrahedra
    with pytest.raises(scene_file.SceneFileError, match="about 9.6e.02 tetrahedra .limit 959."):
        scene_file.load(path)
    path.write_text(edited(("[10, 4, 4]", "[10, 4, 4]\nmax_cells = 960")))
    assert scene_file.load(path).body.mesh.n_cells == 960


@pytest.mark.parametrize("mistake", ["a negative modulus", "a misspelled section", "a missing mesh file",
                                     "a needle that comes out the other side", "TOML nested 5 000 deep",
                                     "a needle's h_ref in nanometres", "a billion moves"])
def test_the_command_line_says_the_line_and_exits_with_status_2(mistake, tmp_path):
    text, message = MISTAKES[mistake]
    (tmp_path / "my_scene.toml").write_text(text)
    out = subprocess.run([sys.executable, "-m", "snede", "run", "my_scene.toml", "--out", "here"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 2
    (line,) = out.stderr.splitlines()
    assert line.startswith("python -m snede: error: my_scene.toml: ") and message in line
    assert not (tmp_path / "here").exists()
