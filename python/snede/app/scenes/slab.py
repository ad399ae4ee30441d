"""§6.8.1: a plane-stress slab 0.1 × 0.1 m, 0.01 m thick (E = 34 kPa, ν = 0.34) held at
x = 0.1 m and loaded along y = 0.05 m over the 70 mm a needle would occupy, with a line load
shaped like Figure 6.4: uniform shaft friction plus a bulge near the tip where the needle
cuts (our stand-in for DiMaio and Salcudean's measured profile; total 0.2 N)."""
import numpy as np

import snede
from snede.app.plotting import LOAD
from snede.app.scenes.scene import Parameters, Scene, divisions, material

SIZE, THICKNESS, DEPTH, TOTAL_FORCE = 0.1, 0.01, 0.07, 0.2
PLOT_SCALE = 20.0  # the slab moves half a millimetre: exaggerated in the picture
OPTIONS = ("divisions", "formulation")  # the scene options it uses (the command line refuses the others)
DESCRIPTION = "§6.8.1 plane-stress slab with a needle-like line load (Figure 6.4 shape)"


def friction_profile(s):
    """Force per unit length along the shaft at distance s from the entry (relative units):
    1 along the shaft, rising to 4 in a 5 mm bulge at the tip (s = DEPTH)."""
    return 1.0 + 3.0 * np.exp(-0.5 * ((s - DEPTH + 0.0025) / 0.0015) ** 2)


def held(points) -> np.ndarray:
    """The vertices the slab is held at: its side x = 0.1 m."""
    return np.isclose(points[:, 0], SIZE)


def build(parameters: Parameters) -> Scene:
    n = divisions(parameters, 16, 2, "for the slab must be even (the load line is y = 0.05)")
    mesh = snede.meshing.rectangle((SIZE, SIZE), (n, n))
    body = snede.Body(mesh, material(parameters.material or "linear", 34e3, 0.34), density=1000.0, thickness=THICKNESS,
                      formulation=parameters.formulation or "p1")
    x = mesh.points
    body.fix(held(x))
    line = np.flatnonzero(np.isclose(x[:, 1], SIZE / 2) & (x[:, 0] <= DEPTH + 1e-12))
    # Lumped line load: each node gets the profile times its share of the line length.
    order = line[np.argsort(x[line, 0])]
    s = x[order, 0]
    share = np.gradient(s) if len(s) > 1 else np.ones(1)
    weights = friction_profile(s) * share
    forces = np.zeros((len(order), 2))
    forces[:, 0] = TOTAL_FORCE * weights / weights.sum()  # pushes along the insertion (+x)
    body.add_nodal_force(order, forces)
    entry = order[0]

    def decorate(ax) -> None:
        """The load line, where the needle would be, on the deformed slab (as the picture scales it)."""
        line = x[order] + PLOT_SCALE * body.displacement[order]
        ax.plot(line[:, 0], line[:, 1], color=LOAD, linewidth=3, alpha=0.6, solid_capstyle="butt", zorder=3,
                label=f"line load, {TOTAL_FORCE:g} N along +x", gid="load-line")

    return Scene(
        name="slab", description=DESCRIPTION, body=body, default_method="cg",
        probe_name="entry-point displacement [m]", probe=lambda b: float(b.displacement[entry, 0]),
        damping=20.0, plot_scale=PLOT_SCALE, decorate=decorate, fixed=held, details={"divisions": [n, n]})
