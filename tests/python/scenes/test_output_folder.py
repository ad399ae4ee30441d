"""``--out`` is honoured by scene scripts (issue 34 item 6): ``python -m snede run script.py --out
DIR`` wrote into ``out/`` all the same, because a script chose its own paths. The command line
now hands DIR to the script, which asks for its folder with ``snede.output_folder(name)``."""
import subprocess
import sys
from pathlib import Path

import pytest

import snede
from snede import _output_folder

ROOT = Path(__file__).resolve().parents[3]
SCRIPTS = sorted((ROOT / "examples").glob("*.py"))


def test_every_example_script_asks_for_its_folder():
    """No script writes to a path of its own choosing (``"out/..."``)."""
    assert SCRIPTS
    for script in SCRIPTS:
        text = script.read_text()
        assert f'snede.output_folder("{script.stem}")' in text, script.name
        assert '"out/' not in text, script.name


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda path: path.name)
def test_a_script_scene_writes_into_the_out_folder_given(script, tmp_path):
    out = subprocess.run([sys.executable, "-m", "snede", "--quiet", "run", str(script), "--out", tmp_path / "mine"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    folder = tmp_path / "mine" / script.stem
    assert {path.suffix for path in folder.iterdir()} >= {".xdmf", ".h5", ".png"}
    assert not (tmp_path / "out").exists()


def test_output_folder_is_out_unless_the_command_line_says_otherwise(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv(_output_folder.VARIABLE, raising=False)
    assert snede.output_folder("beam") == Path("out") / "beam" and (tmp_path / "out" / "beam").is_dir()
    monkeypatch.setenv(_output_folder.VARIABLE, str(tmp_path / "elsewhere"))
    assert snede.output_folder("beam") == tmp_path / "elsewhere" / "beam"
    assert (tmp_path / "elsewhere" / "beam").is_dir()


@pytest.mark.parametrize("name", ["", "/tmp/x", "../beam", "a/../../b"])
def test_output_folder_takes_a_name_inside_the_folder(name):
    with pytest.raises(ValueError, match="output_folder takes a scene's name"):
        snede.output_folder(name)
