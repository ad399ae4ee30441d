"""A scene file read and checked, before anything is computed: the ``Recipe``. Sections:
``[mesh]``, ``[material]``, ``[[hold]]`` (at least one), ``[loads]`` (``gravity``,
``[[loads.force]]``), ``[solver]``, ``[[tool]]``; top-level ``name`` and ``description``."""
from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import snede
from snede.app.scene_file.mesh import read_mesh
from snede.app.scene_file.reading import (COUNT, POINT, POSITIVE, REFUSED, REQUIRED, TEXT, Kind, SceneFileError, Table,
                                      choice, is_number, number_kind, shown)
from snede.app.scene_file.regions import Region, read_region
from snede.app.scene_file.tools import read_tools
from snede.app.scenes.scene import MATERIAL_NAMES

SECTIONS = ("name", "description", "mesh", "material", "hold", "loads", "solver", "tool")
NEEDED = "a scene file needs [mesh], [material] and at least one [[hold]]"
METHODS = (*snede.static.METHODS, "dynamic")
POISSON = number_kind("a number in (-1, 0.5)", lambda v: -1 < v < 0.5)
NAME = Kind("a name of letters, digits, '-', '_' or '.' (the output folder's)",
            lambda v: v if isinstance(v, str) and re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]*", v) else REFUSED)


@dataclass
class Material:
    name: str
    E: float
    nu: float
    gamma: float
    density: float
    formulation: str  # snede.formulations()


@dataclass
class Solver:
    method: str | None  # None: "cg" for a linear material, else "newton"
    rtol: float
    preconditioner: str | None  # None: the solver's default ("auto")
    max_iterations: int | None  # None: the solver's default
    damping: float
    petsc: dict

    def options(self) -> dict:
        """The keyword arguments of snede.StaticSolver the file gives."""
        given = {"preconditioner": self.preconditioner, "max_iterations": self.max_iterations,
                 "petsc_options": self.petsc or None}
        return {key: value for key, value in given.items() if value is not None}


@dataclass
class Recipe:
    source: str  # the file, as named to the command line
    name: str
    description: str
    mesh: Callable  # mesh() makes it
    material: Material
    holds: list[tuple[Region, list]]  # (region, displacement)
    forces: list[tuple[Region, list]]  # (region, total force)
    gravity: list | None
    solver: Solver
    tools: list = field(default_factory=list)


def read(path) -> Recipe:
    """Read and check the scene file ``path``; a SceneFileError names what is wrong."""
    source = str(path)
    path = Path(path)
    try:
        values = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SceneFileError(f"{source}: no such scene file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise SceneFileError(f"{source}: could not be read: {error}") from None
    except tomllib.TOMLDecodeError as error:
        raise SceneFileError(f"{source}: not valid TOML: {error}") from None
    except RecursionError:  # tomllib parses nested arrays and inline tables recursively
        raise SceneFileError(f"{source}: nests arrays or tables too deeply to be read (no scene file nests more "
                             "than 3 deep)") from None
    top = Table(values, "", source)
    for section in SECTIONS:  # a misspelled section is named before one it leaves missing
        top.has(section)
    top.close()
    name = top.get("name", NAME, path.stem)
    description = top.get("description", TEXT, f"scene file {path.name}")
    mesh, max_cells = read_mesh(top.table("mesh", NEEDED), path.parent)
    material = _material(top.table("material", NEEDED))
    holds = [_region_and(t, "displacement", [0.0, 0.0, 0.0]) for t in top.tables("hold")]
    if not holds:
        raise SceneFileError(f"{source}: [[hold]] is missing: a scene needs at least one [[hold]] table (a static "
                             "solve needs the body held)")
    loads = top.table("loads") or Table({}, "loads", source)
    gravity = loads.get("gravity", POINT, None)
    forces = [_region_and(t, "force", meaning="the total force in N, shared equally by the region's vertices")
              for t in loads.tables("force")]
    loads.close()
    solver = _solver(top.table("solver") or Table({}, "solver", source), material.name)
    tools = read_tools(top.tables("tool"), solver.method, max_cells)
    if solver.method == "dynamic" and tools:
        raise SceneFileError(f'{source}: solver.method "dynamic" cannot relax the tools\' steps: take newton, '
                             "ncg or cg")
    return Recipe(source, name, description, mesh, material, holds, forces, gravity, solver, tools)


def _region_and(table: Table, key: str, default=REQUIRED, meaning: str = "") -> tuple[Region, list]:
    """The region of a ``[[hold]]`` or ``[[loads.force]]`` table and its vector ``key``."""
    region = read_region(table)
    vector = table.get(key, POINT, default, meaning)
    table.close()
    return region, vector


def _material(table: Table) -> Material:
    name = table.get("name", choice(MATERIAL_NAMES))
    young = table.get("E", POSITIVE, meaning="Young's modulus in Pa, a positive number")
    poisson = table.get("nu", POISSON, meaning="Poisson's ratio, a number in (-1, 0.5)")
    if name != "veronda" and table.has("gamma"):
        table.fail("gamma", f'is the nonlinearity of name = "veronda", not of "{name}"')
    gamma = table.get("gamma", POSITIVE, 8.0)
    density = table.get("density", POSITIVE, 1000.0)
    formulation = table.get("formulation", choice(tuple(snede.formulations())), "p1")
    table.close()
    return Material(name, young, poisson, gamma, density, formulation)


def _solver(table: Table, material: str) -> Solver:
    method = table.get("method", choice(METHODS), None)
    if method != "dynamic" and table.has("damping"):
        table.fail("damping", 'applies to method = "dynamic" only')
    if method == "dynamic" and table.has("preconditioner"):
        table.fail("preconditioner", 'applies to the static methods (cg, ncg, newton), not "dynamic"')
    if material != "linear" and method == "cg":
        table.fail("method", f'"cg" is linear CG, for name = "linear" only; the material is "{material}": take '
                             '"newton" or "ncg"')
    solver = Solver(method, table.get("rtol", POSITIVE, 1e-6), table.get("preconditioner", TEXT, None),
                    table.get("max_iterations", COUNT, None), table.get("damping", POSITIVE, 20.0),
                    _petsc(table.table("petsc")))
    table.close()
    return solver


def _petsc(table: Table | None) -> dict:
    """PETSc options without the leading '-' and the solver's prefix: ``true`` a flag, a
    string or a number its value (``false`` leaves it out)."""
    if table is None:
        return {}
    options = {}
    for key, value in table.values.items():
        table.has(key)
        if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", key):
            table.fail(key, "is not a PETSc option name: give it without the leading '-' and the prefix "
                            "(ksp_monitor, snes_linesearch_type)")
        if isinstance(value, bool):
            if value:
                options[key] = None
        elif is_number(value) or isinstance(value, str):
            options[key] = str(value)
        else:
            table.fail(key, f"must be true, a number or a string, got {shown(value)}")
    return options

