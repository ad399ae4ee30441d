"""Built-in scenes for ``python -m snede run``: each module has ``build(options) -> Scene`` and
``builders()`` names them. ``Scene`` and the helpers the scene modules share are in
``snede.scenes.scene`` (re-exported here): the modules import them from there, not from this
package, which imports the modules."""
from snede.scenes.scene import (MATERIAL_NAMES, Scene, briefly, material, shaft_force,  # noqa: F401
                                solve_entries)


def builders() -> dict:
    from snede.scenes import cantilever, cut, cylinder, membrane_cut, needle, needle3d, sheet_cut, slab

    return {"cantilever": cantilever, "cylinder": cylinder, "slab": slab, "needle": needle, "needle3d": needle3d,
            "cut": cut, "sheet-cut": sheet_cut, "membrane-cut": membrane_cut}
