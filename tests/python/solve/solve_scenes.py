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
