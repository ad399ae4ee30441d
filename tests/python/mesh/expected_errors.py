"""The one check of an error message the mesh tests share."""
import pytest


def refused(call, *fragments, error=ValueError) -> str:
    """``call()`` raises ``error`` whose message holds every fragment; the message."""
    with pytest.raises(error) as info:
        call()
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    return message
