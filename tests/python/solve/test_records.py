"""The engine's report structs are Python's records (issue 36: fields spelled once, in C++):
keyword construction, attributes, repr, equality, pickling, and the one-line summary."""
import copy
import pickle
import subprocess
import sys

import numpy as np
import pytest

import snede
from snede._snede import NeedleOptions, NeedleStepResult

RECORDS = [snede.SolveResult, NeedleStepResult, NeedleOptions, snede.CutResult, snede.PlanarCutResult]


def a_solve():
    body = snede.Body(snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)), snede.LinearElastic(E=1e3, nu=0.3))
    body.fix(np.isclose(body.mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return snede.StaticSolver(body, "cg", rtol=1e-8).solve()


def test_a_solve_returns_the_record_with_its_fields():
    result = a_solve()
    assert isinstance(result, snede.SolveResult)
    assert result.converged and result.reason.startswith("CONVERGED") and result.iterations > 0
    assert result.residual_norm <= result.tolerance < result.initial_residual_norm
    assert result.residual_history[0] == pytest.approx(result.initial_residual_norm)
    assert result.residual_history[-1] == pytest.approx(result.residual_norm)


def test_keyword_construction_defaults_and_unknown_names():
    record = snede.SolveResult(converged=True, reason="CONVERGED_RTOL", iterations=3, residual_history=[2.0, 1.0])
    assert (record.converged, record.reason, record.iterations, record.energy) == (True, "CONVERGED_RTOL", 3, 0.0)
    assert record.residual_history == (2.0, 1.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'iteration'"):
        snede.SolveResult(iteration=3)
    with pytest.raises(TypeError, match="iterations cannot be 'three'"):
        snede.SolveResult(iterations="three")


def test_repr_names_every_field_and_evaluates_back_to_an_equal_record():
    result = a_solve()
    text = repr(result)
    for name in ("converged", "reason", "iterations", "residual_norm", "energy", "seconds", "flops",
                 "linear_iterations", "initial_residual_norm", "tolerance", "residual_history"):
        assert f"{name}=" in text
    assert eval(text, {"SolveResult": snede.SolveResult}) == result


def test_equality_pickling_and_assignment():
    result = a_solve()
    copy = pickle.loads(pickle.dumps(result))
    assert copy == result and copy is not result
    copy.seconds += 1.0
    assert copy != result and copy != "not a record"


def test_summary_line():
    record = snede.SolveResult(converged=False, reason="DIVERGED_ITS", iterations=7, linear_iterations=40,
                               residual_norm=1.5e-3, tolerance=1e-6, energy=-2.25, seconds=0.0125, flops=5.05e6)
    assert str(record) == ("NOT converged (DIVERGED_ITS) after 7 iterations (40 linear): |r| = 1.500e-03 "
                           "(tolerance 1.000e-06), energy -2.250000e+00 J, 0.013 s, 5.0 MFLOP")


def test_needle_step_report_is_the_engines_record():
    report = NeedleStepResult(rearrangements=2, slipped=1, reason="CONVERGED")
    assert (report.rearrangements, report.slipped, report.stuck, report.converged) == (2, 1, 0, True)
    assert pickle.loads(pickle.dumps(report)) == report
    assert repr(report).startswith("NeedleStepResult(rearrangements=2, solver_iterations=0,")


def test_cut_reports_add_as_the_engine_adds_them_and_read_sequences_as_tuples():
    first = snede.CutResult(sweeps=2, faces_dissected=3, degenerate_shapes=[1, 0, 2, 0], components=1, seconds=0.5)
    later = snede.CutResult(sweeps=1, faces_dissected=4, degenerate_shapes=[0, 1, 0, 1], components=2,
                            piece_elements=[40, 2], seconds=0.25)
    total = first + later
    assert (total.sweeps, total.faces_dissected, total.components, total.seconds) == (3, 7, 2, 0.75)
    assert total.degenerate_shapes == (1, 1, 2, 1) and total.piece_elements == (40, 2)
    assert first == snede.CutResult(sweeps=2, faces_dissected=3, degenerate_shapes=(1, 0, 2, 0), components=1,
                                    seconds=0.5)
    assert str(total).startswith("7 faces dissected (0 vertices snapped, 0 refused)")
    planar = snede.PlanarCutResult(moves=1, triangles_before=10, triangles_after=12) + \
        snede.PlanarCutResult(moves=2, branches=1, triangles_before=12, triangles_after=15)
    assert (planar.moves, planar.triangles_before, planar.triangles_after) == (3, 10, 15)
    assert str(planar).endswith("1 branches, 0 annihilations; 10 → 15 triangles in 0.00 ms")


# Protocols 0 and 1 aborted the interpreter with pybind11's own pickling (it serves 2 and up),
# so the probe runs in a subprocess.
@pytest.mark.parametrize("protocol", [0, 1])
@pytest.mark.parametrize("record", RECORDS, ids=lambda cls: cls.__name__)
def test_records_pickle_under_every_protocol_without_killing_the_interpreter(record, protocol):
    code = (f"import pickle, snede._snede as m\n"
            f"r = m.{record.__name__}()\n"
            f"assert pickle.loads(pickle.dumps(r, {protocol})) == r\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, f"returncode {run.returncode}: {run.stderr[-400:]}"


def test_a_record_holding_nan_equals_itself_and_its_copy():
    result = snede.SolveResult(converged=False, reason="DIVERGED_NONFINITE_STATE", residual_norm=float("nan"))
    assert result == result
    assert copy.deepcopy(result) == result
