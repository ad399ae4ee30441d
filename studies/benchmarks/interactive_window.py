"""Benchmark: the live window's frame rate on the cut scene beside the solver's rate (issue 37).

    xvfb-run -a .venv/bin/python studies/benchmarks/interactive_window.py [--divisions 12 24] [--repeat 1]

For each beam (``cut --divisions n``: n × n/4 × n/4 cubes, 6 tetrahedra each) the same scripted
drag as the tests' (tests/python/interactive/tool_scripts.py: the scalpel from a centimetre above
the sagging beam's top at x = 5.6 cm down 70 % of its height) is played twice: headless through a
``ToolSession`` (the moves alone) and in the window (``snede.app.interactive.window``: pyvista under
whatever display there is, Xvfb with Mesa's software renderer in CI), which renders while the
worker thread cuts and relaxes. Columns: cells; moves of the blade; the solver's rate (relaxations
per second of solve time) and the headless session's (moves per second of wall time, cuts
included); the window's frame rate over the session (frames / wall time from the first event to
the last relaxation) and the frames drawn during the solves. Wall-clock times on a shared machine:
compare rows of one run.
"""
import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "python" / "interactive"))

from snede.app.interactive import ToolSession  # noqa: E402
from snede.app.interactive.events import events  # noqa: E402
from tool_scripts import cut_events  # noqa: E402


def headless(divisions: int) -> dict:
    session = ToolSession("cut", {"divisions": divisions})
    scripted = events(cut_events(session))
    start = time.perf_counter()
    relaxations = [r for event in scripted for r in session.handle(event)]
    wall = time.perf_counter() - start
    solve = sum(r.seconds for r in relaxations)
    return {"cells": session.body.mesh.n_cells, "moves": len(relaxations),
            "solve_hz": len(relaxations) / solve, "session_hz": len(relaxations) / wall}


def windowed(divisions: int) -> dict:
    from snede.app.interactive.window import Window

    make = lambda: ToolSession("cut", {"divisions": divisions})  # noqa: E731
    scripted = events(cut_events(make()))
    frames = []
    window = Window(make)
    window.run(scripted, close=True, tick=lambda: frames.append(time.perf_counter()))
    start = window.start + scripted[0].t
    shown = [t for t in frames if t >= start]
    return {"frame_hz": (len(shown) - 1) / (shown[-1] - shown[0]) if len(shown) > 1 else 0.0,
            "window_solve_hz": window.worker.relaxations / window.worker.solve_seconds}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--divisions", type=int, nargs="+", default=[12, 24])
    parser.add_argument("--repeat", type=int, default=1, help="runs per beam; the best of each column is shown")
    args = parser.parse_args()
    print(f"{'divisions':>9} {'cells':>6} {'moves':>5} | {'solves/s':>8} {'moves/s':>8} | {'frames/s':>8} "
          f"{'solves/s in window':>18}")
    for n in args.divisions:
        runs = [{**headless(n), **windowed(n)} for _ in range(args.repeat)]
        best = {key: max(r[key] for r in runs) for key in runs[0]}
        print(f"{n:>9} {best['cells']:>6} {best['moves']:>5} | {best['solve_hz']:>8.1f} {best['session_hz']:>8.1f} | "
              f"{best['frame_hz']:>8.1f} {best['window_solve_hz']:>18.1f}", flush=True)


if __name__ == "__main__":
    main()
