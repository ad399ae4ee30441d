"""The engine's options records as the facade takes them: a record given whole, or keywords
that change its fields. The defaults and the checks of each value are the record's (the
engine's struct, bindings/record_binding.hpp); none is written here."""
from __future__ import annotations

from snede._petsc import option_list


def fields(record) -> dict:
    """A record's fields by name, as its keyword construction takes them."""
    return record._asdict()


def settings(record_type, given, **keywords):
    """A new ``record_type``: a copy of ``given`` (a default record when None; TypeError for
    anything but a ``record_type``) with each keyword that is not None as its field; the record
    checks them (a ValueError or TypeError naming the field). ``petsc_options`` may be given as
    a dict (``{name: value}``, None for a flag), as the solvers' keywords take it."""
    if keywords.get("petsc_options") is not None:
        keywords["petsc_options"] = option_list(keywords["petsc_options"])
    if given is not None and not isinstance(given, record_type):
        raise TypeError(f"options must be a snede.{record_type.__name__}, got {type(given).__name__}")
    return record_type(**{**fields(given or record_type()),
                          **{name: value for name, value in keywords.items() if value is not None}})
