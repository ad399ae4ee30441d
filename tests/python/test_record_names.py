"""Issue 51, item 3: records are named one way, ``...Result``. The ``...Report`` names they had
still work, with a DeprecationWarning, from snede and from the module that defined them."""
import pickle

import pytest

import snede
from snede import _snede, cutting, needle, planar_cutting

OLD_NAMES = [
    (snede, "CutReport", "CutResult"),
    (snede, "PlanarCutReport", "PlanarCutResult"),
    (snede, "InsertionReport", "InsertionResult"),
    (snede, "NeedleStepReport", "NeedleStepResult"),
    (cutting, "CutReport", "CutResult"),
    (planar_cutting, "PlanarCutReport", "PlanarCutResult"),
    (needle, "InsertionReport", "InsertionResult"),
    (needle, "NeedleStepReport", "NeedleStepResult"),
]


@pytest.mark.parametrize("module, old, new", OLD_NAMES, ids=lambda x: getattr(x, "__name__", x))
def test_an_old_name_gives_the_record_with_a_deprecation_warning(module, old, new):
    with pytest.warns(DeprecationWarning, match=f"{old} is now .*{new}"):
        record = getattr(module, old)
    assert record is getattr(module, new)
    assert old not in dir(module)  # the old name is not a module attribute, only reachable


def test_every_public_record_is_named_result_or_options():
    records = [name for name in snede.__all__ if name.endswith(("Report", "Result"))]
    assert records and all(name.endswith("Result") for name in records), records


def test_a_record_prints_and_pickles_under_its_new_name():
    result = snede.PlanarCutResult(flips=2)
    assert repr(result).startswith("PlanarCutResult(")
    assert pickle.loads(pickle.dumps(result)) == result
    assert _snede.CutReport is _snede.CutResult  # a record pickled under its old name still loads


def test_a_name_that_never_was_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'NoSuchReport'"):
        snede.NoSuchReport  # noqa: B018
