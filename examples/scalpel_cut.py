"""A user scene with a scalpel (§3.2): a soft block, clamped at one end and stretched by a pull
on the other, is cut from its side by a vertical blade moved in steps; the block relaxes (a
static solve) after each step, and the cut opens like a mouth, wider the deeper it goes.

Run it with `python -m snede run examples/scalpel_cut.py`; it prints what each move of the
scalpel did (a CutResult) and how each solve ended, and writes out/scalpel_cut/ (with --out DIR,
DIR/scalpel_cut/): the XDMF series (a new mesh after each move that cut; the point field
`incision` is 1 on the lips) and a picture with the incision in red.
"""
import numpy as np

import snede
from snede.output import SeriesWriter
from snede.app.plotting import plot_body

# 1. A 10 × 4 × 2 cm block of 5 mm Kuhn-split cubes, neo-Hookean (E = 30 kPa, ν = 0.3),
#    clamped at x = 0 and pulled along +x by 3 N spread over the end x = 10 cm.
mesh = snede.meshing.box((0.10, 0.04, 0.02), (20, 8, 4))
body = snede.Body(mesh, snede.NeoHookean(E=3e4, nu=0.3), density=1000.0)
body.fix(np.isclose(mesh.points[:, 0], 0.0))
end = np.flatnonzero(np.isclose(mesh.points[:, 0], 0.10))
body.add_nodal_force(end, (3.0 / len(end), 0.0, 0.0))

solver = snede.StaticSolver(body, "newton", rtol=1e-8)
folder = snede.output_folder("scalpel_cut")  # out/scalpel_cut, or --out DIR/scalpel_cut
series = SeriesWriter(folder / "scalpel_cut")
series.write(body, time=0.0)
print("stretched:", solver.solve())
series.write(body, time=1.0)

# 2. The scalpel is a segment given in DEFORMED coordinates (where the user sees the body): a
#    vertical blade, taller than the block, across the material plane X = 5.15 cm (which the
#    stretch has moved), entering at the side y = 0 and going 6 of the 8 cubes deep in steps of
#    3.6 mm.
middle = np.isclose(mesh.points[:, 0], 0.05)
x = 0.0515 + body.displacement[middle, 0].mean()
path = [[(x, y, -0.01), (x, y, 0.03)] for y in np.linspace(-0.005, 0.024, 9)]

# 3. Cut and relax in turn. The first move only places the scalpel; each later one cuts along
#    the quadrilateral swept since the previous position. The same solver continues on the cut
#    mesh from the state the body carried across the cut.
cutter = snede.TetrahedralCutter(body)
cutter.move(path[0])
total = snede.CutResult()
for step, scalpel in enumerate(path[1:], start=1):
    report = cutter.move(scalpel)
    total = total + report
    result = solver.solve()
    print(f"move {step}, blade at y = {scalpel[0][1] * 1e3:4.1f} mm: {report}")
    print(f"    relaxed: {result}")
    lips = np.zeros(mesh.n_points)
    lips[cutter.incision_faces()] = 1.0
    series.write(body, time=1.0 + step, point_fields={"incision": lips})

# 4. How far the cut opened: at its mouth (the side y = 0) the two lips, made from the same
#    vertices, have moved apart along the pull.
faces = cutter.incision_faces()
deformed = mesh.points + body.displacement
mouth = np.unique(faces)[np.isclose(mesh.points[np.unique(faces), 1], 0.0)]
print(f"all moves: {total}")
print(f"incision: {len(faces)} boundary faces; the mouth is {np.ptp(deformed[mouth, 0]) * 1e3:.1f} mm wide")
plot_body(body, folder / "scalpel_cut.png", title="stretched block cut from the side",
          highlight=faces, reference=False, view=(50, -75))
print(f"wrote {series.xdmf_path} ({series.n_steps} steps, {series.n_meshes} meshes)")
