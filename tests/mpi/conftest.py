"""The helper modules the serial tests share (tests/python/helpers) are imported by name here too."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "python" / "helpers"))
