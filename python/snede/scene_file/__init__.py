"""Scene files: a scene declared in TOML, run by ``python -m snede run my_scene.toml [--out DIR]``
as a built-in scene is (docs/guide/meshes_and_scenes.md, "Scene files", has every key).

    scene = snede.scene_file.load("examples/liver_cut.toml")   # a snede.scenes.Scene
    snede.run_scene.run(scene, None, None, "out")

A mistake in the file raises ``SceneFileError`` (a ValueError), one line naming the file and the
key: ``my_scene.toml: material.E must be a positive number, got -3``.
"""
from __future__ import annotations

from snede.scene_file.reading import SceneFileError
from snede.scene_file.recipe import read
from snede.scene_file.scene import build

OPTIONS = ()  # the command line's scene options (--divisions, --speed, --mesh-size) apply to no scene file
SUFFIX = ".toml"


def load(path, material: str | None = None):
    """The scene of the file ``path`` (a ``snede.scenes.Scene``), its mesh made, its body held
    and loaded, its tools' paths checked against the body; ``material`` (the command line's
    ``--material``) replaces the file's material model."""
    return build(read(path), material)


__all__ = ["OPTIONS", "SUFFIX", "SceneFileError", "load", "read"]
