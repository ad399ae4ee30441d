"""Scene files: a scene declared in TOML, run by ``python -m snede run my_scene.toml [--out DIR]``
as a built-in scene is (docs/guide/meshes_and_scenes.md, "Scene files", has every key).

    scene = snede.app.scene_file.load("examples/liver_cut.toml")   # a snede.app.scenes.Scene
    snede.app.run_scene.run(scene, None, None, "out")

A mistake in the file raises ``SceneFileError`` (a ValueError), one line naming the file and the
key: ``my_scene.toml: material.E must be a positive number, got -3``.
"""
from __future__ import annotations

from snede.app.scene_file.reading import SceneFileError
from snede.app.scene_file.recipe import read
from snede.app.scene_file.scene import build

OPTIONS = ("formulation",)  # of the command line's scene options only --formulation applies to scene files
SUFFIX = ".toml"


def load(path, material: str | None = None, formulation: str | None = None):
    """The scene of the file ``path`` (a ``snede.app.scenes.Scene``), its mesh made, its body held
    and loaded, its tools' paths checked against the body; ``material`` and ``formulation`` (the
    command line's ``--material`` and ``--formulation``) replace the file's."""
    return build(read(path), material, formulation)


__all__ = ["OPTIONS", "SUFFIX", "SceneFileError", "load", "read"]
