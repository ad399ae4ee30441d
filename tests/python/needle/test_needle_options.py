"""NeedleInsertion forwards (issue 51, item 3): its settings are a NeedleOptions record and its
solver's a StaticOptions record, each given whole or changed by keywords; the defaults are the
engine's (NeedleOptions(), NeedleInsertion.default_solver_options()), written nowhere in Python;
the records check each value by name."""
import inspect

import numpy as np
import pytest

import snede

ENTRY, DIRECTION = (-0.01, 0.05, 0.05), (1.0, 0.0, 0.0)


def cube():
    body = snede.Body(snede.meshing.box((0.1, 0.1, 0.1), (2, 2, 2)), snede.LinearElastic(34e3, 0.34))
    body.fix(np.isclose(body.mesh.points[:, 2], 0.0))
    return body


def sheet():
    body = snede.Body(snede.meshing.rectangle((0.1, 0.1), (4, 4)), snede.LinearElastic(34e3, 0.34), thickness=0.01)
    body.fix(np.isclose(body.mesh.points[:, 0], 0.1))
    return body


def needle(body, **settings):
    entry, direction = (ENTRY, DIRECTION) if body.mesh.dim == 3 else ((0.0, 0.05), (1.0, 0.0))
    return snede.NeedleInsertion(body, entry, direction, snede.FrictionProfile.uniform(1.0), **settings)


def test_every_keyword_defaults_to_none_and_the_defaults_are_the_records():
    parameters = inspect.signature(snede.NeedleInsertion.__init__).parameters
    keywords = [name for name, p in parameters.items() if p.kind is p.KEYWORD_ONLY]
    assert set(snede.NeedleOptions()._asdict()) - {"friction_channel"} <= set(keywords)
    assert {parameters[name].default for name in keywords} == {None}
    solver = snede.NeedleInsertion.default_solver_options()
    assert (solver.method, solver.rtol, solver.round_tolerance, solver.options_prefix) == ("cg", 1e-3, 1e-8, "needle_")
    assert solver.max_iterations == snede.StaticOptions().max_iterations  # the rest are the solver's defaults
    assert needle(cube()).options == snede.NeedleOptions()


def test_the_radius_unset_is_one_millimetre_in_3d_and_a_line_in_2d():
    assert snede.NeedleOptions().radius is None and snede.NeedleOptions.default_radius == 1e-3
    assert needle(cube()).radius == 1e-3
    assert needle(cube(), radius=2e-3).radius == 2e-3
    assert needle(sheet()).radius == 0.0
    with pytest.raises(ValueError, match="radius is for 3D needles.*radius=0.001"):
        needle(sheet(), options=snede.NeedleOptions(radius=1e-3))


def test_records_given_whole_and_keywords_change_their_fields():
    options = snede.NeedleOptions(static_factor=3.0, max_rearrangements=7, extension_rings=0, radius=2e-3)
    insertion = needle(cube(), options=options, solves_per_update=1)
    assert insertion.options == snede.NeedleOptions(static_factor=3.0, max_rearrangements=7, extension_rings=0,
                                                    radius=2e-3, solves_per_update=1)
    assert options.solves_per_update == 0  # the record given is not changed
    solver = snede.StaticOptions(method="newton", rtol=1e-6, options_prefix="my_needle_")
    made = needle(cube(), solver=solver, rtol=1e-5, petsc_options={"snes_max_it": 5}).solver_options
    assert (made.method, made.rtol, made.options_prefix) == ("newton", 1e-5, "my_needle_")
    assert ("snes_max_it", "5") in made.petsc_options
    assert ("mg_coarsening", "grid") in made.petsc_options  # the needle's own choice, since none was given
    assert needle(cube()).solver_options.method == "cg"
    with pytest.raises(TypeError, match="options must be a snede.NeedleOptions"):
        needle(cube(), options={"radius": 1e-3})
    with pytest.raises(TypeError, match="options must be a snede.StaticOptions"):
        needle(cube(), solver=snede.NeedleOptions())


@pytest.mark.parametrize("settings, message", [
    (dict(static_factor=0.5), "static_factor must be at least 1"),
    (dict(radius=0.0), "radius must be positive and finite"),
    (dict(radius=-1e-3), "radius must be positive and finite"),
    (dict(h_ref=float("inf")), "h_ref must be positive and finite"),
    (dict(extension_rings=-1), "extension_rings must be at least 0"),
    (dict(method="gmres"), "method must be 'cg', 'ncg' or 'newton'"),
    (dict(rtol=-1.0), "rtol must be positive"),
])
def test_bad_settings_are_refused_by_name(settings, message):
    with pytest.raises(ValueError, match=message):
        needle(cube(), **settings)


@pytest.mark.parametrize("record, message", [
    (lambda: snede.NeedleOptions(extension_rings=-2), "extension_rings must be 0 .*got -2"),
    (lambda: snede.NeedleOptions(friction_channel=""), "friction_channel must name a load channel"),
    (lambda: snede.NeedleOptions(solves_per_update=-1), "solves_per_update must be 0 .*got -1"),
])
def test_the_record_checks_its_own_fields(record, message):
    with pytest.raises(ValueError, match=message):
        record()
