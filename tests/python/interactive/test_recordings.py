"""Recorded sessions as regression tests (issue 37): the scripted cut and needle push of
tool_scripts.py, stored in recordings/, replay to their digests (mesh and displacement to 1e-12
of their norms). A change that moves the result on purpose (a solver, the cutter) re-records
them: `.venv/bin/python tests/python/interactive/tool_scripts.py`, and says so in its commit."""
import pytest

from snede.interactive import replay
from tool_scripts import RECORDINGS


@pytest.mark.parametrize("name", ["cut_drag", "needle_push"])
def test_a_stored_recording_replays_to_its_digest(name):
    result = replay(RECORDINGS / f"{name}.json")
    assert result.moves > 0
    assert result.matches, f"{name}: " + "; ".join(result.mismatches)
