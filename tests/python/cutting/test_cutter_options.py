"""Issue 51, item 3: the cutters' options as a record. TetrahedralCutterOptions is the engine's
CutterOptions (its defaults); a cutter takes one whole or keywords that change its fields, and
the engine refuses thresholds out of range."""
import math
import pickle

import pytest

import snede
from snede import TetrahedralCutterOptions


def cube():
    return snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))


def test_the_record_holds_the_engines_defaults():
    options = TetrahedralCutterOptions()
    assert (options.snap, options.remove_degeneracies, options.fix_free_pieces) == (True, True, True)
    assert options.min_aspect_ratio == 0.01 and options.large_angle == pytest.approx(0.99 * math.pi)
    assert options.max_fragment_elements == 10
    assert pickle.loads(pickle.dumps(options)) == options
    assert snede.TetrahedralCutter(cube()).options == options


def test_a_cutter_takes_a_record_whole_or_keywords_changing_it():
    record = TetrahedralCutterOptions(snap=False, max_fragment_elements=3)
    assert snede.TetrahedralCutter(cube(), options=record).options == record
    changed = snede.TetrahedralCutter(cube(), options=record, min_aspect_ratio=0.05).options
    assert (changed.snap, changed.max_fragment_elements, changed.min_aspect_ratio) == (False, 3, 0.05)
    with pytest.raises(TypeError, match="options must be a snede.TetrahedralCutterOptions"):
        snede.TetrahedralCutter(cube(), options={"snap": False})
    with pytest.raises(TypeError, match="unexpected keyword argument 'snapp'"):
        TetrahedralCutterOptions(snapp=False)
    with pytest.raises(ValueError, match="min_aspect_ratio must be in"):
        snede.TetrahedralCutter(cube(), options=TetrahedralCutterOptions(min_aspect_ratio=2.0))
