"""pyproject.toml declares every package snede imports at run time (issue 34 item 7) — an import
guarded by ``except ImportError``, or one of the applications' (snede.app) drawing packages, in an
optional extra — and tools/requirements.txt, which `make setup` installs (snede itself with
--no-deps), pins every one, the extras' too. The studies beside the
package (studies/) are not in it: what they use beyond snede's dependencies (the `triangle`
package of the Delaunay-cut experiment) they import where present and say so on their pages."""
import ast
import functools
import importlib.metadata
import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: declared without an import of their own: why
INDIRECT = {"pillow": "matplotlib's PillowWriter writes the GIFs (snede.app.plotting.save_animation)",
            "vtk": "pyvista draws the live window with it"}
APP = ROOT / "python" / "snede" / "app"


def name(requirement: str) -> str:
    return re.split(r"[\s<>=!~;\[]", requirement, maxsplit=1)[0].lower().replace("_", "-")


def project():
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def declared() -> set[str]:
    return {name(r) for r in project()["dependencies"]}


def optional(extra: str | None = None) -> set[str]:
    """The packages of the optional extras (or of one), without snede's own (``snede[view,plot]``)."""
    extras = project().get("optional-dependencies", {})
    return {name(r) for key, rs in extras.items() if extra in (None, key) for r in rs} - {"snede"}


def imports(node) -> set[str]:
    if isinstance(node, ast.Import):
        return {alias.name.split(".")[0] for alias in node.names}
    if isinstance(node, ast.ImportFrom) and node.level == 0:
        return {node.module.split(".")[0]}
    return set()


def needed(node) -> set[str]:
    """What ``need("module", ...)`` (snede.app._extras) imports."""
    if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "need" and node.args \
            and isinstance(node.args[0], ast.Constant):
        return {node.args[0].value.split(".")[0]}
    return set()


def imported_modules() -> tuple[set[str], set[str]]:
    """Top-level modules imported anywhere in python/snede (inside functions too), not the
    standard library's nor snede's own: (required, optional: guarded by ``except ImportError``,
    or the applications' drawing packages, which may be missing: see test_import_without_extras)."""
    required, guarded = set(), set()
    drawing = optional("view") | optional("plot")
    for path in (ROOT / "python" / "snede").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            found = imports(node) | needed(node)
            if APP in path.parents:
                guarded |= {m for m in found if owners(m) & drawing}
                found -= guarded
            required |= found
            if isinstance(node, ast.Try) and any("ImportError" in ast.dump(h.type) for h in node.handlers if h.type):
                guarded |= set().union(*(imports(n) for statement in node.body for n in ast.walk(statement)))
    own = set(sys.stdlib_module_names) | {"snede", "_snede", "__future__"}
    return required - guarded - own, guarded - own


@functools.cache
def distributions() -> dict:
    return importlib.metadata.packages_distributions()


def owners(module: str) -> set[str]:
    return {d.lower().replace("_", "-") for d in distributions().get(module, [module])}


def test_every_imported_package_is_declared():
    required, guarded = imported_modules()
    missing = {m: sorted(owners(m)) for m in required if not owners(m) & declared()}
    assert not missing, f"imported but not in pyproject.toml's dependencies: {missing}"
    missing = {m: sorted(owners(m)) for m in guarded if not owners(m) & (declared() | optional())}
    assert not missing, f"imported where present but in no optional extra: {missing}"
    assert {"gmsh", "meshio", "h5py"} <= declared()
    assert {"matplotlib", "pillow"} <= optional("plot") and {"pyvista", "vtk"} <= optional("view")
    assert not {"matplotlib", "pyvista", "vtk"} & declared()


def test_every_declared_package_is_used():
    required, guarded = imported_modules()
    used = set().union(*map(owners, required | guarded))
    assert (declared() | optional()) - used - set(INDIRECT) == set()


def test_make_setup_installs_every_declared_package():
    pinned = {name(line) for line in (ROOT / "tools" / "requirements.txt").read_text().splitlines()
              if line.strip() and not line.startswith("#")}
    assert declared() | optional() <= pinned
