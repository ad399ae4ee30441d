"""Meshes distributed over MPI ranks by PETSc's DMPlex (issue 18, first part).

``snede.distribute(mesh, comm=None)`` is collective: rank 0 passes the serial mesh (the other
ranks may pass it too, or None; only rank 0's is read), and every rank gets its part: the cells
PETSc's partitioner gave it, as a :class:`snede.Mesh` with local vertex ids, the serial id of
each local vertex (``global_vertex``), and which of them the rank owns (``owned``; a vertex on
several ranks' cells is owned by exactly one). Cells are not overlapped. A problem with rank
0's input raises the same ``ValueError`` on every rank. Run with ``mpirun -n N``.

:class:`DistributedStatic` solves a static problem on the parts: the same element kernels on
every rank's cells, PETSc's SNES and KSP on a vector distributed by owned vertices, so the
same problem gives the same displacement on any number of ranks: linear CG, Newton, nonlinear
CG, with no preconditioner, Jacobi or GAMG; :class:`DistributedRelaxation` relaxes it in time.
Gravity is given as nodal forces, and the mesh cannot be edited (a PartBody refines on the ranks:
part_body.py; cuts and needles stay serial).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from snede import _checks, _records, _snede, part_groups
from snede.mesh import Mesh
from snede._snede import SolveResult

MATERIALS = (_snede.LinearElastic, _snede.StVenantKirchhoff, _snede.NeoHookean, _snede.VerondaWestmann)


def agreed(comm, check):
    """``check()`` on every rank of ``comm`` (collective): its value, or, if it raised on any
    rank, the same exception on every rank (the lowest such rank's, named; a RuntimeError
    naming its type if that type cannot be made from a message), so that no rank goes on alone
    into a collective call."""
    try:
        value, problem = check(), None
    except Exception as error:  # any: one rank leaving alone would leave the others waiting
        value, problem = None, (type(error), str(error))
    for rank, found in enumerate(comm.allgather(problem)):
        if found is not None:
            kind, text = found
            text = text if comm.size == 1 else f"rank {rank}: {text}"
            try:
                same = kind(text)
            except Exception:
                same = RuntimeError(f"{kind.__name__}: {text}")
            raise same
    return value


def _world():
    from mpi4py import MPI

    return MPI.COMM_WORLD


@dataclass
class DistributedMesh:
    """This rank's part of a distributed mesh (see :func:`distribute`)."""

    comm: object  # mpi4py communicator
    local: Mesh
    global_vertex: np.ndarray  # (n_local_vertices,) serial vertex id of each local vertex
    owned: np.ndarray  # (n_local_vertices,) bool: this rank owns the vertex
    global_number: np.ndarray  # (n_local_vertices,) PETSc's numbering: owned rows contiguous per rank
    n_global_vertices: int
    n_global_cells: int
    _impl: object = None  # keeps the engine's part (which holds `local`) alive

    @classmethod
    def read(cls, path, comm=None) -> "DistributedMesh":
        """This rank's part of the mesh in ``path``, collective over ``comm`` (default
        ``MPI.COMM_WORLD``). An XDMF series written by ``snede.output.SeriesWriter`` (its last
        step's mesh) is read in shares: each rank reads only its share of the cells and of the
        points from the HDF5 file, and DMPlex balances them (``distribute_cells``); no rank
        holds the whole. A series written on ranks gives its vertices their serial ids back
        (its field ``serial_vertex``), so conditions by serial id apply as before. Every other
        format ``snede.Mesh.read`` takes is read whole by rank 0 and distributed
        (``distribute``), with its named groups (a series read in shares has none). A file that
        cannot be read raises the same error on every rank."""
        from snede import series_files

        comm = _world() if comm is None else comm
        if Path(path).suffix.lower() in (".xdmf", ".xmf") and agreed(comm, lambda: series_files.is_series(path)):
            cells, points, on_ranks = agreed(comm, lambda: series_files.read_last_mesh_share(path, comm.rank,
                                                                                                comm.size))
            part = distribute_cells(cells, points, comm)
            if on_ranks:
                serial = agreed(comm, lambda: series_files.read_serial_vertices(path, part.global_vertex))
                part._impl.renumber_vertices(serial)
                part.global_vertex = part._impl.global_vertex.ravel().copy()
            return part
        mesh = agreed(comm, lambda: Mesh.read(path) if comm.rank == 0 else None)
        return distribute(mesh, comm)

    def vertices_where(self, where) -> np.ndarray:
        """The global ids of the vertices whose points ``where`` picks, the same sorted array on
        every rank (collective): ``where(points)`` takes this rank's (n_local, dim) points and
        returns a bool per point, e.g. ``lambda x: np.isclose(x[:, 2], 0.0)``. What a
        :class:`DistributedStatic`'s ``fixed`` or ``forces`` take, without any rank holding the
        whole mesh; the ids picked (a face, a patch) are gathered on every rank."""
        def picked():
            mask = np.asarray(where(self.local.points), dtype=bool)
            if mask.shape != (self.local.n_points,):
                raise ValueError(f"where(points) must give one bool per point, ({self.local.n_points},); "
                                 f"got shape {mask.shape}")
            return self.global_vertex[mask & self.owned]

        mine = agreed(self.comm, picked)
        return np.sort(np.concatenate(self.comm.allgather(mine))).astype(np.int64)


def distribute(mesh: Mesh | None, comm=None) -> DistributedMesh:
    """Partition rank 0's ``mesh`` over ``comm`` (default ``MPI.COMM_WORLD``) with DMPlex;
    every rank returns its part, with the mesh's named groups (their members on the rank,
    ``part_groups.py``). Collective."""
    comm = _world() if comm is None else comm
    serial = mesh._impl if (comm.rank == 0 and isinstance(mesh, Mesh)) else None
    part = _part(comm, _snede.distribute_mesh(comm.py2f(), serial))
    groups = agreed(comm, lambda: part_groups.serial_groups(mesh) if comm.rank == 0 else None)
    part_groups.give_groups(part, *comm.bcast(groups, root=0))
    return part


def distribute_cells(cells, coordinates, comm=None) -> DistributedMesh:
    """A mesh that no rank holds whole (issue 52): every rank of ``comm`` (default
    ``MPI.COMM_WORLD``) gives some of its cells, ``cells`` ((n, 3) triangles or (n, 4)
    tetrahedra, by global vertex ids), and the coordinates of its range of vertices,
    ``coordinates`` ((m, 2) or (m, 3)): rank 0 the first ids, each next rank's range starting
    where the previous one's ends. DMPlex balances the cells over the ranks; every rank returns
    its part, whose ``global_vertex`` are these global ids. Collective; a malformed part on any
    rank raises the same ValueError on every rank."""
    comm = _world() if comm is None else comm
    cells = np.asarray(cells, dtype=np.int64)
    coordinates = np.asarray(coordinates, dtype=np.float64)
    corners = cells.shape[1] if cells.ndim == 2 else 0
    space = coordinates.shape[1] if coordinates.ndim == 2 else 0
    return _part(comm, _snede.distribute_cells(comm.py2f(), corners - 1, cells.reshape(-1, max(corners, 1)),
                                               coordinates.reshape(-1, max(space, 1))))


def refresh_part(part: DistributedMesh) -> None:
    """Reads the arrays of a part from its engine object, which a refinement on the ranks
    changes in place (rank_refinement): its ids, owners and numbering; ``part.local`` is the same
    mesh, refined."""
    impl = part._impl
    part.global_vertex = impl.global_vertex.ravel().copy()
    part.owned = impl.owned.ravel().astype(bool)
    part.global_number = impl.global_number.ravel().copy()
    part.n_global_vertices, part.n_global_cells = int(impl.n_global_vertices), int(impl.n_global_cells)


def _part(comm, part) -> DistributedMesh:
    local = Mesh._wrap(part.local)
    local._distributed_part = f"rank {comm.rank}'s part of a mesh distributed over {comm.size} MPI ranks"
    made = DistributedMesh(comm=comm, local=local, global_vertex=None, owned=None, global_number=None,
                           n_global_vertices=0, n_global_cells=0, _impl=part)
    refresh_part(made)
    return made


class DistributedStatic:
    """A static solve on a :class:`DistributedMesh` (collective throughout).

    ``DistributedStatic(part, material, *, density=1000.0, thickness=None, fixed=(),
    fixed_values=None, sliding=(), sliding_directions=None, sliding_anchors=None, forces=None,
    gravity=None)``: ``fixed`` are serial vertex ids held at ``fixed_values`` ((len(fixed), dim),
    default zero); ``sliding`` are serial vertex ids that move only along the lines
    ``sliding_anchors + s·sliding_directions`` (both (len(sliding), dim); the directions non-zero,
    the anchors — displacements on the lines, what ``Body.slide`` takes from where the vertices
    are — default zero), as ``Body.slide`` constrains them; ``forces`` maps serial vertex ids to
    nodal force vectors; ``gravity`` (m/s², dim components) loads the element masses as
    ``Body.add_gravity`` does. ``thickness`` is for triangles: plane-stress sheets in 2D and
    membranes (a surface mesh, triangles in 3D). Every rank passes the same arguments (else every rank raises
    ValueError naming those that differ). The density also sets the masses of
    :class:`DistributedRelaxation`.

    ``solve(method="cg" | "newton" | "ncg", rtol=1e-8, preconditioner="none" | "jacobi" |
    "gamg" | "mg" | "bjacobi" | "sor" | "lu" | ...)`` returns a :class:`snede.SolveResult` with
    PETSc's reason; ``-<prefix>snes_*``/``-<prefix>ksp_*``/``-<prefix>pc_*`` options apply
    (prefix ``dstatic_``)."""

    def __init__(self, part: DistributedMesh, material, *, density: float = 1000.0, thickness=None, fixed=(),
                 fixed_values=None, sliding=(), sliding_directions=None, sliding_anchors=None, forces=None,
                 gravity=None):
        self.part = part

        def conditions():
            if not isinstance(part, DistributedMesh):
                raise TypeError(f"part must be a DistributedMesh (from snede.distribute), got {type(part).__name__}")
            dim = part.local.dim
            ids = np.asarray(fixed, dtype=np.int64).ravel()
            values = _per_vertex(fixed_values, len(ids), dim, "fixed_values")
            sliding_ids = np.asarray(sliding, dtype=np.int64).ravel()
            if sliding_directions is None and len(sliding_ids):
                raise ValueError("sliding vertices need sliding_directions, (len(sliding), dim)")
            directions = _per_vertex(sliding_directions, len(sliding_ids), dim, "sliding_directions")
            anchors = _per_vertex(sliding_anchors, len(sliding_ids), dim, "sliding_anchors")
            if not isinstance(material, MATERIALS):
                raise TypeError(f"material must be LinearElastic, StVenantKirchhoff, NeoHookean or VerondaWestmann, "
                                f"got {type(material).__name__}")
            if not (np.isfinite(float(density)) and density > 0):
                raise ValueError(f"density must be positive and finite, got {density}")
            loaded = np.array(list(forces or {}), dtype=np.int64)
            loads = np.array([np.asarray(f, dtype=np.float64) for f in forces.values()]).reshape(len(loaded), -1) \
                if forces else np.zeros((0, dim))
            if len(loaded) and loads.shape[1] != dim:
                raise ValueError(f"forces must be {dim}-vectors, got {loads.shape[1]} components")
            g = [] if gravity is None else np.asarray(gravity, dtype=np.float64).ravel().tolist()
            return (float(density), float(thickness or 0.0), ids.tolist(), values.ravel().tolist(),
                    sliding_ids.tolist(), directions.ravel().tolist(), anchors.ravel().tolist(), loaded.tolist(),
                    loads.ravel().tolist(), g)

        # A rank given no part has no communicator: it reports on the world's, which is the
        # part's unless the script distributed over a sub-communicator.
        comm = part.comm if isinstance(part, DistributedMesh) else _world()
        arguments = agreed(comm, conditions)
        self._impl = _snede.DistributedStatic(part._impl, material, *arguments)

    def solve(self, method: str | None = None, rtol: float | None = None, max_iterations: int | None = None,
              preconditioner: str | None = None, options_prefix: str | None = None, criterion: str | None = None,
              round_tolerance: float | None = None, petsc_options: dict | None = None, *,
              options: _snede.StaticOptions | None = None) -> SolveResult:
        """The serial :class:`snede.StaticSolver`'s engine on this problem. ``options``: a
        :class:`snede.StaticOptions` record (default ``snede._snede.distributed_solve_options()``:
        linear CG without a preconditioner, rtol 1e-8, criterion "relative", prefix ``dstatic_``);
        each keyword given (not None) changes its field. ``method`` "cg"
        (linear), "newton" or "ncg" (nonlinear CG, no preconditioner); ``preconditioner`` "none",
        "jacobi" (the tangent's diagonal, summed across the ranks), "mg" (multigrid by aggregation
        of each rank's vertices, Galerkin levels of the assembled tangent), or any PETSc PC on the
        assembled MPIAIJ tangent: "gamg", "bjacobi" (ILU(0) on each rank's block;
        ``-dstatic_sub_pc_type icc`` for ICC), "sor" (symmetric sweeps over each rank's rows), "lu"
        (MUMPS's factors: one CG iteration for a linear body). Starts from the current state (the
        previous solve's answer, or :meth:`set_displacement`'s).

        ``criterion`` "relative": ‖F‖ ≤ rtol·‖F(u₀)‖ on the true residual (CG's
        unpreconditioned one); "6.9" or "6.8": the criteria of §6.6, ‖F‖ ≤ rtol·√(‖f_ext‖² +
        ‖f_react‖²) plus ``round_tolerance``'s floor, or ‖F‖ ≤ rtol·‖f_ext‖; ``tolerance`` in
        the result is the threshold. A start that already meets (6.9) is converged with no
        iteration under "relative" too (a residual at round-off cannot meet ε‖F(u₀)‖)."""
        def checked():  # the engine's record checks every value (a ValueError naming it)
            return _records.settings(
                _snede.StaticOptions, _snede.distributed_solve_options() if options is None else options,
                method=method, rtol=rtol, criterion=criterion, round_tolerance=round_tolerance,
                max_iterations=_checks.optional_count(max_iterations, "max_iterations", 1),
                options_prefix=options_prefix, preconditioner=preconditioner,
                petsc_options=petsc_options)

        return _snede.StaticSolver(self._impl, agreed(self.part.comm, checked)).solve()

    def set_displacement(self, displacement) -> None:
        """Start the next solve (or relaxation) from ``displacement``, (n_global_vertices, dim) in
        the serial mesh's vertex order, the same on every rank; fixed vertices keep their
        prescribed displacements, sliding ones are moved onto their lines. Collective."""
        part = self.part

        def checked():
            u = np.asarray(displacement, dtype=np.float64)
            if u.shape != (part.n_global_vertices, part.local.dim):
                raise ValueError(f"displacement must be ({part.n_global_vertices}, {part.local.dim}) (the serial "
                                 f"mesh's vertices), got shape {u.shape}")
            if not np.all(np.isfinite(u)):
                raise ValueError("displacement must be finite")
            return u.ravel()

        self._impl.set_displacement(agreed(part.comm, checked))

    def set_local_displacement(self, displacement) -> None:
        """Start the next solve from this rank's vertices' displacement, (n_local_vertices, dim)
        in the part's local order (the owned vertices' values are taken; fixed and sliding
        vertices as :meth:`set_displacement` treats them): no array of the whole body. Collective;
        an array of the wrong size or with a non-finite value on any rank raises ValueError on
        every rank."""
        self._impl.set_local_displacement(np.ascontiguousarray(displacement, dtype=np.float64).ravel())

    def energy(self) -> float:
        """Π(u) = Π_int(u) − f_extᵀu of the whole body."""
        return self._impl.energy()

    def local_displacement(self) -> np.ndarray:
        """(n_local_vertices, dim): this rank's vertices, owned and ghosts."""
        return self._impl.local_displacement().reshape(-1, self.part.local.dim)

    def gathered_displacement(self) -> np.ndarray:
        """(n_global_vertices, dim) in the serial mesh's vertex order, on every rank."""
        u, part = self.local_displacement(), self.part
        pieces = part.comm.allgather((part.global_vertex[part.owned], u[part.owned]))
        out = np.zeros((part.n_global_vertices, part.local.dim))
        for ids, values in pieces:
            out[ids] = values
        return out


def _per_vertex(values, n: int, dim: int, name: str) -> np.ndarray:
    """``values`` as (n, dim) floats (zeros for None), or ValueError naming ``name``."""
    array = np.zeros((n, dim)) if values is None else np.asarray(values, dtype=np.float64)
    if array.shape != (n, dim):
        raise ValueError(f"{name} must be ({n}, {dim}), got shape {array.shape}")
    return array


def relaxation_options(options, damping, dt, options_prefix, petsc_options) -> _snede.DynamicRelaxationOptions:
    """The engine's record of a relaxation's settings: ``options`` (None: a default record) with
    each keyword given (not None) as its field; the record checks them (a negative or
    non-finite damping or step is a ValueError naming it; its ``dt`` None is the CFL estimate).
    The serial and the distributed relaxation both make theirs here."""
    return _records.settings(_snede.DynamicRelaxationOptions, options, damping=damping, dt=dt,
                             options_prefix=options_prefix,
                             petsc_options=petsc_options)


class DistributedRelaxation:
    """Dynamic relaxation (§2.5) of a :class:`DistributedStatic` problem: the damped motion
    M ü + η M u̇ = −F(u) with lumped masses, integrated by snede's central-difference TS
    (snede_ss22) on all ranks — the serial DynamicRelaxation's engine, on the problem's
    communicator; ``run(rtol, max_steps)`` stops at criterion (6.9)
    ‖F(u)‖ ≤ rtol·√(‖f_ext‖² + ‖f_react‖²). ``dt`` None takes the CFL estimate (2.61) of the
    whole mesh. ``options``: a :class:`snede.DynamicRelaxationOptions` record (default: the
    default record with ``options_prefix="drelax_"``), whose fields the keywords given (not None)
    change. Options under ``options_prefix``: ``-drelax_ts_monitor`` and so on, or
    ``petsc_options`` (without the prefix) for this solver only. Collective."""

    def __init__(self, problem: DistributedStatic, damping: float | None = None, dt: float | None = None, *,
                 options: _snede.DynamicRelaxationOptions | None = None, options_prefix: str | None = None,
                 petsc_options: dict | None = None):
        self.problem = problem
        given = _snede.DynamicRelaxationOptions(options_prefix="drelax_") if options is None else options
        self._impl = _snede.DynamicRelaxation(problem._impl, agreed(
            problem.part.comm, lambda: relaxation_options(given, damping, dt, options_prefix, petsc_options)))

    @property
    def dt(self) -> float:
        return self._impl.dt

    def run(self, rtol: float = 1e-3, max_steps: int = 100000) -> SolveResult:
        """Steps until (6.9) or ``max_steps`` (``DIVERGED_MAX_IT``); a blow-up, NaN or an
        inverted element ends the run with that reason, not converged."""
        arguments = agreed(self.problem.part.comm, lambda: (float(rtol), _checks.count(max_steps, "max_steps")))
        return self._impl.run(*arguments)
