"""The one check of an error message that tests share."""
import pytest


def refused(call, *fragments, error=ValueError) -> str:
    """``call()`` raises ``error`` whose message holds every fragment; the message."""
    with pytest.raises(error) as info:
        call()
    missing = [fragment for fragment in fragments if fragment not in str(info.value)]
    assert not missing, f"{missing} not in {str(info.value)!r}"
    return str(info.value)
