"""The helper modules that tests of several subject folders share (tests/python/helpers) are
imported by name, as each folder's own helpers are."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "helpers"))
