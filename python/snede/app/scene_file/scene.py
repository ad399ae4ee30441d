"""A scene file's recipe made into a ``snede.app.scenes.Scene``, which ``run_scene.run`` runs as it
runs the built-in ones (the XDMF series, the picture, summary.json): the body, held and
loaded; without tools one static solve, with tools a run (``ToolRun.evolve``) that relaxes the
loads, then moves each tool, relaxing after each move, and adds a GIF of it."""
from __future__ import annotations

import numpy as np

import snede
from snede.app.run_scene import static_solver
from snede.app.scene_file.frames import VIEW, Frames, clipped
from snede.app.scene_file.reading import SceneFileError
from snede.app.scene_file.recipe import Recipe
from snede.app.scene_file.tools import Needle
from snede.app.scenes.scene import Scene, briefly, material, shaft_force, solve_entries
from snede.app.scenes.incision import incision_cells, lips_gap


class ToolRun:
    """The run of a scene with tools (``evolve``): the loads relaxed, then each tool in turn."""

    def __init__(self, scene: Scene, tools: list):
        self.scene, self.body, self.tools = scene, scene.body, tools
        self.results, self.frames = [], Frames()
        self._cutter, self.cut_report = None, snede.CutResult()
        self.needle = self.insertion = None
        self.solver = self.writer = None
        self.say = print

    # -- what the tools use ---------------------------------------------------------------
    def cutter(self) -> snede.TetrahedralCutter:
        if self._cutter is None:
            self._cutter = snede.TetrahedralCutter(self.body)
        return self._cutter

    def incision(self) -> np.ndarray:
        return np.zeros((0, 3), dtype=np.int64) if self._cutter is None else self._cutter.incision_faces()

    def relax(self):
        result = self.solver.solve()
        self.results.append(result)
        return result

    def record(self, label: str, tool=None) -> None:
        """A step of the series (with the cell field ``incision``) and a frame of the GIF."""
        incision = self.incision()
        fields = {"point_fields": {"needle_state": self.needle.node_state()}} if self.needle is not None else {}
        self.writer.write(self.body, time=float(len(self.frames.frames)),
                          incision=incision_cells(self.body.mesh, incision), **fields)
        self.frames.record(self.body, incision, tool, label)

    # -- the run ---------------------------------------------------------------------------
    def evolve(self, method: str, rtol: float, writer, folder, progress: bool) -> dict:
        for tool in self.tools:
            if method not in tool.methods:
                raise ValueError(f"method {method!r} cannot relax the {type(tool).__name__.lower()} of {tool.key}: "
                                 f"it takes {' or '.join(tool.methods)}")
        self.method, self.rtol, self.writer = method, rtol, writer
        self.say = (lambda line: print(line, flush=True)) if progress else (lambda line: None)
        self.solver = static_solver(self.scene, method, rtol)
        self.record("unloaded")
        result = self.relax()
        self.say(f"{self.scene.name}: loads relaxed: {briefly(result)}")
        self.record("loaded")
        done = result.converged and all(tool.run(self) for tool in self.tools)
        if not done:
            self.say(f"{self.scene.name}: stopped: a relaxation did not converge")
        gif = self.frames.save(folder / f"{self.scene.name}.gif")
        return {**self.entries(), "frames": len(self.frames.frames), "files": {"gif": str(gif)}}

    def entries(self) -> dict:
        """The summary's entries: the static solves' (``solve_entries``), the insertion's added."""
        entries = solve_entries(self.results)
        entries["seconds"] += self.cut_report.seconds
        notes = []
        if self._cutter is not None:
            entries.update(incision_faces=len(self.incision()), faces_dissected=self.cut_report.faces_dissected,
                           components=self.cut_report.components)
            notes.append(str(self.cut_report))
        if self.insertion is not None:
            report = self.insertion
            if entries["converged"] and not report.converged:
                entries.update(converged=False, reason=report.reason)
            entries.update(iterations=entries["iterations"] + sum(s.solver_iterations for s in report.steps),
                           seconds=entries["seconds"] + report.seconds, updates=report.updates,
                           rearrangements=report.rearrangements, needle_nodes=len(self.needle.needle_nodes))
            notes.append(str(report))
        return {**entries, "notes": "; ".join(notes)}

    def decorate(self, ax) -> None:
        """The picture's tool where it last was (the blade's edge, the needle's shaft), within the body's box."""
        last = self.frames.frames[-1] if self.frames.frames else None
        if last is None or last.tool is None:
            return
        deformed = (self.body.mesh.points + self.body.displacement)[self.body.mesh.live_vertices]
        tool = clipped(last.tool, deformed.min(axis=0), deformed.max(axis=0))
        if tool is not None:
            name = "needle" if isinstance(self.tools[-1], Needle) else "blade"
            ax.plot(tool[:, 0], tool[:, 1], tool[:, 2], color="k", linewidth=2.0, zorder=5, label=name)

    @property
    def probe_name(self) -> str:
        if isinstance(self.tools[-1], Needle):
            return "needle force along shaft [N]"
        return "widest gap between the lips [m]"

    def probe(self, body) -> float:
        """What the last tool measures: the needle's force along its shaft, or how wide the cut opened."""
        last = self.tools[-1]
        if isinstance(last, Needle):
            return 0.0 if self.needle is None else shaft_force(self.needle)
        return lips_gap(body, self.incision())


def largest_displacement(body) -> float:
    return float(np.linalg.norm(body.displacement, axis=1).max())


def build(recipe: Recipe, material_name: str | None = None, formulation: str | None = None) -> Scene:
    """The scene of ``recipe``; ``material_name`` (the command line's ``--material``) replaces
    the file's material model, its parameters kept, and ``formulation`` (``--formulation``) the
    file's formulation."""
    mesh = recipe.mesh()
    m = recipe.material
    body = snede.Body(mesh, material(material_name or m.name, m.E, m.nu, m.gamma), density=m.density,
                      formulation=formulation or m.formulation)
    held = np.zeros(mesh.n_points, dtype=bool)
    for region, displacement in recipe.holds:
        vertices = _picked(recipe, region, mesh)
        body.fix(vertices, displacement)
        held[vertices] = True
    for region, force in recipe.forces:
        vertices = _picked(recipe, region, mesh)
        body.add_nodal_force(vertices, np.asarray(force) / len(vertices))
    if recipe.gravity is not None:
        body.add_gravity(recipe.gravity)
    for tool in recipe.tools:
        tool.check(mesh)
    s = recipe.solver
    linear = isinstance(body.material, snede.LinearElastic)
    scene = Scene(
        name=recipe.name, description=recipe.description, body=body,
        default_method=s.method or ("cg" if linear else "newton"), default_rtol=s.rtol, damping=s.damping,
        probe_name="largest displacement [m]", probe=largest_displacement,
        fixed=lambda points: np.r_[held, np.zeros(len(points) - len(held), dtype=bool)],
        solver_options=s.options(),
        details={"scene_file": recipe.source, "holds": [r.description for r, _ in recipe.holds],
                 "forces": [r.description for r, _ in recipe.forces]})
    scene.picture = lambda: {"view": VIEW, "loads": ("nodal", "gravity")}
    if recipe.tools:
        run = ToolRun(scene, recipe.tools)
        scene.evolve = run.evolve
        scene.probe_name, scene.probe = run.probe_name, run.probe
        scene.decorate = run.decorate
        scene.picture = lambda: {"view": VIEW, "loads": ("nodal", "gravity"), "reference": run._cutter is None,
                                 **({"highlight": run.incision()} if run._cutter is not None else {})}
    return scene


def _picked(recipe: Recipe, region, mesh) -> np.ndarray:
    try:
        vertices = region.pick(mesh)
    except ValueError as error:  # a group the mesh does not have
        raise SceneFileError(f"{recipe.source}: {region.key}: {error}") from None
    if len(vertices) == 0:
        raise SceneFileError(f"{recipe.source}: {region.key} ({region.description}) picks no vertex of the mesh "
                             f"(it spans {np.round(mesh.points.min(axis=0), 6).tolist()} to "
                             f"{np.round(mesh.points.max(axis=0), 6).tolist()})")
    return vertices

