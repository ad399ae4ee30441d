"""Benchmark: Table 6.5 — update rates of an automated needle insertion (§6.8.5).

    .venv/bin/python benchmarks/needle_rates.py [--quick] [--rtol 1e-3] [--method cg|ncg|newton]
                                                [--loop thesis|settle] [PETSc options, e.g. -log_view]

The §6.8.1 slab (h_start = h3, scenes/needle_slab.py) with the needle inserted to 70 mm at
3, 1, 0.3, 0.1, 0.03 and 0.01 h_ref per update, for h_ref = h6 and h7 (--quick: h6 at 3, 1
and 0.3). ``--loop thesis`` (default) is the thesis's interaction loop: one solve and one
rearrangement per update, pending rearrangements carried into the next update, and at 70 mm
updates in place until no node changes state (NeedleInsertion(solves_per_update=1)); ``settle``
relaxes and rearranges every update until nothing changes. CPU seconds are this process's
time over the whole insertion (time.process_time); rearrangements are solves; the update rate
is rearrangements per CPU second; CG iterations are per solve (Newton: outer + inner CG).
Next to each row: the thesis's numbers (Pentium III, 1 GHz) and the ratio of update rates.
The relaxation tolerance ε of (6.9) is 1e-3 unless --rtol says otherwise (the thesis does not
state the ε of Table 6.5; at 1e-3 Table 6.1 gives errors of 0.001 mm).

Then one row (h6, 0.1 h_ref per update) again with PETSc's event log, to show where the time
goes: the solver (KSPSolve or SNESSolve) and the tangent products inside it, the rest of each
update (refinement, interception, thresholds, rearrangement, evaluations outside the solver),
and Python between updates.
"""
import argparse
import time

import snede
from snede import PETSc
from snede.scenes.needle_slab import DEPTH, h, needle_for, slab_body

SPEEDS = (3.0, 1.0, 0.3, 0.1, 0.03, 0.01)
# Table 6.5: h_ref → speed → (CPU s, rearrangements, updates [Hz], CG iterations mean, max).
THESIS = {
    6: {3.0: (0.80, 157, 196.25, 11.81, 41), 1.0: (0.90, 232, 257.78, 11.52, 62), 0.3: (0.94, 308, 327.66, 10.87, 70),
        0.1: (1.07, 504, 471.03, 8.14, 61), 0.03: (2.24, 1478, 659.82, 5.31, 57), 0.01: (5.77, 4187, 725.65, 3.87, 51)},
    7: {3.0: (2.46, 243, 98.78, 12.67, 57), 1.0: (2.80, 401, 143.21, 10.88, 82), 0.3: (3.15, 561, 178.10, 10.03, 66),
        0.1: (3.48, 1000, 287.36, 6.63, 67), 0.03: (6.34, 2966, 467.82, 4.18, 53), 0.01: (15.68, 8505, 542.41, 3.15, 48)},
}


def insert(h_ref, speed, args):
    """One automated insertion; (InsertionReport, CPU seconds, wall seconds, final cells)."""
    body = slab_body(3)
    needle = needle_for(body, h_ref, method=args.method, rtol=args.rtol,
                        solves_per_update=1 if args.loop == "thesis" else None)
    cpu, wall = time.process_time(), time.perf_counter()
    report = needle.insert(DEPTH, speed * h(h_ref))
    return report, time.process_time() - cpu, time.perf_counter() - wall, body.mesh.n_cells


def row(h_ref, speed, args):
    report, cpu, _, cells = insert(h_ref, speed, args)
    rate = report.rearrangements / cpu
    t_cpu, t_rearrangements, t_rate, t_mean, t_max = THESIS[h_ref][speed]
    state = "" if report.converged else f"  NOT converged: {report.reason}"
    print(f"h{h_ref:<5} {speed:>5.2f} {report.updates:>7} {cells:>6} {cpu:>7.2f} {report.rearrangements:>7} {rate:>7.0f} "
          f"{report.mean_iterations:>7.2f} {report.max_iterations:>6} | {t_cpu:>6.2f} {t_rearrangements:>7} "
          f"{t_rate:>7.1f} {t_mean:>7.2f} {t_max:>6} | {rate / t_rate:>6.2f}{state}", flush=True)


def event_seconds(name: str) -> float:
    return PETSc.Log.Event(name).getPerfInfo()["time"]


def phases(args, h_ref=6, speed=0.1):
    PETSc.Log.begin()  # PETSc's default event log (what -log_view prints); from here on
    before = {name: event_seconds(name) for name in ("KSPSolve", "SNESSolve", "SnedeTangentApply", "SnedeForces",
                                                     "SnedeEnergy")}
    report, cpu, wall, _ = insert(h_ref, speed, args)
    spent = {name: event_seconds(name) - seconds for name, seconds in before.items()}
    solver = spent["KSPSolve"] + spent["SNESSolve"]
    solver_name = "KSPSolve" if spent["KSPSolve"] else "SNESSolve"
    lines = [
        ("insertion, wall clock", wall),
        ("  updates in the engine (sum of NeedleStepReport.seconds)", report.seconds),
        (f"    solver ({solver_name})", solver),
        ("      tangent products (SnedeTangentApply, matrix-free)", spent["SnedeTangentApply"]),
        ("    rest: refinement, interception, thresholds, rearrangement, evaluations", report.seconds - solver),
        ("  Python between updates", wall - report.seconds),
        ("force evaluations (SnedeForces; inside and outside the solver)", spent["SnedeForces"]),
        ("energy evaluations (SnedeEnergy; inside and outside the solver)", spent["SnedeEnergy"]),
    ]
    print(f"\nwhere the time goes: h_ref = h{h_ref}, {speed} h_ref per update, {report.updates} updates, "
          f"{report.rearrangements} solves, CPU {cpu:.2f} s")
    print(f"{'phase':<72} {'s':>7} {'% wall':>7} {'µs/solve':>9}")
    for name, seconds in lines:
        print(f"{name:<72} {seconds:>7.3f} {100 * seconds / wall:>7.1f} {1e6 * seconds / report.rearrangements:>9.1f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="h_ref = h6 at 3, 1, 0.3 h_ref per update only")
    parser.add_argument("--rtol", type=float, default=1e-3, help="relaxation tolerance ε of (6.9) (default 1e-3)")
    parser.add_argument("--method", choices=("cg", "ncg", "newton"), default="cg", help="static solver (default cg)")
    parser.add_argument("--loop", choices=("thesis", "settle"), default="thesis",
                        help="thesis: one solve per update (§6.7); settle: relax until no node changes (default thesis)")
    args, _ = parser.parse_known_args()  # the rest is PETSc's (-log_view)
    print(f"snede {snede.__version__}: needle insertion to {DEPTH * 1e3:.0f} mm, h_start = h3, {args.method}, "
          f"ε = {args.rtol:g}, loop: {args.loop}")
    print(f"{'':>6} {'speed':>5} {'updates':>7} {'cells':>6} {'CPU s':>7} {'rearr.':>7} {'Hz':>7} {'CG avg':>7} "
          f"{'max':>6} | {'thesis':>6} {'rearr.':>7} {'Hz':>7} {'CG avg':>7} {'max':>6} | {'Hz/th.':>6}")
    for h_ref in (6,) if args.quick else (6, 7):
        for speed in SPEEDS[:3] if args.quick else SPEEDS:
            row(h_ref, speed, args)
    phases(args)


if __name__ == "__main__":
    main()
