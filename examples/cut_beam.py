"""A user scene with a topology change: the beam of sagging_beam.py is cut halfway through
from below at x = 5 cm (§7.3 dissect), and the relaxation continues from the carried-over
state. The XDMF series holds both meshes: step 1 is before the cut, step 2 after.

Run it with `python -m snede run examples/cut_beam.py`.
"""
import numpy as np

import snede
from snede.output import SeriesWriter
from snede.app.plotting import plot_body

mesh = snede.meshing.box((0.10, 0.02, 0.02), (20, 4, 4))
body = snede.Body(mesh, snede.NeoHookean(E=3e4, nu=0.3), density=1000.0)
body.fix(np.isclose(mesh.points[:, 0], 0.0))
body.add_gravity((0.0, 0.0, -9.81))
solver = snede.StaticSolver(body, "newton", rtol=1e-8)
folder = snede.output_folder("cut_beam")  # out/cut_beam, or --out DIR/cut_beam
series = SeriesWriter(folder / "cut_beam")
series.write(body, time=0.0)
print("before the cut:", solver.solve())
series.write(body, time=1.0)

# The cut: interior faces on the plane x = 0.05 in the lower half (z ≤ 0.01).
copies = mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.05) & (x[:, 2] <= 0.01 + 1e-12)))
print(f"cut: {len(copies)} vertices duplicated; the body now has {mesh.n_points} points")

print("after the cut: ", solver.solve())  # same solver: sizes were reissued by the watcher
series.write(body, time=2.0)
plot_body(body, folder / "cut_beam.png", title="beam cut from below at x = 5 cm")
print(f"wrote {series.xdmf_path} ({series.n_steps} steps, {series.n_meshes} meshes)")
