"""A static scene on several ranks through the command line's path (run_scene.run, as
`mpirun -n N python -m snede run cantilever` calls it): the probe and files as the serial run
gives them; scenes that change their mesh are refused with NotImplementedError on every rank.
On one rank the serial path runs (the serial tests cover it)."""
import json
from pathlib import Path

import pytest
from mpi4py import MPI

from snede import DynamicRelaxation, StaticSolver
from snede.app import run_scene
from snede.output import read_series
from snede.app.scenes import Parameters, cantilever, cylinder, needle

COMM = MPI.COMM_WORLD
several = pytest.mark.skipif(COMM.size == 1, reason="the distributed path needs several ranks")


def options(**given):
    return Parameters(**given)


@several
def test_cantilever_on_several_ranks_matches_the_serial_run(tmp_path_factory):
    folder = Path(COMM.bcast(str(tmp_path_factory.mktemp("mpi")) if COMM.rank == 0 else None))
    summary = run_scene.run(cantilever.build(options(divisions=8)), None, 1e-10, folder, progress=False)
    assert summary["converged"] and summary["ranks"] == COMM.size
    assert sum(summary["cells_per_rank"]) == 8 * 2 * 2 * 6
    if COMM.rank == 0:
        # Rank 0 wrote what a serial run writes, and its probe is the serial solve's.
        written = json.loads((folder / "cantilever" / "summary.json").read_text())
        assert written["value"] == pytest.approx(summary["value"])
        assert (folder / "cantilever" / "cantilever.png").exists()
        # The ranks wrote one series together: the unloaded and the solved state on one mesh.
        unloaded, solved = read_series(folder / "cantilever" / "cantilever.xdmf")
        assert unloaded.mesh is solved.mesh and solved.mesh.n_cells == 8 * 2 * 2 * 6
        assert not unloaded.point_fields["displacement"].any() and solved.point_fields["displacement"].any()
        serial = cantilever.build(options(divisions=8))
        assert StaticSolver(serial.body, "cg", preconditioner="none", rtol=1e-12).solve().converged
        assert summary["value"] == pytest.approx(serial.probe(serial.body), rel=1e-8)
    COMM.Barrier()


@several
@pytest.mark.parametrize("method", ["ncg", "dynamic"])
def test_cantilever_by_nonlinear_cg_or_dynamic_relaxation_matches_the_serial_run(method, tmp_path_factory):
    """`--method ncg` and `--method dynamic` on several ranks: nonlinear CG gives the serial
    static probe; dynamic relaxation (the scene's η, the CFL step) takes as many steps as the
    serial DynamicRelaxation and gives its probe."""
    folder = Path(COMM.bcast(str(tmp_path_factory.mktemp("mpi")) if COMM.rank == 0 else None))
    rtol = 1e-10 if method == "ncg" else 1e-6
    summary = run_scene.run(cantilever.build(options(divisions=8)), method, rtol, folder, progress=False)
    assert summary["converged"] and summary["ranks"] == COMM.size
    if COMM.rank == 0:
        serial = cantilever.build(options(divisions=8))
        if method == "ncg":
            assert StaticSolver(serial.body, "cg", preconditioner="none", rtol=1e-12).solve().converged
            assert summary["value"] == pytest.approx(serial.probe(serial.body), rel=1e-7)
        else:
            result = DynamicRelaxation(serial.body, damping=serial.damping).run(rtol=rtol)
            assert result.converged and result.iterations == summary["iterations"]
            assert summary["value"] == pytest.approx(serial.probe(serial.body), rel=1e-10)
    COMM.Barrier()


@several
def test_a_neo_hookean_cylinder_under_gravity_matches_the_serial_solve(tmp_path_factory):
    """Gravity reaches the distributed solve as the lumped nodal forces of the serial mesh
    (they do not depend on the state): Newton on N ranks gives the serial tip sag."""
    folder = Path(COMM.bcast(str(tmp_path_factory.mktemp("mpi")) if COMM.rank == 0 else None))
    summary = run_scene.run(cylinder.build(options()), None, 1e-10, folder, progress=False)
    assert summary["converged"] and summary["ranks"] == COMM.size
    if COMM.rank == 0:
        serial = cylinder.build(options())
        assert StaticSolver(serial.body, "newton", preconditioner="none", rtol=1e-12).solve().converged
        assert summary["value"] == pytest.approx(serial.probe(serial.body), rel=1e-7)
    COMM.Barrier()


@several
def test_a_scene_that_changes_its_mesh_is_refused_on_every_rank(tmp_path_factory):
    folder = Path(COMM.bcast(str(tmp_path_factory.mktemp("mpi")) if COMM.rank == 0 else None))
    with pytest.raises(NotImplementedError, match=r"needle on \d MPI ranks: it changes its mesh"):
        run_scene.run(needle.build(options()), None, None, folder, progress=False)
    assert COMM.allreduce(1) == COMM.size  # no rank left waiting
