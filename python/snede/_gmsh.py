"""gmsh sessions for snede: a model made and removed around one task, gmsh's messages kept, and
gmsh's elements as vertex-index arrays."""
from __future__ import annotations

import contextlib

import numpy as np

#: gmsh's element type numbers: (meshio's name, corners)
TYPES = {2: ("triangle", 3), 3: ("quad", 4), 4: ("tetra", 4)}


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
