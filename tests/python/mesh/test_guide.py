"""docs/guide/meshes_and_scenes.md as written: its Python runs from the repository's root, and the
messages it quotes are the ones snede gives."""
import re
import subprocess
import sys
from pathlib import Path

import snede
from expected_errors import refused

ROOT = Path(__file__).resolve().parents[3]
GUIDE = ROOT / "docs" / "guide" / "meshes_and_scenes.md"


def test_the_guides_python_runs():
    code = "\n".join(re.findall(r"```python\n(.*?)```", GUIDE.read_text(), re.S))
    done = subprocess.run([sys.executable, "-c", code + "\nassert hit is not None and len(held) > 3\n"], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "Warning" not in done.stderr


def test_the_crossing_it_quotes_is_the_one_tetrahedralize_reports():
    (quoted,) = [line for line in GUIDE.read_text().splitlines() if line.startswith("the surface crosses itself")]
    refused(lambda: snede.meshing.tetrahedralize(ROOT / "meshes" / "liver_surface.obj", 0.2), quoted)
