"""``import snede`` and the library's modules work without the optional extras (issue 51, item
4): a Python in which pyvista, VTK and matplotlib cannot be imported (a meta-path finder refuses
them, as if they were not installed) imports snede and every library module, solves a small box,
and never loads them; the applications (snede.app) load them only to draw, and then say which
extra to install."""
import json
import subprocess
import sys
import textwrap

BLOCKER = '''
import sys

BLOCKED = ("pyvista", "vtk", "vtkmodules", "matplotlib")


class Blocker:
    """A meta-path finder that refuses the optional extras, as if they were not installed."""

    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {name!r} (blocked)", name=name)
        return None


sys.meta_path.insert(0, Blocker())


def loaded():
    return sorted(m for m in sys.modules if m.split(".")[0] in BLOCKED)
'''


def run(code: str) -> dict:
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(BLOCKER) + textwrap.dedent(code)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_the_library_imports_and_solves_without_pyvista_vtk_and_matplotlib():
    result = run('''
        import importlib, json, pkgutil
        import numpy as np
        import snede

        library = [m.name for m in pkgutil.iter_modules(snede.__path__, "snede.")
                   if m.name not in ("snede.app", "snede.__main__")]
        for name in library:
            importlib.import_module(name)
        mesh = snede.meshing.box((0.1, 0.02, 0.02), (5, 1, 1))
        body = snede.Body(mesh, snede.LinearElastic(E=1e5, nu=0.3), density=1000.0)
        body.fix(np.isclose(mesh.points[:, 0], 0.0))
        body.add_gravity((0.0, 0.0, -9.81))
        solved = snede.StaticSolver(body, "cg").solve()
        print(json.dumps({"library": library, "converged": bool(solved.converged), "loaded": loaded(),
                          "app": sorted(m for m in sys.modules if m.startswith("snede.app"))}))
    ''')
    assert {"snede.body", "snede.mesh", "snede.meshing", "snede.static", "snede.dynamics", "snede.needle",
            "snede.cutting", "snede.output", "snede.distributed"} <= set(result["library"])
    assert result["converged"]
    assert result["loaded"] == [], f"the library loaded {result['loaded']}"
    assert result["app"] == [], f"the library loaded the applications' {result['app']}"


def test_the_applications_name_the_extra_they_need():
    """Scenes, scene files and the command line's parser load without the extras; the window
    and the pictures stop with an ImportError naming ``snede[view]`` or ``snede[plot]``."""
    result = run('''
        import json
        import snede.app.command_line, snede.app.interactive, snede.app.run_scene, snede.app.scene_file
        from snede.app import plotting
        from snede.app.scenes import builders

        scenes = sorted(builders())
        errors = {}
        try:
            import snede.app.interactive.window
        except ImportError as error:
            errors["window"] = str(error)
        try:
            plotting._figure()
        except ImportError as error:
            errors["plot"] = str(error)
        print(json.dumps({"scenes": scenes, "errors": errors, "loaded": loaded()}))
    ''')
    assert "cut" in result["scenes"]
    assert "pip install snede[view]" in result["errors"]["window"], result["errors"]
    assert "pip install snede[plot]" in result["errors"]["plot"], result["errors"]
    assert result["loaded"] == []


def command(*arguments: str) -> subprocess.CompletedProcess:
    """``python -m snede ARGUMENTS`` in a Python without the extras."""
    code = textwrap.dedent(BLOCKER) + f"import runpy\nsys.argv = ['snede', *{list(arguments)!r}]\n" \
        "runpy.run_module('snede', run_name='__main__', alter_sys=True)\n"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)


def test_the_command_line_lists_without_the_extras_and_names_the_one_view_needs():
    listed = command("list")
    assert listed.returncode == 0, listed.stderr
    assert "cantilever" in listed.stdout
    viewed = command("view", "cut")
    assert viewed.returncode == 2, viewed.stderr
    assert viewed.stderr.strip().splitlines() == [
        "python -m snede: error: the live window (python -m snede view) needs pyvista, which is not installed: "
        "pip install snede[view]"]
