"""Built-in scenes for ``python -m snede run``: each module has ``build(parameters) -> Scene``
(a ``Parameters`` record, ``Parameters.of(namespace)`` from the command line's options) and
``builders()`` names them; an interactive scene's module registers its tool
(``snede.app.interactive.tools.register``). ``Scene``, ``Parameters`` and the helpers the scene
modules share are in ``snede.app.scenes.scene`` (re-exported here): the modules import them from there, not from this
package, which imports the modules."""
from snede.app.scenes.scene import (MATERIAL_NAMES, Parameters, Scene, briefly, material,  # noqa: F401
                                    shaft_force, solve_entries)


def builders() -> dict:
    from snede.app.scenes import cantilever, cut, cylinder, membrane_cut, needle, needle3d, sheet_cut, slab

    return {"cantilever": cantilever, "cylinder": cylinder, "slab": slab, "needle": needle, "needle3d": needle3d,
            "cut": cut, "sheet-cut": sheet_cut, "membrane-cut": membrane_cut}
