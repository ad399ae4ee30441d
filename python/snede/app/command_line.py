"""Command line: ``python -m snede run SCENE [options] [PETSc options]``, ``list``, ``demo``.

Options starting with ``--`` are snede's: one snede does not know is an error (a script run by
``run path/to/scene.py`` gets the ones snede does not know, as its own arguments). Options
starting with a single ``-`` (and their values) are PETSc's (``-static_snes_monitor``,
``-log_view``): PETSc read them, and only them, from sys.argv when snede was imported (see
``snede._argv``). Before a built-in scene runs, a value PETSc refuses is an error, whether or
not the scene's solver reads the option; at the end, the options nothing read are reported,
as PETSc's ``-options_left`` does. A scene file (``run path/to/scene.toml``, ``snede.app.scene_file``)
runs as a built-in scene does; a script gets ``--out`` through ``snede.output_folder``.

Bad input gives one line, ``python -m snede: error: ...``, and exit status 2 (under mpirun,
from rank 0 alone when every rank finds it); Ctrl-C one line and status 130; a solve that did
not converge status 1 (see ``snede._command_line``).

``-h``/``--help`` is snede's help; ``-help`` is PETSc's: PETSc prints its options as the
solvers are set up (with ``run SCENE``, the scene runs); without a command, snede's help
follows PETSc's general one.
"""
from __future__ import annotations

import argparse
import logging
import os
import runpy
import sys
import traceback
from functools import partial
from pathlib import Path

from snede import _command_line
from snede import _output_folder as output_folder
from snede import static
from snede.app._extras import MissingExtra

METHODS = (*static.METHODS, "dynamic")  # the engine's static methods, then dynamic relaxation
SCENE_OPTIONS = ("divisions", "mesh_size", "speed", "formulation")  # apply to the scenes whose OPTIONS name them


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0 or value != value or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be positive and finite, got {text}")
    return value


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text}")
    return value


class _ArgumentParser(argparse.ArgumentParser):
    """argparse, with its errors on the command line's one line (no usage: --help has it)."""

    def error(self, message):
        _command_line.fail(message)


def _parser() -> argparse.ArgumentParser:
    from snede.app.scenes import MATERIAL_NAMES

    parser = _ArgumentParser(
        prog="python -m snede",
        description="snede: soft deformable objects whose meshes change. Options starting with '--' are snede's; "
                    "options starting with a single '-' are passed to PETSc (e.g. -static_snes_monitor, -log_view; "
                    "-help: PETSc's help, printed as the solvers are set up).")
    quiet = "only warnings and the final table"
    parser.add_argument("--quiet", action="store_true", help=quiet)
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("list", help="list the built-in scenes")
    run = commands.add_parser("run", help="run a built-in scene, a scene file (.toml) or a scene script (.py)",
                              description="Run a built-in scene, a scene file (.toml: docs/guide/meshes_and_scenes.md) "
                                          "or a scene script (a .py file: it gets the "
                                          "arguments snede does not know). Options starting with a single '-' "
                                          "are PETSc's (e.g. -static_snes_monitor; -help lists the solvers' "
                                          "options as they are set up).")
    # SUPPRESS: `--quiet run ...` is not undone by the subcommand's default
    run.add_argument("--quiet", action="store_true", default=argparse.SUPPRESS, help=quiet)
    run.add_argument("scene", help="cantilever, cylinder, slab, needle, needle3d, cut, sheet-cut, membrane-cut, "
                                      "path/to/scene.toml or path/to/scene.py")
    run.add_argument("--material", choices=MATERIAL_NAMES, help="material model (default: the scene's)")
    run.add_argument("--formulation", choices=("p1", "smoothed"),
                     help="p1: the thesis's linear simplex; smoothed: strains averaged over patches, free of "
                          "volumetric locking (docs/results/locking.md); tetrahedra and plane triangles (default: "
                          "the scene's)")
    run.add_argument("--method", choices=METHODS,
                     help="cg: linear CG (linear material); ncg: nonlinear CG; newton: truncated Newton; "
                          "dynamic: damped explicit dynamics (default: the scene's)")
    run.add_argument("--rtol", type=_positive_float,
                     help="relaxation tolerance ε of the stopping criterion (6.9) (default 1e-6; needle: 1e-3)")
    run.add_argument("--divisions", type=_positive_int,
                     help="structured mesh resolution (cantilever, cut: n × n/4 × n/4; slab: n × n; "
                          "needle: n × n, n a power of 2; sheet-cut: n × 3n/5; membrane-cut: the bell's n × n)")
    run.add_argument("--speed", type=_positive_float,
                     help="needle: insertion speed, in h_ref per update (default 0.1)")
    run.add_argument("--mesh-size", type=_positive_float, help="target edge length (m) for gmsh meshes (cylinder)")
    run.add_argument("--out", type=Path, default=Path("out"),
                     help="output folder (default out/); a scene script finds it as snede.output_folder(name)")
    demo = commands.add_parser("demo", help="run the default scenes and the cutting demo")
    demo.add_argument("--quiet", action="store_true", default=argparse.SUPPRESS, help=quiet)
    demo.add_argument("--out", type=Path, default=Path("out"), help="output folder (default out/)")
    view = commands.add_parser("view", help="the live window: the mouse drives the scene's tool (snede.app.interactive)",
                               description="The live window (pyvista): the mouse drives the scalpel (cut) or the "
                                           "needle (needle) while the body relaxes. Keys: s scalpel, n needle, "
                                           "p pause, r reset, c screenshot, w write the series, q quit.")
    view.add_argument("scene", help="cut, needle, needle3d or a scene file (.toml) with a [[tool]] table")
    view.add_argument("--material", choices=MATERIAL_NAMES, help="material model (default: the scene's)")
    view.add_argument("--divisions", type=_positive_int, help="the scene's mesh resolution (as for run)")
    view.add_argument("--speed", type=_positive_float, help="needle: h_ref per update (as for run)")
    view.add_argument("--events", type=Path, help="play pointer events (JSON) as if from the mouse")
    view.add_argument("--screenshot", type=Path, help="save the last frame (PNG)")
    view.add_argument("--exit", action="store_true", help="close once the events are played and the body relaxed")
    view.add_argument("--record", type=Path, help="write the session's recording (JSON, for replay) at the end")
    replay = commands.add_parser("replay", help="replay a recorded tool session headless (snede.app.interactive)")
    replay.add_argument("recording", type=Path, help="the recording (JSON, from `view --record`)")
    replay.add_argument("--check", action="store_true",
                        help="exit 0 only if the final mesh and displacement match the recording's digest "
                             "(cells exactly, floats to about the recorded rtol)")
    replay.add_argument("--out", type=Path, help="write the series and a picture to OUT/SCENE/")
    return parser


def _check_scene_options(parser, args, module) -> None:
    """An option of SCENE_OPTIONS given to a scene that does not use it is an error."""
    for name in SCENE_OPTIONS:
        if getattr(args, name, None) is not None and name not in module.OPTIONS:
            own = ", ".join("--" + o.replace("_", "-") for o in module.OPTIONS) or "none"
            parser.error(f"--{name.replace('_', '-')} does not apply to the {args.scene} scene "
                         f"(its options: {own})")


def _warn_unused(logger) -> None:
    from snede._petsc import unused_options

    for name, value in unused_options():
        logger.warning("PETSc option -%s%s was not used (misspelled, or not for this scene's solver?)",
                       name, "" if value is None else f" {value}")


def main(argv: list[str] | None = None) -> int:
    from snede._argv import split

    parser = _parser()
    ours, petsc = split(sys.argv[1:] if argv is None else list(argv))
    if "-help" in petsc and not any(command in ours for command in ("list", "run", "demo", "replay", "view")):
        parser.print_help()  # PETSc printed its general help at initialisation
        print("\nPETSc's options of a scene's solvers: python -m snede run SCENE -help")
        return 0
    args, unknown = parser.parse_known_args(ours)
    script = args.command == "run" and args.scene.endswith(".py")
    if unknown and not script:
        options = [a.split("=", 1)[0] for a in unknown if a.startswith("-")]
        if options:
            parser.error(f"unknown option(s): {' '.join(options)} (snede's options start with '--', "
                         "PETSc's with a single '-'; see --help)")
        parser.error(f"unexpected argument(s): {' '.join(unknown)}")
    handler = logging.StreamHandler()
    handler.setFormatter(logging.Formatter("%(levelname)s: %(message)s"))
    logger = logging.getLogger("snede")
    logger.addHandler(handler)
    logger.setLevel(logging.WARNING if args.quiet else logging.INFO)
    import snede  # (initialised PETSc with the PETSc options of sys.argv)

    # Until here Ctrl-C ended the process at once (nothing written yet); now solves stop
    # between iterations (engine/core/interrupt.hpp) and the files written so far are closed.
    _command_line.on_ctrl_c(_command_line.raise_keyboard_interrupt)
    try:
        code = _command(parser, args, unknown, petsc)
        if args.command != "list":
            _warn_unused(logger)
    except (snede.PetscError, ValueError, OSError, MissingExtra) as error:  # bad input, maybe on this rank alone
        print(_command_line.error_line(error), file=sys.stderr)
        return _command_line.BAD_INPUT
    except KeyboardInterrupt:
        where = f" (the files written so far in {args.out} are complete up to the last step)" \
            if args.command in ("run", "demo") else ""
        print(f"interrupted{where}", file=sys.stderr)
        return _command_line.INTERRUPTED
    return code


def _command(parser, args, unknown, petsc) -> int:
    from snede.app import run_scene, scene_file
    from snede._petsc import OptionValueError, check_option_values
    from snede.app.scenes import Parameters, builders

    if args.command == "list":
        for name, module in builders().items():
            print(f"{name:<11} {module.DESCRIPTION}")
        return 0
    if args.command == "demo":
        from snede.app import demo

        return demo.run(args.out, progress=not args.quiet)
    if args.command == "replay":
        return _replay(args)
    if args.command == "view":
        return _view(args)
    if args.scene.endswith(".py"):
        script = Path(args.scene)
        if not script.exists():
            parser.error(f"scene script {script} does not exist")
        sys.argv = [str(script), *unknown, *petsc]
        os.environ[output_folder.VARIABLE] = str(args.out)  # snede.output_folder(name) is args.out / name
        runpy.run_path(str(script), run_name="__main__")
        return 0
    scenes = builders()
    if args.scene.endswith(scene_file.SUFFIX):
        module, build = scene_file, lambda: scene_file.load(args.scene, args.material, args.formulation)
    elif args.scene in scenes:
        module = scenes[args.scene]
        build = partial(module.build, Parameters.of(args))
    else:
        parser.error(f"unknown scene {args.scene!r}: choose one of {', '.join(scenes)}, or give a .py or "
                     f"{scene_file.SUFFIX} file")
    _check_scene_options(parser, args, module)
    try:
        check_option_values()
        scene = build()
        summary = run_scene.run(scene, args.method, args.rtol, args.out, progress=not args.quiet)
    except (OptionValueError, run_scene.SerialOnly, scene_file.SceneFileError) as error:  # the same on every rank
        _command_line.fail(error)
    if summary.get("rank", 0) == 0:  # on several MPI ranks, rank 0 reports
        run_scene.print_table([summary])
    return 0 if summary["converged"] else 1


def _view(args) -> int:
    from snede.app.interactive import events
    from snede.app.interactive.recording import save
    from snede.app.interactive.session import ToolSession
    from snede.app.interactive.window import Window, display_answers

    display = os.environ.get("DISPLAY")
    if sys.platform.startswith("linux") and not (display or os.environ.get("WAYLAND_DISPLAY")):
        _command_line.fail("view needs a display: none is set (DISPLAY); without one, run it under xvfb-run")
    if sys.platform.startswith("linux") and display and not display_answers(display):
        _command_line.fail(f"view needs a display: DISPLAY={display} does not answer (no X server there, or it "
                           "refuses this user); without one, run it under xvfb-run")
    played = events.load(args.events) if args.events else []
    options = {name: getattr(args, name) for name in ("divisions", "material", "speed") if getattr(args, name)}
    window = Window(partial(ToolSession, args.scene, options))
    tool = window.worker.session.tool.name
    for index, event in enumerate(played):
        if event.tool != tool:
            raise ValueError(f"events file {args.events}: event {index}: 'tool' is {event.tool}, but the "
                             f"{args.scene} scene's tool is the {tool}")
    try:
        window.run(played, args.screenshot, close=args.exit)
    except _mismatched_interactor() as error:  # VTK could not draw on the display (no GLX?) and went off-screen
        _command_line.fail(f"view cannot open its window on DISPLAY={display}: {str(error).split('. ')[0]}")
    session = window.worker.session
    if args.record:
        save(session.recording(), args.record)
    print(f"view: {len(session.moves)} moves on the {args.scene} scene, {window.frames} frames"
          + (f"; recorded to {args.record}" if args.record else "")
          + (f"; screenshot {args.screenshot}" if args.screenshot else ""))
    if window.worker.error:
        print(_command_line.error_line(window.worker.error), file=sys.stderr)
        return _command_line.BAD_INPUT
    return 0


def _mismatched_interactor() -> tuple:
    """pyvista's error for an interactor without its X window (none in older pyvista)."""
    from pyvista.plotting import errors

    return tuple(filter(None, [getattr(errors, "MismatchedInteractorError", None)]))


def _replay(args) -> int:
    from snede.app.interactive import replay

    result = replay(args.recording, args.out)
    state = "matches" if result.matches else "does NOT match"
    print(f"replayed {result.moves} moves of the {result.scene} scene: the final state {state} the recording's digest"
          + "".join(f"; wrote {path}" for path in result.files.values()))
    if args.check and not result.matches:
        for line in result.mismatches:
            print(f"replay --check: {line}", file=sys.stderr)
        return 1
    return 0


def run() -> None:
    """``python -m snede``: ``main()``, then the exit status, ending every MPI rank if need be.
    Not converged (1, from the collective summary) and bad input every rank finds alike end
    every rank alike; an error, an interrupt or a script's sys.exit may have happened on this
    rank alone."""
    try:
        exit_code = main()
        alone = exit_code in (_command_line.BAD_INPUT, _command_line.INTERRUPTED)  # an error or Ctrl-C
    except _command_line.AlikeOnEveryRank as stop:
        exit_code, alone = stop.code, False
    except SystemExit as stop:  # sys.exit in a scene script, Ctrl-C while modules load
        exit_code = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
        if not isinstance(stop.code, (int, type(None))):
            print(stop.code, file=sys.stderr)  # as Python prints it
        alone = True
    except Exception:
        traceback.print_exc()
        exit_code, alone = 1, True
    if exit_code != 0 and alone:
        _command_line.end_every_rank(exit_code)
    sys.exit(exit_code)
