"""Command line: ``python -m snede demo [options] [PETSc options]``.

Options snede does not know and that start with '-' are left to PETSc, which has already
read them from sys.argv when snede was imported.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m snede",
        description="snede: soft deformable objects whose meshes change. Unknown options "
                    "starting with '-' are passed to PETSc (e.g. -log_view).")
    commands = parser.add_subparsers(dest="command", required=True)
    demo = commands.add_parser("demo", help="build meshes, cut a box in two, write a ParaView file")
    demo.add_argument("--divisions", type=int, default=20,
                      help="the box has divisions^3 cubes of 6 tetrahedra each (default 20)")
    demo.add_argument("--out", type=Path, default=Path("out/demo"), help="output folder (default out/demo)")
    return parser


def main(argv: list[str] | None = None) -> int:
    args, unknown = _parser().parse_known_args(argv)
    # PETSc options are '-name' optionally followed by a value ('-ksp_rtol 1e-8').
    not_petsc = [a for i, a in enumerate(unknown)
                 if not a.startswith("-") and (i == 0 or not unknown[i - 1].startswith("-"))]
    if not_petsc:
        _parser().error(f"unexpected argument(s): {' '.join(not_petsc)}")
    if args.command == "demo":
        if args.divisions < 2:
            _parser().error(f"--divisions must be at least 2, got {args.divisions}")
        from snede import demo

        return demo.run(args.divisions, args.out)
    return 1


if __name__ == "__main__":
    sys.exit(main())
