"""The README's code, run as written (issue 38, item 9): its statements are what a reader
copies, so they must work as they stand, with what the README says is needed around them."""
import re
import subprocess
import sys
from pathlib import Path

import snede
from snede.output import SeriesWriter

README = Path(__file__).resolve().parents[2] / "README.md"


def inline_code(containing: str) -> list[str]:
    """The README's `inline code` spans that contain ``containing``."""
    return [span for span in re.findall(r"`([^`\n]+)`", README.read_text()) if containing in span]


def test_the_membrane_of_the_readme_is_built_from_boundary_surface_as_written():
    """boundary_surface gives (surface, vertex ids); the README passed that tuple to Body."""
    namespace = {"snede": snede, "box": snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)),
                 "material": snede.NeoHookean(E=3e3, nu=0.3)}
    statements = [span for span in inline_code("boundary_surface(box)") if re.match(r"surface\b.*=", span)]
    assert statements, "the README shows boundary_surface(box) without what it returns"
    for statement in statements:
        exec(statement, namespace)
        (body_statement,) = inline_code("snede.Body(surface, material")
        body = eval(body_statement, namespace)
        assert body.mesh.is_surface and body.mesh.n_cells == 48


def run_python(code: str, cwd: Path) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter (what a reader's script starts from), in ``cwd``."""
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True, timeout=300)


def test_read_series_of_the_readme_needs_only_import_snede(tmp_path):
    """``snede.output.read_series(...)`` raised AttributeError unless snede.output had been
    imported; importing snede still does not load h5py (the output module loads on first use)."""
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    SeriesWriter(tmp_path / "out" / "sheet-cut" / "sheet-cut").write_mesh(mesh, 0.5)
    (statement,) = [span for span in inline_code("snede.output.read_series(") if span.endswith(")")]
    done = run_python("import sys\nimport snede\nassert 'h5py' not in sys.modules\n"
                      f"steps = {statement}\nprint(len(steps), steps[0].time)", tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["1", "0.5"]


def python_blocks(containing: str = "") -> list[str]:
    """The README's ```python blocks that contain ``containing``."""
    return [block for block in re.findall(r"```python\n(.*?)```", README.read_text(), re.S) if containing in block]


def test_every_python_block_of_the_readme_is_python():
    """A command line inside a python block (``python myscript.py -static_pc_type gamg``) is a
    syntax error where a reader pastes it; placeholders (``u``, ``vertices``) are not checked."""
    for block in python_blocks():
        compile(block, "README.md", "exec")


def test_the_scene_of_your_own_of_the_readme_runs_as_written(tmp_path):
    """The README's copy of examples/sagging_beam.py lacked its imports (SeriesWriter, plot_body)."""
    (block,) = python_blocks("sagging_beam")
    done = run_python(block, tmp_path)
    assert done.returncode == 0, done.stderr
    assert re.match(r"converged \(CONVERGED_FNORM_ABS\) after \d+ iterations.* MFLOP$", done.stdout.strip())
    assert (tmp_path / "out" / "sagging_beam" / "sagging_beam.xdmf").is_file()
    assert (tmp_path / "out" / "sagging_beam" / "sagging_beam.png").is_file()
