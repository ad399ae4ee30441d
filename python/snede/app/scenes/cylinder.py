"""§4.2: the soft horizontal cylinder (length 0.1 m, radius 0.03 m, Tables 4.1–4.2) fixed at
x = 0 and sagging under gravity; neo-Hookean by default (E = 10 kPa, ν = 0.3, ρ = 1000, γ = 8)."""
from pathlib import Path

import numpy as np

import snede
from snede.app.scenes.scene import Parameters, Scene, material

MESHES = Path(__file__).resolve().parents[4] / "meshes"
OPTIONS = ("mesh_size", "formulation")  # the scene options it uses (the command line refuses the others)
DESCRIPTION = "§4.2 soft cylinder under gravity (Table 4.1 parameters), no analytic solution"
ETA_CRIT = {"linear": 17.0, "stvk": 20.0, "neohookean": 21.0, "veronda": 27.0}  # Table 4.4


def build(parameters: Parameters) -> Scene:
    if parameters.mesh_size:
        mesh = snede.meshing.cylinder(0.1, 0.03, parameters.mesh_size, seed=1)
    else:
        mesh = snede.Mesh.read(MESHES / "cylinder_small.msh")
    name = parameters.material or "neohookean"
    body = snede.Body(mesh, material(name, 1e4, 0.3, 8.0), density=1000.0, formulation=parameters.formulation or "p1")
    x0 = mesh.points[:, 0].min()

    def held(points) -> np.ndarray:  # the end x = x0
        return np.isclose(points[:, 0], x0)

    body.fix(held(mesh.points))
    body.add_gravity((0.0, 0.0, -9.8))
    tip = np.flatnonzero(np.isclose(mesh.points[:, 0], mesh.points[:, 0].max()))
    return Scene(
        name="cylinder", description=DESCRIPTION, body=body, default_method="newton",
        probe_name="tip sag [m]", probe=lambda b: float(-b.displacement[tip, 2].mean()),
        damping=ETA_CRIT[name], fixed=held,
        details={"mesh": "cylinder_small.msh" if not parameters.mesh_size else f"h={parameters.mesh_size}"})
