"""Fails on an include against the engine's layers (issue 51).

    python tools/check_layers.py [engine folder]

engine/layers.txt lists each engine folder with the folders whose headers it may include; each
folder is listed after those below it. This reads every #include "folder/..." of engine/*/ and
prints each one the table does not allow (file:line), each folder the table does not list, and
each folder listed before one it depends on; exit status 1 if there is any. `make test` runs it
(tests/python/test_layers.py); CMakeLists.txt links one library per folder by the same table.
"""
import re
import sys
from pathlib import Path

ENGINE = Path(__file__).resolve().parents[1] / "engine"
INCLUDE = re.compile(r'^\s*#\s*include\s+"([a-z_0-9]+)/')


def read_layers(engine: Path) -> dict[str, list[str]]:
    """Folder → the folders it may include, in the table's order."""
    layers = {}
    for line in (engine / "layers.txt").read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        folder, _, below = line.partition(":")
        layers[folder.strip()] = below.split()
    return layers


def violations(engine: Path = ENGINE) -> list[str]:
    layers = read_layers(engine)
    found = []
    order = list(layers)
    for folder, below in layers.items():
        for dependency in below:
            if dependency not in layers:
                found.append(f"layers.txt: {folder} depends on {dependency}, which the table does not list")
            elif order.index(dependency) >= order.index(folder):
                found.append(f"layers.txt: {folder} is listed before {dependency}, which it depends on")
    folders = sorted(p.name for p in engine.iterdir() if p.is_dir())
    for folder in folders:
        if folder not in layers:
            found.append(f"engine/{folder}/ is not in engine/layers.txt: say which folders it may include")
            continue
        allowed = {folder, *layers[folder]}
        for source in sorted((engine / folder).glob("*.[ch]pp")):
            for number, line in enumerate(source.read_text().splitlines(), start=1):
                match = INCLUDE.match(line)
                if match and match.group(1) in folders and match.group(1) not in allowed:
                    found.append(f"engine/{folder}/{source.name}:{number}: {folder} may not include "
                                 f"{match.group(1)}/ (engine/layers.txt: {folder} may include "
                                 f"{', '.join(layers[folder]) or 'nothing'})")
    return found


def main() -> int:
    engine = Path(sys.argv[1]) if len(sys.argv) > 1 else ENGINE
    found = violations(engine)
    for line in found:
        print(line)
    print(f"check_layers: {len(found)} include(s) against the layers" if found else "check_layers: every include follows the layers")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
