"""A user scene: a soft neo-Hookean beam fixed at one end sags under gravity.

Run it with `python -m snede run examples/sagging_beam.py` (add PETSc options such as
-static_snes_monitor); it writes out/sagging_beam/ (XDMF for ParaView and a PNG), or with
--out DIR, DIR/sagging_beam/.
"""
import numpy as np

import snede
from snede.output import SeriesWriter
from snede.app.plotting import plot_body

# 1. Mesh: 10 cm × 2 cm × 2 cm, Kuhn-split cubes.
mesh = snede.meshing.box((0.10, 0.02, 0.02), (20, 4, 4))

# 2. Material and body: E = 30 kPa, ν = 0.3, water-like density.
body = snede.Body(mesh, snede.NeoHookean(E=3e4, nu=0.3), density=1000.0)

# 3. Constraints and loads: clamp x = 0, gravity along −z.
body.fix(np.isclose(mesh.points[:, 0], 0.0))
body.add_gravity((0.0, 0.0, -9.81))

# 4. Solve: truncated Newton; the result says whether it converged and why.
result = snede.StaticSolver(body, "newton", rtol=1e-8).solve()
print(result)

# 5. Output: a ParaView series (reference and deformed) and a picture.
folder = snede.output_folder("sagging_beam")  # out/sagging_beam, or --out DIR/sagging_beam
series = SeriesWriter(folder / "sagging_beam")
series.write(body, time=0.0, displacement=np.zeros_like(body.displacement))
series.write(body, time=1.0)
plot_body(body, folder / "sagging_beam.png", title="sagging beam")
print(f"tip sag {-body.displacement[:, 2].min() * 1000:.2f} mm; wrote {series.xdmf_path}")
