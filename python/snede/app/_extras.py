"""The optional extras the applications draw with: ``snede[view]`` (pyvista, VTK: the live
window) and ``snede[plot]`` (matplotlib, pillow: pictures and GIFs). ``import snede`` needs
neither; an application that does gets an ImportError naming the extra to install."""
from __future__ import annotations

import importlib

from snede._errors import Error

EXTRAS = {"pyvista": "view", "vtk": "view", "vtkmodules": "view", "matplotlib": "plot", "PIL": "plot"}


class MissingExtra(Error, ImportError):
    """An application needs a package of one of snede's optional extras, and it is not installed."""


def need(module: str, purpose: str):
    """``importlib.import_module(module)``, or a ``MissingExtra`` saying which extra installs it."""
    try:
        return importlib.import_module(module)
    except ImportError as error:
        top = (error.name or module).split(".")[0]
        extra = EXTRAS.get(top, EXTRAS.get(module.split(".")[0]))
        raise MissingExtra(f"{purpose} needs {top}, which is not installed: pip install snede[{extra}]",
                           name=top) from error
