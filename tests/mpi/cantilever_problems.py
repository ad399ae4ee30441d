"""The cantilevers the distributed tests solve: a 4 × 1 × 1 box (or a plane-stress 4 × 1 bar)
held at x = 0 and pulled down by 200 N spread over its tip, with snede's serial StaticSolver
as the reference."""
import numpy as np

import snede


def cantilever(dim):
    if dim == 3:
        return snede.meshing.box((4.0, 1.0, 1.0), (8, 2, 2)), None
    return snede.meshing.rectangle((4.0, 1.0), (16, 4)), 0.1


def conditions(mesh):
    x = mesh.points
    fixed = np.flatnonzero(np.isclose(x[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(x[:, 0], 4.0))
    force = np.zeros(mesh.dim)
    force[-1] = -200.0 / len(tip)
    return fixed, tip, force


def serial_solution(mesh, material, thickness, method):
    fixed, tip, force = conditions(mesh)
    body = snede.Body(mesh, material, thickness=thickness)
    body.fix(fixed)
    body.add_nodal_force(tip, force)
    result = snede.StaticSolver(body, method, preconditioner="none", rtol=1e-12).solve()
    assert result.converged, result
    return body.displacement


def linear_cantilever_problem(comm):
    """The linear 3D cantilever as a DistributedStatic over ``comm`` (COMM_SELF: the whole mesh
    on each rank alone)."""
    serial, _ = cantilever(3)
    fixed, tip, force = conditions(serial)
    part = snede.distribute(serial if comm.rank == 0 else None, comm)
    return snede.DistributedStatic(part, snede.LinearElastic(1e5, 0.3), fixed=fixed, forces={int(v): force for v in tip})
