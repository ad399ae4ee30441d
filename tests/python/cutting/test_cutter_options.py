"""Issue 51, item 3: the cutters' options as records. TetrahedralCutterOptions is the engine's
CutterOptions, DelaunayCutterOptions and SurfaceCutterOptions the Delaunay cutters' thresholds
(their defaults); a cutter takes one whole or keywords that change its fields, and the engine
refuses values out of range."""
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


def square_sheet():
    return snede.meshing.rectangle((1.0, 1.0), (8, 8))


def test_the_delaunay_cutters_take_their_thresholds_as_a_record():
    defaults = snede.DelaunayCutterOptions()
    assert (defaults.eps_edge, defaults.eps_entry, defaults.eps_exit, defaults.short_edge_angle) == (0, 0, 0, 0)
    assert pickle.loads(pickle.dumps(defaults)) == defaults
    record = snede.DelaunayCutterOptions(eps_edge=0.05, eps_exit=0.02)
    cutter = snede.DelaunayCutter(square_sheet(), options=record, eps_entry=0.01)
    assert (cutter.eps_edge, cutter.eps_entry, cutter.eps_exit) == (0.05, 0.01, 0.02)
    # 0 (the record's default) is the thesis's h̄/3 from the mean edge length, as None was.
    assert snede.DelaunayCutter(square_sheet()).eps_edge == snede.DelaunayCutter(square_sheet(), eps_edge=0).eps_edge > 0
    with pytest.raises(ValueError, match="eps_exit"):
        snede.DelaunayCutter(square_sheet(), eps_exit=-1.0)
    with pytest.raises(ValueError, match="short_edge_angle"):
        snede.DelaunayCutter(square_sheet(), short_edge_angle=math.pi / 2)
    with pytest.raises(TypeError, match="options must be a snede.DelaunayCutterOptions"):
        snede.DelaunayCutter(square_sheet(), options=snede.SurfaceCutterOptions())


def test_the_surface_cutter_takes_its_thresholds_as_a_record():
    skin = snede.meshing.height_field(lambda x, y: 0 * x, divisions=(6, 6))
    cutter = snede.SurfaceCutter(skin, options=snede.SurfaceCutterOptions(eps_edge=0.1), eps_exit=0.03)
    assert (cutter.eps_edge, cutter.eps_exit) == (0.1, 0.03) and cutter.eps_entry > 0
    with pytest.raises(ValueError, match="eps_entry"):
        snede.SurfaceCutter(skin, eps_entry=float("nan"))
