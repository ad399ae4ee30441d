"""Benchmark: matrix-free kernel throughput per material (§4.3, Table 4.3).

    .venv/bin/python studies/benchmarks/fem_throughput.py [--divisions 26 55] [--repeat 3]

For Kuhn boxes of 6n³ tetrahedra (n = 26: about 10⁵, n = 55: about 10⁶) and each material,
prints elements per second (one core, best of --repeat) for the energy, the internal forces
and the tangent action; the flops per element counted by running the kernels on a counting
scalar (next to the thesis's Table 4.3 counts for force and derivative); the MFLOP/s that
follow; and an estimate of the bytes moved per element per force evaluation (connectivity
20 B, reference data Z⁻¹ and |τ| 80 B, displacements gathered 96 B, forces scattered
2 × 96 B read and written).
"""
import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.append(str(Path(__file__).resolve().parents[2]))  # the repository root: studies.experiments

import snede
from studies.experiments.common import best_seconds

THESIS_TABLE_4_3 = {  # force, derivative flops per tetrahedron
    "LinearElastic": (129, 129),
    "StVenantKirchhoff": (235, 421),
    "NeoHookean": (277, 595),
    "VerondaWestmann": (347, 797),
}
BYTES_PER_ELEMENT = 20 + 80 + 96 + 2 * 96


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--divisions", type=int, nargs="+", default=[26, 55])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    materials = [snede.LinearElastic(3e3, 0.3), snede.StVenantKirchhoff(3e3, 0.3),
                 snede.NeoHookean(3e3, 0.3), snede.VerondaWestmann(3e3, 0.3, 2.0)]
    print(f"{'cells':>9} {'material':<18} {'energy el/s':>12} {'force el/s':>12} {'tangent el/s':>12} "
          f"{'flops F/K':>10} {'thesis F/K':>10} {'force MFLOP/s':>13} {'force GB/s est':>14}")
    for n in args.divisions:
        mesh = snede.meshing.box((0.1, 0.1, 0.1), (n, n, n))
        rng = np.random.default_rng(0)
        u = 1e-4 * rng.standard_normal((mesh.n_points, 3))
        d = rng.standard_normal(u.shape)
        for material in materials:
            body = snede.Body(mesh, material)
            name = type(material).__name__
            t_energy = best_seconds(lambda: body.energy(u), args.repeat)
            t_force = best_seconds(lambda: body.internal_forces(u), args.repeat)
            t_tangent = best_seconds(lambda: body.tangent_apply(u, d), args.repeat)
            flops = body.flops_per_element()
            rate = mesh.n_cells / t_force
            thesis = THESIS_TABLE_4_3[name]
            print(f"{mesh.n_cells:>9} {name:<18} {mesh.n_cells / t_energy:>12.3g} {rate:>12.3g} "
                  f"{mesh.n_cells / t_tangent:>12.3g} {flops['force']:>4}/{flops['tangent']:<5} "
                  f"{thesis[0]:>4}/{thesis[1]:<5} {rate * flops['force'] / 1e6:>13.0f} "
                  f"{rate * BYTES_PER_ELEMENT / 1e9:>14.2f}", flush=True)


if __name__ == "__main__":
    main()
