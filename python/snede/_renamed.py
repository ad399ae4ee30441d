"""Names snede gave up, kept working: a record that was ``...Report`` is ``...Result`` since
issue 51 (``CutReport`` is ``CutResult``...). A module lists its old names here and reaches them
through its ``__getattr__``, which warns (DeprecationWarning) and gives the class by its new name."""
from __future__ import annotations

import warnings

#: old name -> new name
RENAMED = {"CutReport": "CutResult", "PlanarCutReport": "PlanarCutResult", "InsertionReport": "InsertionResult",
           "NeedleStepReport": "NeedleStepResult"}


def old_name(module: str, namespace: dict, name: str):
    """The class ``name`` once named in ``module`` (whose globals are ``namespace``), with a
    DeprecationWarning; AttributeError for a name that never was."""
    new = RENAMED.get(name)
    if new is None or new not in namespace:
        raise AttributeError(f"module {module!r} has no attribute {name!r}")
    warnings.warn(f"{module}.{name} is now {module}.{new} (issue 51: records are named ...Result); "
                  f"the old name will go", DeprecationWarning, stacklevel=3)
    return namespace[new]
