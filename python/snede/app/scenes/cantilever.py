"""§3.3: a 1.2 × 0.2 × 0.3 m beam (E = 1 MPa, ν = 0) fixed at x = 0 with 3 N at the tip.
Beam theory gives the tip deflection y = 4F/(Ed) (l/h)³ = 8.64 mm (Table 3.1)."""
import numpy as np

import snede
from snede.app.scenes.scene import Parameters, Scene, divisions, material

LENGTH, HEIGHT, DEPTH, YOUNG, LOAD = 1.2, 0.2, 0.3, 1e6, 3.0
VIEW = (20.0, 30.0, 0.0, "y")  # the picture's camera: y up, the beam bending down across the picture
OPTIONS = ("divisions", "formulation")  # the scene options it uses (the command line refuses the others)
DESCRIPTION = "§3.3 cantilever beam, 3 N tip load, analytic tip deflection 8.64 mm"


def held(points) -> np.ndarray:
    """The vertices the beam is held at: its end x = 0."""
    return np.isclose(points[:, 0], 0.0)


def build(parameters: Parameters) -> Scene:
    n = divisions(parameters, 16, 4, "for the cantilever must be a multiple of 4 (n × n/4 × n/4 cubes)")
    mesh = snede.meshing.box((LENGTH, HEIGHT, DEPTH), (n, n // 4, n // 4))
    body = snede.Body(mesh, material(parameters.material or "linear", YOUNG, 0.0), density=1000.0, formulation=parameters.formulation or "p1")
    x = mesh.points
    body.fix(held(x))
    tip = np.flatnonzero(np.isclose(x[:, 0], LENGTH))
    body.add_nodal_force(tip, (0.0, -LOAD / len(tip), 0.0))
    return Scene(
        name="cantilever", description=DESCRIPTION, body=body, default_method="cg",
        probe_name="tip deflection [m]", probe=lambda b: float(-b.displacement[tip, 1].mean()),
        analytic=4 * LOAD / (YOUNG * DEPTH) * (LENGTH / HEIGHT) ** 3, damping=17.0, plot_scale=10.0,
        fixed=held, picture=lambda: {"view": VIEW}, details={"divisions": [n, n // 4, n // 4]})
