"""gmsh sessions for snede: a model made and removed around one task, gmsh's messages kept, and
gmsh's elements as vertex-index arrays; gmsh's file readers run in a child process."""
from __future__ import annotations

import contextlib
import os
import pickle
import signal
import subprocess
import sys
import tempfile

import numpy as np

#: gmsh's element type numbers (in its files too): (meshio's name, corners)
TYPES = {1: ("line", 2), 2: ("triangle", 3), 3: ("quad", 4), 4: ("tetra", 4)}


@contextlib.contextmanager
def model(name: str):
    """``with model("snede-x") as gmsh:``: a new gmsh model, current inside the block and removed
    after it; gmsh is initialised here if it is not already (and then finalised). gmsh's log
    is collected: ``errors(gmsh)`` gives its warnings and errors."""
    import gmsh

    initialized_here = not gmsh.isInitialized()
    if initialized_here:
        # interruptible=False: gmsh would otherwise take over SIGINT for good, and Ctrl-C
        # would kill the process without a word instead of raising KeyboardInterrupt.
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)  # deterministic
        gmsh.logger.start()
        gmsh.model.add(name)
        try:
            yield gmsh
        finally:
            gmsh.model.remove()
            gmsh.logger.stop()
    finally:
        if initialized_here:
            gmsh.finalize()


def errors(gmsh) -> list[str]:
    """gmsh's error and warning lines logged in this session, without their "Error: " or "Warning: "."""
    return [line.split(": ", 1)[1] for line in gmsh.logger.get() if line.startswith(("Error: ", "Warning: "))]


def elements(gmsh, dim: int = -1) -> tuple[np.ndarray, list[tuple[str, np.ndarray]]]:
    """The current model's nodes as (n, 3) points (in gmsh's order) and its elements of dimension
    ``dim`` (-1: all) of the types in ``TYPES``: (meshio's name, (m, corners) vertex indices) pairs."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    tags = tags.astype(np.int64)
    index_of_tag = np.zeros(int(tags.max(initial=0)) + 1, dtype=np.int64)
    index_of_tag[tags] = np.arange(len(tags))
    kinds, _, nodes = gmsh.model.mesh.getElements(dim)
    blocks = [(TYPES[kind][0], index_of_tag[corners.astype(np.int64)].reshape(-1, TYPES[kind][1]))
              for kind, corners in zip(map(int, kinds), nodes) if kind in TYPES]
    return coords.reshape(-1, 3), blocks


def unnamed_group(dim: int, tag: int) -> str:
    """The name of a physical group the file does not name: gmsh's (dimension, tag), in gmsh's
    words, e.g. "physical volume 1" (a volume and a surface may share a tag)."""
    return f"physical {('point', 'curve', 'surface', 'volume')[dim]} {tag}"


def physical_groups(gmsh) -> list[tuple[str, str, np.ndarray]]:
    """The current model's physical groups as (meshio's cell type, name, (m, corners) vertex
    indices) triples, in the node order of ``elements``; a group without a name as
    ``unnamed_group`` calls it."""
    tags, _, _ = gmsh.model.mesh.getNodes()
    tags = tags.astype(np.int64)
    index_of_tag = np.zeros(int(tags.max(initial=0)) + 1, dtype=np.int64)
    index_of_tag[tags] = np.arange(len(tags))
    groups = []
    for dim, tag in gmsh.model.getPhysicalGroups():
        name = gmsh.model.getPhysicalName(dim, tag) or unnamed_group(dim, tag)
        for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
            kinds, _, nodes = gmsh.model.mesh.getElements(dim, entity)
            for kind, corners in zip(map(int, kinds), nodes):
                if kind in TYPES:
                    groups.append((TYPES[kind][0], name, index_of_tag[corners.astype(np.int64)].reshape(-1, TYPES[kind][1])))
    return groups


def read_file(path) -> tuple[np.ndarray, list, list]:
    """gmsh's own reader (``gmsh.merge``: every format gmsh reads, gmsh's .msh 1, 2 and 4 among
    them): the points, ``elements`` and ``physical_groups`` of ``path``; a ValueError with gmsh's
    errors if it fails. It crashes the process on some damaged files: see ``read_file_in_child``."""
    with model("snede-read") as gmsh:
        try:
            gmsh.merge(str(path))
        except Exception as error:
            raise ValueError("; ".join(errors(gmsh)) or str(error)) from None
        points, blocks = elements(gmsh)
        return points, blocks, physical_groups(gmsh)


# The child loads this file by its path, not as snede._gmsh: importing snede would start PETSc
# and the engine. It gets the parent's sys.path, and answers through a file.
_CHILD = """import importlib.util, pickle, sys
module_path, path, answer = sys.argv[1:4]
sys.path[:] = sys.argv[4:]
spec = importlib.util.spec_from_file_location("snede_gmsh_reader", module_path)
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
try:
    result = ("mesh", module.read_file(path))
except ValueError as error:
    result = ("error", str(error))
with open(answer, "wb") as file:
    pickle.dump(result, file)
"""


def read_file_in_child(path) -> tuple[np.ndarray, list, list]:
    """``read_file`` in a child Python process: gmsh's readers crash (SIGSEGV) on some damaged
    files, which must not take the caller's interpreter with them. A ValueError says why the
    child gave no mesh."""
    with tempfile.TemporaryDirectory(prefix="snede-gmsh-") as folder:
        answer = os.path.join(folder, "answer.pickle")
        try:
            done = subprocess.run([sys.executable, "-c", _CHILD, __file__, os.fspath(path), answer, *sys.path],
                                  stdin=subprocess.DEVNULL, capture_output=True, text=True, errors="replace")
        except OSError as error:  # no interpreter to start: not the file's fault, but no mesh either
            raise ValueError(f"could not start a process for gmsh's reader ({error})") from None
        if done.returncode == -signal.SIGINT:  # Ctrl-C reached the child first
            raise KeyboardInterrupt
        if done.returncode < 0:
            try:
                name = signal.Signals(-done.returncode).name
            except ValueError:
                name = f"signal {-done.returncode}"
            raise ValueError(f"its reader crashed on this file ({name}), as it does on some damaged files")
        if not os.path.exists(answer):  # gmsh not installed, say: the child's last words
            lines = done.stderr.strip().splitlines() or [f"exit status {done.returncode}"]
            raise ValueError(f"its reader's process failed: {lines[-1]}")
        with open(answer, "rb") as file:
            kind, value = pickle.load(file)
    if kind == "error":
        raise ValueError(value)
    return value
