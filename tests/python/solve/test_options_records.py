"""The solvers' option structs are Python's records (issue 36 item 3: fields spelled once, in
C++): StaticOptions and DynamicRelaxationOptions build from keywords with the engine's defaults,
refuse a bad field by name, print, compare, pickle, and read method and criterion as names."""
import inspect
import pickle
import subprocess
import sys

import numpy as np
import pytest

import snede
from snede._snede import DynamicRelaxationOptions, StaticOptions

SOME_STATIC = dict(method="ncg", rtol=1e-8, criterion="6.8", round_tolerance=1e-10, max_iterations=77,
                   options_prefix="mine_", petsc_options=[("snes_ncg_type", "fr")], preconditioner="jacobi")
SOME_DYNAMIC = dict(damping=12.5, dt=2e-4, options_prefix="relax_", petsc_options=[("ts_max_steps", "9")])


def keyword_defaults(function, names):
    parameters = inspect.signature(function).parameters
    return {name: parameters[name].default for name in names}


def test_static_defaults_are_the_public_solvers():
    """StaticSolver writes no default of its own (issue 51): a keyword left out (None) is the
    record's, and a solver made without any has a default record's settings."""
    options = StaticOptions()
    names = ["method", "rtol", "criterion", "round_tolerance", "max_iterations", "options_prefix"]
    assert set(keyword_defaults(snede.StaticSolver.__init__, names).values()) == {None}
    body = snede.Body(snede.meshing.box((1.0, 1.0, 1.0), (1, 1, 1)), snede.LinearElastic(E=1e3, nu=0.3))
    assert snede.StaticSolver(body).options == options
    assert options.petsc_options == () and options.preconditioner == ""  # none given: PETSc's, and "auto"


def test_a_static_solver_takes_a_record_whole_and_keywords_change_its_fields():
    body = snede.Body(snede.meshing.box((1.0, 1.0, 1.0), (1, 1, 1)), snede.LinearElastic(E=1e3, nu=0.3))
    record = snede.StaticOptions(method="ncg", rtol=1e-8, max_iterations=77, options_prefix="whole_")
    assert snede.StaticSolver(body, options=record).options == record
    changed = snede.StaticSolver(body, options=record, rtol=1e-5, ncg_type="fr").options
    assert (changed.method, changed.rtol, changed.max_iterations) == ("ncg", 1e-5, 77)
    assert changed.petsc_options == (("snes_ncg_type", "fr"),)
    assert record.rtol == 1e-8  # the record given is not changed
    with pytest.raises(TypeError, match="options must be a snede.StaticOptions"):
        snede.StaticSolver(body, options={"rtol": 1e-3})
    with pytest.raises(ValueError, match="criterion must be"):
        snede.StaticSolver(body, criterion="6.7")
    with pytest.raises(ValueError, match="rtol must be positive"):
        snede.StaticSolver(body, rtol=0.0)


def test_asdict_gives_the_fields_keyword_construction_takes():
    for record in (StaticOptions(**SOME_STATIC), DynamicRelaxationOptions(**SOME_DYNAMIC), snede.NeedleOptions()):
        fields = record._asdict()
        assert type(record)(**fields) == record
        assert all(getattr(record, name) == value for name, value in fields.items())
    assert set(StaticOptions()._asdict()) == set(SOME_STATIC)  # every field, none but the fields
    assert set(DynamicRelaxationOptions()._asdict()) == set(SOME_DYNAMIC)


def test_the_records_and_the_method_names_are_exported():
    assert (snede.StaticOptions, snede.DynamicRelaxationOptions) == (StaticOptions, DynamicRelaxationOptions)
    assert snede.static.METHODS == ("cg", "ncg", "newton")  # the engine's table, in its order


def test_dynamic_defaults_are_the_public_solvers():
    """DynamicRelaxation writes no default of its own (issue 51): its keywords are None, and
    the record's dt None is the CFL estimate, as the keyword's is (one meaning)."""
    options = DynamicRelaxationOptions()
    names = ["damping", "dt", "options_prefix", "petsc_options"]
    assert set(keyword_defaults(snede.DynamicRelaxation.__init__, names).values()) == {None}
    assert (options.damping, options.dt, options.options_prefix, options.petsc_options) == (0.0, None, "dynamic_", ())
    body = snede.Body(snede.meshing.box((1.0, 1.0, 1.0), (1, 1, 1)), snede.LinearElastic(E=1e3, nu=0.3))
    relaxation = snede.DynamicRelaxation(body, 5.0)
    assert relaxation.options == DynamicRelaxationOptions(damping=5.0)
    assert relaxation.dt == pytest.approx(relaxation.cfl_time_step, rel=1e-12)


def test_a_relaxation_takes_a_record_whole_and_keywords_change_its_fields():
    body = snede.Body(snede.meshing.box((1.0, 1.0, 1.0), (1, 1, 1)), snede.LinearElastic(E=1e3, nu=0.3))
    record = DynamicRelaxationOptions(damping=3.0, dt=1e-4, options_prefix="whole_relax_")
    relaxation = snede.DynamicRelaxation(body, options=record)
    assert relaxation.options == record and relaxation.dt == 1e-4
    changed = snede.DynamicRelaxation(body, 8.0, options=record, petsc_options={"ts_max_steps": 4}).options
    assert (changed.damping, changed.dt, changed.petsc_options) == (8.0, 1e-4, (("ts_max_steps", "4"),))
    assert record.damping == 3.0  # the record given is not changed
    with pytest.raises(TypeError, match="options must be a snede.DynamicRelaxationOptions"):
        snede.DynamicRelaxation(body, options=StaticOptions())


def test_keywords_set_every_field_and_method_and_criterion_read_back_as_names():
    static = StaticOptions(**SOME_STATIC)
    dynamic = DynamicRelaxationOptions(**SOME_DYNAMIC)
    for record, values in ((static, SOME_STATIC), (dynamic, SOME_DYNAMIC)):
        for name, value in values.items():
            assert getattr(record, name) == (tuple(value) if isinstance(value, list) else value), name
    assert isinstance(static.method, str) and isinstance(static.criterion, str)


@pytest.mark.parametrize("record, values", [(StaticOptions, SOME_STATIC), (DynamicRelaxationOptions, SOME_DYNAMIC)],
                         ids=["static", "dynamic"])
def test_repr_evaluates_back_to_an_equal_record_and_equality_is_field_by_field(record, values):
    options = record(**values)
    text = repr(options)
    assert text.startswith(record.__name__ + "(") and all(f"{name}=" in text for name in values)
    assert eval(text, {record.__name__: record}) == options
    for name in values:
        other = record(**values)
        setattr(other, name, getattr(record(), name))
        assert other != options, name
    assert options != "not a record"


def test_every_pickle_protocol_gives_an_equal_record():
    # Protocols 0 and 1 aborted the interpreter with pybind11's own pickling: a subprocess.
    code = ("import pickle\n"
            "from snede._snede import StaticOptions, DynamicRelaxationOptions\n"
            f"records = [StaticOptions(**{SOME_STATIC!r}), DynamicRelaxationOptions(**{SOME_DYNAMIC!r})]\n"
            "for protocol in range(pickle.HIGHEST_PROTOCOL + 1):\n"
            "    for record in records:\n"
            "        assert pickle.loads(pickle.dumps(record, protocol)) == record, (record, protocol)\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, f"returncode {run.returncode}: {run.stderr[-400:]}"


@pytest.mark.parametrize("make, error, message", [
    (lambda: StaticOptions(method="gmres"), ValueError, "method must be 'cg', 'ncg' or 'newton', got 'gmres'"),
    (lambda: StaticOptions(criterion="6.7"), ValueError, "criterion must be .*'6.8'.*got '6.7'"),
    (lambda: StaticOptions(method=2), TypeError, "method cannot be 2"),
    (lambda: StaticOptions(max_iterations="many"), TypeError, "max_iterations cannot be 'many'"),
    (lambda: StaticOptions(rtl=1e-3), TypeError, "unexpected keyword argument 'rtl'"),
    (lambda: DynamicRelaxationOptions(damping=-0.5), ValueError, "damping .* got -0.5"),
    (lambda: DynamicRelaxationOptions(damping=float("inf")), ValueError, "damping .* got inf"),
    (lambda: DynamicRelaxationOptions(dt=-1e-3), ValueError, "dt must be .* got -0.001"),
    (lambda: DynamicRelaxationOptions(dt=0.0), ValueError, "dt must be positive and finite .*CFL.* got 0"),
    (lambda: DynamicRelaxationOptions(dt=float("nan")), ValueError, "dt must be .* got nan"),
    (lambda: DynamicRelaxationOptions(damping="strong"), TypeError, "damping cannot be 'strong'"),
    (lambda: DynamicRelaxationOptions(dampnig=1.0), TypeError, "unexpected keyword argument 'dampnig'"),
])
def test_bad_values_are_refused_naming_the_field(make, error, message):
    with pytest.raises(error, match=message):
        make()


def test_a_refused_assignment_leaves_the_record_as_it_was():
    static, dynamic = StaticOptions(**SOME_STATIC), DynamicRelaxationOptions(**SOME_DYNAMIC)
    with pytest.raises(ValueError, match="criterion"):
        static.criterion = "relative-ish"
    with pytest.raises(ValueError, match="damping"):
        dynamic.damping = -1.0
    assert static == StaticOptions(**SOME_STATIC) and dynamic == DynamicRelaxationOptions(**SOME_DYNAMIC)
    static.method = "cg"
    assert static.method == "cg"


def test_the_solvers_run_with_the_options_given():
    body = snede.Body(snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)), snede.LinearElastic(E=1e3, nu=0.3))
    body.fix(np.isclose(body.mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    options = DynamicRelaxationOptions(damping=7.0, dt=1e-4, options_prefix="records_",
                                       petsc_options=[("ts_max_steps", "3")])
    dynamics = snede._snede.DynamicRelaxation(body._model, options)
    assert (dynamics.damping, dynamics.dt, dynamics.ts.getOptionsPrefix()) == (7.0, 1e-4, "records_")
    assert dynamics.step(10).iterations == 3  # -records_ts_max_steps reached the TS
    solver = snede._snede.StaticSolver(body._model, StaticOptions(method="ncg", options_prefix="records_static_"),
                                       None)
    assert solver.snes.getType() == "ncg" and solver.snes.getOptionsPrefix() == "records_static_"
