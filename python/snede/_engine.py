"""Attributes the Python classes hand on unchanged from the engine objects they wrap."""
from __future__ import annotations


def engine_property(name: str, doc: str | None = None, convert=None, source: str = "_impl") -> property:
    """A read-only property giving ``self.<source>.<name>`` (through ``convert``, e.g.
    ``np.asarray``, when given): what a plain ``@property`` returning it would be."""
    def get(self):
        value = getattr(getattr(self, source), name)
        return value if convert is None else convert(value)

    return property(get, doc=doc)
