"""snede's applications, over the library ``snede``: the built-in scenes (``scenes``), scene
files (``scene_file``), running a scene and writing its results (``run_scene``, ``demo``,
``distributed_scene``), the pictures (``plotting``, matplotlib: ``pip install snede[plot]``),
the live window and its recordings (``interactive``, pyvista/VTK: ``pip install snede[view]``)
and the command line (``command_line``, run by ``python -m snede``).

The library never imports this package; this package loads pyvista and matplotlib only where
it draws, through ``snede.app._extras``, which names the extra to install when one is missing.
"""
