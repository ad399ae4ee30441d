"""Command line: ``python -m snede run SCENE [options] [PETSc options]``, ``list``, ``demo``.

Options snede does not know and that start with '-' are PETSc's (``-static_snes_monitor``,
``-log_view``); PETSc read them from sys.argv when snede was imported.
"""
from __future__ import annotations

import argparse
import logging
import runpy
import sys
from pathlib import Path

METHODS = ("cg", "ncg", "newton", "dynamic")


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0 or value != value or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be positive and finite, got {text}")
    return value


def _parser() -> argparse.ArgumentParser:
    from snede.scenes import MATERIAL_NAMES

    parser = argparse.ArgumentParser(
        prog="python -m snede",
        description="snede: soft deformable objects whose meshes change. Options starting with '-' that snede "
                    "does not know are passed to PETSc (e.g. -static_snes_monitor, -log_view).")
    parser.add_argument("--quiet", action="store_true", help="only warnings and the final table")
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("list", help="list the built-in scenes")
    run = commands.add_parser("run", help="run a built-in scene, or a scene script (a .py file)")
    run.add_argument("scene", help="cantilever, cylinder, slab, needle, or path/to/scene.py")
    run.add_argument("--material", choices=MATERIAL_NAMES, help="material model (default: the scene's)")
    run.add_argument("--method", choices=METHODS,
                     help="cg: linear CG (linear material); ncg: nonlinear CG; newton: truncated Newton; "
                          "dynamic: damped explicit dynamics (default: the scene's)")
    run.add_argument("--rtol", type=_positive_float,
                     help="relaxation tolerance ε of the stopping criterion (6.9) (default 1e-6; needle: 1e-3)")
    run.add_argument("--divisions", type=int,
                     help="structured mesh resolution (cantilever: n × n/4 × n/4; slab: n × n; needle: n × n, n a power of 2)")
    run.add_argument("--speed", type=_positive_float,
                     help="needle: insertion speed, in h_ref per update (default 0.1)")
    run.add_argument("--mesh-size", type=_positive_float, help="target edge length (m) for gmsh meshes (cylinder)")
    run.add_argument("--out", type=Path, default=Path("out"), help="output folder (default out/)")
    demo = commands.add_parser("demo", help="run the default scenes and the cutting demo")
    demo.add_argument("--out", type=Path, default=Path("out"), help="output folder (default out/)")
    return parser


def _split_petsc(unknown: list[str]) -> list[str]:
    """The tokens that are not PETSc options ('-name' optionally followed by a value)."""
    return [a for i, a in enumerate(unknown)
            if not a.startswith("-") and (i == 0 or not unknown[i - 1].startswith("-"))]


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args, unknown = parser.parse_known_args(argv)
    stray = _split_petsc(unknown)
    if stray:
        parser.error(f"unexpected argument(s): {' '.join(stray)}")
    handler = logging.StreamHandler()
    handler.setFormatter(logging.Formatter("%(levelname)s: %(message)s"))
    logger = logging.getLogger("snede")
    logger.addHandler(handler)
    logger.setLevel(logging.WARNING if args.quiet else logging.INFO)
    import snede  # noqa: F401  (initialises PETSc with sys.argv)
    from snede import run_scene
    from snede.scenes import builders

    try:
        if args.command == "list":
            for name, module in builders().items():
                print(f"{name:<11} {module.DESCRIPTION}")
            return 0
        if args.command == "demo":
            from snede import demo

            return demo.run(args.out, progress=not args.quiet)
        if args.scene.endswith(".py"):
            script = Path(args.scene)
            if not script.exists():
                parser.error(f"scene script {script} does not exist")
            sys.argv = [str(script), *unknown]
            runpy.run_path(str(script), run_name="__main__")
            return 0
        scenes = builders()
        if args.scene not in scenes:
            parser.error(f"unknown scene {args.scene!r}: choose one of {', '.join(scenes)}, or give a .py file")
        scene = scenes[args.scene].build(args)
        summary = run_scene.run(scene, args.method, args.rtol, args.out, progress=not args.quiet)
        run_scene.print_table([summary])
        return 0 if summary["converged"] else 1
    except (ValueError, OSError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
