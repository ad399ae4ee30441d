"""The one check of an error message the mesh tests share (tests/python/hardening has its own
``value_error``, out of reach of these folders' imports)."""
import pytest


def refused(call, *fragments, error=ValueError) -> str:
    """``call()`` raises ``error`` whose message holds every fragment; the message."""
    with pytest.raises(error) as info:
        call()
    missing = [fragment for fragment in fragments if fragment not in str(info.value)]
    assert not missing, f"{missing} not in {str(info.value)!r}"
    return str(info.value)
