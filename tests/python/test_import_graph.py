"""No import circle among snede's modules (issue 36): every ``import`` and ``from ... import`` of
python/snede, at module level and inside functions alike (a function-level import still makes a
module depend on another), read with ``ast`` without importing anything. snede.mesh once read
series through snede.output, which imports snede.mesh (snede.series_files now reads them)."""
import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "python" / "snede"
# The compiled extension and the Python modules it imports: snede._errors, the base class of
# the exceptions it registers (bindings/bindings.hpp, error_bases).
EXTENSIONS = {"snede._snede": {"snede._errors"}}


def module_names() -> dict[str, Path]:
    """snede's modules by dotted name (a package by its own name, from its __init__.py)."""
    names = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        names[".".join(parts)] = path
    return names


def imported(name: str, path: Path, known: set[str]) -> set[str]:
    """The snede modules that module ``name`` (at ``path``) imports: ``from a import b`` imports
    module ``a.b`` when there is one, else (a name defined in ``a``) module ``a``."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([node.module] if node.module else []))
            submodules = {f"{base}.{alias.name}" for alias in node.names} & known
            found.update(submodules)
            if len(submodules) < len(node.names):
                found.add(base)
    return (found & known) - {name}


def import_graph() -> dict[str, set[str]]:
    modules = module_names()
    known = set(modules) | set(EXTENSIONS)
    graph = {name: imported(name, path, known) for name, path in modules.items()}
    graph.update({name: set(imports) for name, imports in EXTENSIONS.items()})
    return graph


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), and the modules that
    import themselves."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while not component or component[-1] != v:
                component.append(stack.pop())
                on_stack.discard(component[-1])
            if len(component) > 1 or v in graph[v]:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_graph_sees_snedes_imports():
    """The walk finds the imports it is meant to check (a graph with no edges has no circle)."""
    graph = import_graph()
    assert {"snede.mesh", "snede.output", "snede.distributed", "snede.series_files"} <= set(graph)
    assert "snede.mesh_edits" in graph["snede.mesh"]  # module level
    assert "snede.series_files" in graph["snede.mesh"]  # inside Mesh.read
    assert {"snede.series_files", "snede.mesh", "snede.distributed"} <= graph["snede.output"]
    assert "snede.mesh" in graph["snede.distributed"]


def test_the_walk_finds_a_circle():
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert circles({"a": {"b"}, "b": set()}) == []


def test_no_module_of_snede_imports_one_that_imports_it_back():
    found = circles(import_graph())
    assert not found, "import circles in python/snede: " + "; ".join(" <-> ".join(c) for c in found)


def test_the_library_does_not_import_the_studies():
    """studies/ (experiments and benchmarks) is not in the wheel: snede must not need it."""
    users = set()
    for name, path in module_names().items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                imports = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                imports = [node.module]
            else:
                continue
            if any(module.split(".")[0] == "studies" for module in imports):
                users.add(name)
    assert not users


def test_the_library_does_not_import_the_applications():
    """snede.app (scenes, scene files, the command line, the window) stands on the library, never
    the other way round (issue 51, item 4); ``snede.__main__`` is the command line's entry."""
    graph = import_graph()
    users = {name for name, imports in graph.items()
             if not name.startswith("snede.app") and name != "snede.__main__"
             and any(module.startswith("snede.app") for module in imports)}
    assert not users, f"library modules importing snede.app: {sorted(users)}"
