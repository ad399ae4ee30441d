"""The engine's folders include only the folders below them (engine/layers.txt, issue 51)."""
import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("check_layers", ROOT / "tools" / "check_layers.py")
check_layers = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_layers)


def test_every_engine_include_follows_the_layers():
    assert check_layers.violations() == []


def write_engine(root: Path, layers: str, files: dict[str, str]) -> Path:
    root.mkdir()
    (root / "layers.txt").write_text(layers)
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    return root


def test_an_upward_include_an_unlisted_folder_and_a_misordered_table_are_named(tmp_path):
    engine = write_engine(tmp_path / "up", "core:\nmesh: core\n", {
        "core/a.hpp": '#include "core/b.hpp"\n#include <vector>\n',
        "core/b.cpp": '// why\n#include "mesh/mesh.hpp"\n',
        "mesh/mesh.hpp": '#include "core/a.hpp"\n',
        "extra/x.cpp": "",
    })
    assert check_layers.violations(engine) == [
        "engine/core/b.cpp:2: core may not include mesh/ (engine/layers.txt: core may include nothing)",
        "engine/extra/ is not in engine/layers.txt: say which folders it may include",
    ]
    engine = write_engine(tmp_path / "order", "mesh: core\ncore:\n", {"core/a.hpp": "", "mesh/m.hpp": ""})
    assert check_layers.violations(engine) == ["layers.txt: mesh is listed before core, which it depends on"]
