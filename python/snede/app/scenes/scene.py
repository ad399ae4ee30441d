"""The scene a built-in scene module (or a scene file) builds and ``run_scene.run`` runs, the
parameters a built-in scene is built with, and the helpers the scene modules share: materials by
their command-line names, progress lines and summary entries of scenes that solve many times."""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Callable

import snede

MATERIAL_NAMES = ("linear", "stvk", "neohookean", "veronda")


@dataclass(frozen=True)
class Parameters:
    """What a built-in scene is built with (``build(parameters)``): the command line's
    ``--material``, ``--divisions``, ``--speed``, ``--mesh-size`` and ``--formulation``, None
    where not given (the scene's default). A scene module's ``OPTIONS`` names the ones besides
    the material it uses; the command line refuses the others."""

    material: str | None = None
    divisions: int | None = None
    speed: float | None = None
    mesh_size: float | None = None
    formulation: str | None = None

    @classmethod
    def of(cls, options) -> "Parameters":
        """From the command line's ``argparse.Namespace`` (or a dict of options, as a session
        takes them): the values it has of the fields, None for the others."""
        get = options.get if isinstance(options, dict) else lambda name: getattr(options, name, None)
        return cls(**{f.name: get(f.name) for f in fields(cls)})


@dataclass
class Scene:
    name: str
    description: str
    body: "snede.Body"
    default_method: str
    probe_name: str  # what `probe` measures, with its unit
    probe: Callable[["snede.Body"], float]
    analytic: float | None = None  # the probe's analytic value, where one exists
    damping: float = 20.0  # η for dynamic relaxation (1/s)
    plot_scale: float = 1.0  # displacement exaggeration in the picture (stated in its title)
    details: dict = field(default_factory=dict)
    default_rtol: float = 1e-6
    # A scene that is not one static solve (the needle insertion) runs itself:
    # evolve(method, rtol, writer, folder, progress) -> summary entries (see run_scene.solve_once).
    evolve: Callable | None = None
    decorate: Callable | None = None  # decorate(ax): marks on the 2D picture
    picture: Callable | None = None  # picture() -> more keyword arguments of plotting.plot_body, after the run
    # fixed(points) -> (n_points,) bool: the vertices the scene holds (of the mesh after the
    # run), marked on the picture; the scene's loads are drawn from the body.
    fixed: Callable | None = None
    # Keyword arguments of the scene's static solver (snede.StaticSolver: preconditioner,
    # petsc_options, max_iterations); petsc_options and max_iterations also reach dynamic relaxation.
    solver_options: dict = field(default_factory=dict)
    # The methods the scene runs with (None: every static method and "dynamic"), and why it
    # refuses the others (a clause for the message).
    methods: tuple | None = None
    methods_note: str = ""

    def require_method(self, method: str) -> None:
        """ValueError naming the scene's methods when it does not run with ``method``."""
        if self.methods is not None and method not in self.methods:
            raise ValueError(f"the {self.name} scene solves with {', '.join(self.methods)}{self.methods_note}; "
                             f"got {method!r}")


def material(name: str, young: float, poisson: float, gamma: float = 8.0):
    """A material by its command-line name."""
    makers = {
        "linear": lambda: snede.LinearElastic(young, poisson),
        "stvk": lambda: snede.StVenantKirchhoff(young, poisson),
        "neohookean": lambda: snede.NeoHookean(young, poisson),
        "veronda": lambda: snede.VerondaWestmann(young, poisson, gamma),
    }
    if name not in makers:
        raise ValueError(f"unknown material {name!r}: choose one of {', '.join(MATERIAL_NAMES)}")
    return makers[name]()


def divisions(parameters: Parameters, default: int, multiple_of: int, rule: str) -> int:
    """The scene's ``--divisions`` (``default`` when not given), checked: positive, and a
    multiple of ``multiple_of``, else ValueError with ``rule`` (what it must be, and why)."""
    n = default if parameters.divisions is None else parameters.divisions
    if n <= 0:
        raise ValueError(f"--divisions must be positive, got {n}")
    if n % multiple_of:
        raise ValueError(f"--divisions {rule}, got {n}")
    return n


def briefly(result) -> str:
    """The start of ``str(result)``, for a line of a scene's progress: converged or not,
    PETSc's reason, iterations and the time."""
    state = "converged" if result.converged else "NOT converged"
    return f"{state} ({result.reason}) after {result.iterations} iterations, {result.seconds:.2f} s"


def shaft_force(needle) -> float:
    """The force a ``snede.NeedleInsertion`` exerts on the body along its shaft (N): the needle scenes' probe."""
    return float((needle.needle_forces() @ needle.direction).sum())


def solve_entries(results) -> dict:
    """Summary entries (those of ``run_scene.solve_once``) of a scene that solves many times:
    converged only if every solve did, with the first failure's reason (else the last solve's);
    iterations, solve seconds and MFLOP summed; the last residual norm."""
    failed = [r for r in results if not r.converged]
    return {
        "converged": not failed, "reason": (failed[0] if failed else results[-1]).reason,
        "iterations": sum(r.iterations for r in results),
        "linear_iterations": sum(r.linear_iterations for r in results),
        "residual_norm": results[-1].residual_norm,
        "seconds": sum(r.seconds for r in results), "mflop": sum(r.flops for r in results) / 1e6,
        "solves": len(results),
    }
