"""Issue 14 items: convergence is never reported at overflow and does not depend on the units;
solver arguments are checked; materials say what they are; XDMF names are escaped."""
import math
import sys
import xml.etree.ElementTree as ElementTree

import meshio
import numpy as np
import pytest

import snede
from snede.output import SeriesWriter


def sagging_sheet(young, material=snede.LinearElastic):
    mesh = snede.meshing.rectangle((1.0, 0.2), (10, 2))
    body = snede.Body(mesh, material(young, 0.3), thickness=0.01, density=1.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81 * young / 1e5))  # loads scaled with E: the same displacement
    return body


# Every method runs on the system divided by the force scale (before, ncg and newton failed
# from E = 1e150 on: DIVERGED_LINE_SEARCH, DIVERGED_LINEAR_SOLVE). Below E = 1e-150 linear CG
# said CONVERGED after 0 iterations with u = 0: PETSc's norm of the forces (1e-158 N and less)
# underflowed to 0 and was cached through the right-hand side (issue 38 item 4).
@pytest.mark.parametrize("method", ["cg", "ncg", "newton"])
def test_the_displacement_does_not_depend_on_the_units_from_1e_minus300_to_1e160(method):
    reference = sagging_sheet(1e5)
    assert snede.StaticSolver(reference, "cg", rtol=1e-10).solve().converged
    for young in (1e-300, 1e-200, 1e-160, 1e-3, 1.0, 1e150, 1e155, 1e160):
        body = sagging_sheet(young)
        result = snede.StaticSolver(body, method, rtol=1e-10).solve()
        assert result.converged and np.isfinite(result.tolerance), (young, result)
        np.testing.assert_allclose(body.displacement, reference.displacement, rtol=1e-7,
                                   atol=1e-9 * np.abs(reference.displacement).max())


@pytest.mark.parametrize("method", ["cg", "ncg", "newton", "dynamic"])
def test_loads_beyond_double_range_are_never_converged(method):
    body = sagging_sheet(1e5)
    body.add_gravity((0.0, -1e300))
    if method == "dynamic":
        result = snede.DynamicRelaxation(body, 20.0).run(rtol=1e-6, max_steps=200)
    else:
        result = snede.StaticSolver(body, method, rtol=1e-6).solve()
    assert not result.converged


# 2D plane stress: the neo-Hookean thickness stretch squared λ (overflow from E = 1e155,
# DIVERGED_NONFINITE_STATE; underflow below 1e-160, a converged but wrong state).
@pytest.mark.parametrize("material", [snede.NeoHookean, snede.StVenantKirchhoff,
                                      lambda E, nu: snede.VerondaWestmann(E, nu, gamma=8.0)])
@pytest.mark.parametrize("method", ["ncg", "newton"])
def test_nonlinear_plane_stress_does_not_depend_on_the_units_from_1e_minus300_to_1e160(material, method):
    reference = sagging_sheet(1e5, material)
    assert snede.StaticSolver(reference, "newton", rtol=1e-10).solve().converged
    for young in (1e-300, 1e-200, 1e155, 1e160):
        body = sagging_sheet(young, material)
        result = snede.StaticSolver(body, method, rtol=1e-10).solve()
        assert result.converged, (young, result)
        np.testing.assert_allclose(body.displacement, reference.displacement, rtol=1e-7,
                                   atol=1e-8 * np.abs(reference.displacement).max())


def test_dynamic_relaxation_reaches_the_same_displacement_whatever_the_units():
    reference = sagging_sheet(1e5)
    assert snede.StaticSolver(reference, "cg", rtol=1e-10).solve().converged
    # 1e-200: the 2D wave speed's μ(λ + μ) underflowed to 0, the CFL step was inf (issue 38 item 4).
    for young in (1e-200, 1e-3, 1e5, 1e150):
        body = sagging_sheet(young)
        dynamics = snede.DynamicRelaxation(body, 2.0 * np.sqrt(young / 1e5) * 20.0)
        result = dynamics.run(rtol=1e-8, max_steps=200000)
        assert result.converged and np.isfinite(result.residual_norm), (young, result)
        np.testing.assert_allclose(body.displacement, reference.displacement, rtol=1e-5,
                                   atol=1e-6 * np.abs(reference.displacement).max())


@pytest.mark.parametrize("kwargs, fragment", [
    ({"round_tolerance": -1.0}, "round_tolerance must be finite and non-negative"),
    ({"round_tolerance": float("nan")}, "round_tolerance"),
    ({"max_iterations": -1}, "max_iterations must be at least 1, got -1"),
])
def test_solver_arguments_are_checked_with_the_value(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        snede.StaticSolver(sagging_sheet(1e5), "cg", **kwargs)


def test_materials_show_their_parameters():
    assert repr(snede.NeoHookean(34e3, 0.34)) == "NeoHookean(E=34000.0, nu=0.34)"
    veronda = snede.VerondaWestmann(3e3, 0.3, 8.0)
    assert repr(veronda).startswith("VerondaWestmann(E=3000.0") and "gamma=8.0" in repr(veronda)
    assert veronda.E == pytest.approx(3e3) and veronda.nu == pytest.approx(0.3)
    with pytest.raises(ValueError, match="needs gamma"):
        snede.VerondaWestmann(3e3, 0.3)
    with pytest.raises(ValueError, match="needs nu, Poisson's ratio, and gamma"):
        snede.VerondaWestmann(3e3)
    # E and ν come back from the Lamé parameters; the repr does not show their round-off.
    assert repr(snede.LinearElastic(1e3, 0.3)) == "LinearElastic(E=1000.0, nu=0.3)"
    assert repr(snede.StVenantKirchhoff(2.5e-3, 0.1)) == "StVenantKirchhoff(E=0.0025, nu=0.1)"
    assert repr(snede.VerondaWestmann(3e3, 0.3, 8.0)) == "VerondaWestmann(E=3000.0, nu=0.3, gamma=8.0)"


def test_xdmf_field_names_are_escaped_and_bad_ones_refused(tmp_path):
    mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
    writer = SeriesWriter(tmp_path / "names")
    odd = 'E<1&2 "x"'
    writer.write_mesh(mesh, 0.0, **{odd: np.arange(mesh.n_cells, dtype=float)})
    names = [a.get("Name") for a in ElementTree.parse(writer.xdmf_path).iter("Attribute")]
    assert odd in names
    with meshio.xdmf.TimeSeriesReader(str(writer.xdmf_path)) as reader:
        reader.read_points_cells()
        _, _, cell_data = reader.read_data(0)
    np.testing.assert_array_equal(cell_data[odd][0], np.arange(mesh.n_cells))
    for bad in ("a/b", ""):
        with pytest.raises(ValueError, match="not usable"):
            writer.write_mesh(mesh, 1.0, **{bad: np.zeros(mesh.n_cells)})
    with pytest.raises(ValueError, match="used twice"):
        writer.write_mesh(mesh, 1.0, point_fields={"aspect_ratio": np.zeros(mesh.n_points)})


ORPHANED_HANDLE = """
import gc, sys
import numpy as np
import snede
from snede import PETSc

mesh = snede.meshing.rectangle((1.0, 0.2), (6, 2))
body = snede.Body(mesh, snede.LinearElastic(1e3, 0.3), thickness=0.01)
body.fix(np.isclose(mesh.points[:, 0], 0.0))
body.add_gravity((0.0, -9.81))
x = body._model.displacement_vec.duplicate()
which = sys.argv[1]
if which == "snes":
    owner = snede.StaticSolver(body, "newton"); handle = owner.snes
    use = lambda: handle.solve(None, x)
elif which == "ncg":
    owner = snede.StaticSolver(body, "ncg"); handle = owner.snes
    use = lambda: handle.solve(None, x)
elif which == "ksp":
    owner = snede.StaticSolver(body, "cg"); handle = owner.ksp
    use = lambda: handle.solve(x.duplicate(), x)
elif which == "ts":
    owner = snede.DynamicRelaxation(body, damping=20.0); handle = owner.ts
    use = lambda: handle.step()
elif which == "tangent":
    owner = body; handle = body._model.tangent_mat
    use = lambda: handle.mult(x.duplicate(), x)
del owner
if which == "tangent":
    del body
gc.collect()
try:
    use()
except PETSc.Error as error:
    print("raised", error)
else:
    print("no error")
"""


@pytest.mark.parametrize("which", ["snes", "ncg", "ksp", "ts", "tangent"])
def test_a_petsc4py_handle_used_after_its_owner_was_deleted_raises_instead_of_crashing(which):
    import subprocess
    import sys

    result = subprocess.run([sys.executable, "-c", ORPHANED_HANDLE, which], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, (result.returncode, result.stderr[-2000:])
    assert result.stdout.startswith("raised"), result.stdout + result.stderr[-2000:]


def test_fixing_one_vertex_twice_with_different_values_is_refused_and_changes_nothing():
    body = sagging_sheet(1e5)
    with pytest.raises(ValueError, match="vertex 3 is listed twice .* different values"):
        body.fix([3, 5, 3], [[0.0, 0.0], [0.0, 0.0], [0.1, 0.0]])
    assert np.abs(body.reaction_forces()[3]).max() == 0.0 and np.all(body.displacement[3] == 0)
    body.fix([3, 3], [[0.1, 0.0], [0.1, 0.0]])  # the same value twice is harmless
    assert body.displacement[3, 0] == 0.1


UNIT_CELLS = {  # cell dimension: (corners, measure of the unit cell)
    2: (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), 0.5),
    3: (np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), 1.0 / 6.0),
}


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("scale", [1e-310, 1e-200, 1e-150, 1e-100, 1.0, 1e100, 1e150, 1e200, 1e300])
def test_a_mesh_is_accepted_where_its_measures_are_doubles_and_refused_with_the_reason_elsewhere(scale, dim):
    corners, unit_measure = UNIT_CELLS[dim]
    # Independent of the engine: whether scale^dim · unit measure is a normal double, in logarithms.
    log_measure = dim * math.log10(scale) + math.log10(unit_measure)
    representable = math.log10(sys.float_info.min) < log_measure < math.log10(sys.float_info.max)
    if representable:
        mesh = snede.Mesh(scale * corners, [list(range(dim + 1))])
        mesh.validate()
        assert mesh.quality().volume[0] == pytest.approx(unit_measure * scale**dim, rel=1e-12)
    else:
        units = "smaller" if log_measure < 0 else "larger"
        with pytest.raises(ValueError, match=f"cell 0's (area|volume) is too .* in {units} units"):
            snede.Mesh(scale * corners, [list(range(dim + 1))])
    flat = scale * np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    with pytest.raises(ValueError, match="zero"):
        snede.Mesh(flat, [[0, 1, 2]])


FAILED_CONSTRUCTIONS = """
import numpy as np
import snede
from snede import _snede

mesh = snede.meshing.rectangle((1.0, 0.2), (6, 2))
body = snede.Body(mesh, snede.LinearElastic(1e3, 0.3), thickness=0.01)
body.fix(np.isclose(mesh.points[:, 0], 0.0))
friction = snede.FrictionProfile.uniform(1.0)

FAILURES = {  # each construction fails on an option, after it has made some PETSc objects
    "cg": lambda: snede.StaticSolver(body, "cg", petsc_options={"ksp_type": "nosuchtype"}),
    "ncg": lambda: snede.StaticSolver(body, "ncg", petsc_options={"snes_type": "nosuchtype"}),
    "newton": lambda: snede.StaticSolver(body, "newton", petsc_options={"snes_type": "nosuchtype"}),
    "dynamic, unknown TS": lambda: snede.DynamicRelaxation(body, 10.0, petsc_options={"ts_type": "nosuchtype"}),
    "dynamic, other TS": lambda: snede.DynamicRelaxation(body, 10.0, petsc_options={"ts_type": "euler"}),
    "needle": lambda: snede.NeedleInsertion(body, (0.0, 0.1), (1.0, 0.0), friction, method="newton",
                                            petsc_options={"snes_type": "nosuchtype"}),
}

def fail(make):
    try:
        make()
    except (snede.PetscError, ValueError):
        return
    raise SystemExit("a bad option was accepted")

for make in FAILURES.values():
    for _ in range(10):
        fail(make)  # warm-up: PETSc's registries and caches
before = _snede.petsc_allocated_bytes()
for k in range(1002):
    fail(list(FAILURES.values())[k % len(FAILURES)])
print(before, _snede.petsc_allocated_bytes())
"""


def test_failed_solver_constructions_leave_petsc_memory_flat():
    import os
    import subprocess
    import sys

    env = dict(os.environ, PETSC_OPTIONS="-malloc_debug")
    result = subprocess.run([sys.executable, "-c", FAILED_CONSTRUCTIONS], capture_output=True, text=True,
                            timeout=300, env=env)
    assert result.returncode == 0, result.stderr[-2000:]
    # The first line; PETSc's -malloc_debug report of what is still allocated at exit follows.
    before, after = map(float, result.stdout.splitlines()[0].split())
    assert before > 0  # -malloc_debug tracks PETSc's allocations
    # 1002 failed constructions (static, dynamic, needle): the ~25 kB each used to leak would be
    # over 20 MB; PETSc keeps about 50 bytes per failure (option strings, PetscStrallocpy).
    assert after - before < 100e3, (before, after)


class MonitorError(Exception):
    pass


def raise_from_monitor(exception):
    def monitor(*args):
        raise exception
    return monitor


@pytest.mark.parametrize("handle", ["snes (newton)", "ksp (cg)", "ts (dynamic)"])
@pytest.mark.parametrize("exception", [MonitorError("from my monitor"), KeyboardInterrupt()])
def test_an_exception_inside_a_petsc_monitor_keeps_its_type_and_message(handle, exception):
    # PETSc runs the petsc4py monitor, which raises: the caller gets that exception (before:
    # "PetscError: PETSc error -1"), a Ctrl-C in a monitor is a KeyboardInterrupt, and the
    # solver still works once the monitor is gone.
    body = sagging_sheet(1e5)
    if handle == "ts (dynamic)":
        solver = snede.DynamicRelaxation(body, damping=20.0)
        petsc_object, run = solver.ts, lambda: solver.run(1e-2)
    else:
        solver = snede.StaticSolver(body, "newton" if handle.startswith("snes") else "cg")
        petsc_object, run = (solver.snes if handle.startswith("snes") else solver.ksp), solver.solve
    petsc_object.setMonitor(raise_from_monitor(exception))
    with pytest.raises(type(exception)) as raised:
        run()
    assert str(raised.value) == str(exception)
    petsc_object.cancelMonitor()
    assert run().converged


DELETED_FOLDER_SCRIPT = """
import shutil
import sys
from pathlib import Path

import snede
from snede.output import SeriesWriter

out = Path(sys.argv[1])
mesh = snede.meshing.rectangle((1.0, 1.0), (2, 2))
body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3), thickness=0.01)
writer = SeriesWriter(out / "series")
writer.write(body, 0.0)
shutil.rmtree(out)  # the output folder goes away mid-run
writer.write(body, 1.0)
print("NOT REACHED")
"""


def test_an_output_folder_deleted_mid_run_stops_the_command_line_with_one_line(tmp_path):
    # Item 8: the writer's failure is a snede.FileError (an OSError) naming the file; the
    # command line prints it on one line and exits 2 instead of showing a traceback.
    import subprocess
    import sys

    script = tmp_path / "deleting.py"
    script.write_text(DELETED_FOLDER_SCRIPT)
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, "-m", "snede", "run", str(script), str(out)], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 2, (result.stdout, result.stderr)
    assert "NOT REACHED" not in result.stdout and "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("python -m snede: error: cannot open") and "series.h5" in lines[0], lines
    assert issubclass(snede.FileError, OSError)


@pytest.mark.parametrize("method", ["cg", "ncg", "newton"])
def test_every_method_continues_after_a_dissection_and_agrees_with_a_new_solver(method):
    # Item 3 (ncg raised "Incompatible vector local lengths" after a mesh change): a cut that
    # adds vertices, then the same solver object solves again, from the carried-over state.
    mesh = snede.meshing.rectangle((1.0, 0.2), (10, 2))
    material = snede.LinearElastic(1e5, 0.3) if method == "cg" else snede.NeoHookean(1e5, 0.3)
    body = snede.Body(mesh, material, thickness=0.01, density=1.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81))
    solver = snede.StaticSolver(body, method, rtol=1e-9)
    assert solver.solve().converged
    n_before = mesh.n_points
    faces = mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5) & (x[:, 1] < 0.15))
    assert len(mesh.dissect(faces)) > 0 and mesh.n_points > n_before
    after = solver.solve()
    assert after.converged, after
    carried = body.displacement.copy()
    body.displacement = np.zeros_like(carried)
    fresh = snede.StaticSolver(body, method, rtol=1e-9, options_prefix="fresh_").solve()
    assert fresh.converged, fresh
    np.testing.assert_allclose(carried, body.displacement, atol=1e-6 * np.abs(carried).max())
