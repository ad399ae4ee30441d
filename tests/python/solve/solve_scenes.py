"""Small scenes shared by the solver tests."""
import numpy as np

import snede

# §3.3: l × h × d beam, E = 1e6 Pa, ν = 0, 3 N at the tip; y = 4F/(Ed) (l/h)³ = 8.64e-3 m.
BEAM = dict(l=1.2, h=0.2, d=0.3, E=1e6, load=3.0)
BEAM_DEFLECTION = 4 * BEAM["load"] / (BEAM["E"] * BEAM["d"]) * (BEAM["l"] / BEAM["h"]) ** 3


def cantilever(divisions, material=None):
    """The §3.3 beam on the structured mesh (l × h × d cubes); returns (body, tip vertices)."""
    mesh = snede.meshing.box((BEAM["l"], BEAM["h"], BEAM["d"]), divisions)
    body = snede.Body(mesh, material or snede.LinearElastic(BEAM["E"], 0.0))
    x = mesh.points
    body.fix(np.isclose(x[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(x[:, 0], BEAM["l"]))
    body.add_nodal_force(tip, (0.0, -BEAM["load"] / len(tip), 0.0))
    return body, tip


def soft_beam(material=None, divisions=(8, 2, 2)):
    """A soft beam 0.1 × 0.02 × 0.02 m fixed at x = 0 under gravity: large deflection."""
    mesh = snede.meshing.box((0.1, 0.02, 0.02), divisions)
    body = snede.Body(mesh, material or snede.NeoHookean(3e4, 0.3), density=1000.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    return body


def solve_from_rest(body, method="cg", rtol=1e-8, **options):
    """A solve from rest; without a preconditioner unless one is given (the plain reference).
    Returns (solver, result, displacement)."""
    options.setdefault("preconditioner", "none")
    body.displacement = np.zeros_like(body.displacement)
    solver = snede.StaticSolver(body, method, rtol=rtol, **options)
    result = solver.solve()
    return solver, result, body.displacement.copy()


def relative_difference(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


def as_dense(mat):
    """The entries of an assembled petsc4py Mat as a numpy array."""
    rows, columns = mat.getSize()
    result = np.zeros((rows, columns))
    for i in range(rows):
        cols, values = mat.getRow(i)
        result[i, cols] = values
    return result


def sagging_sheet(young, material=snede.LinearElastic):
    """A plane-stress sheet 1 × 0.2 m fixed at x = 0 under gravity scaled with E: the same
    displacement whatever the units."""
    mesh = snede.meshing.rectangle((1.0, 0.2), (10, 2))
    body = snede.Body(mesh, material(young, 0.3), thickness=0.01, density=1.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81 * young / 1e5))  # loads scaled with E: the same displacement
    return body
