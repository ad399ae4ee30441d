"""An elastic body: a mesh, a material and a density, evaluated matrix-free (§2.3, §4.3).

Sign convention: ``internal_forces(u)`` is −∂Π_int/∂u (the force the material exerts on the
nodes); ``tangent_apply(u, d)`` is ∂²Π_int/∂u² · d. Arrays are ``(n_points, dim)``.
"""
from __future__ import annotations

import numpy as np

from snede import _checks, _snede
from snede._body_arguments import (FORMULATIONS, LockingWarning, check_body, displacement_field,  # noqa: F401
                                   face_forces, traction_faces, vertex_selection)
from snede._engine import engine_property
from snede.distributed import DistributedMesh
from snede.mesh import Mesh
from snede.part_body import PartBody


def formulations() -> dict[str, str]:
    """The names ``Body(..., formulation=NAME)`` takes, each with what it does."""
    assert set(FORMULATIONS) == set(_snede.formulations())
    return dict(FORMULATIONS)


class Body:
    """``Body(mesh, material, density=1000.0, thickness=None, comm=None, formulation="p1")``.

    ``material`` is one of ``snede.LinearElastic(E, nu)``, ``snede.StVenantKirchhoff(E, nu)``,
    ``snede.NeoHookean(E, nu)``, ``snede.VerondaWestmann(E, nu, gamma)``. A 2D mesh is a
    plane-stress sheet and needs ``thickness`` (metres); a tetrahedral mesh must not have one.

    A surface mesh (triangles in 3D, ``mesh.is_surface``) is an elastic membrane: plane stress
    in each triangle's plane, displacements (n_points, 3); it needs ``thickness`` too. Its
    hyperelastic energy depends only on the in-plane stretch FᵀF, so it carries loads across
    its plane once stretched; the linear material's membrane has no stiffness out of its
    plane at all (support every vertex out of plane, or use a hyperelastic material). For a
    membrane "inverted" means collapsed to zero area (a triangle in 3D has no inside).

    Inverted elements (det F ≤ 0): neo-Hookean and Veronda-Westmann give energy +inf and
    leave those elements out of forces and tangent actions; St. Venant-Kirchhoff and linear
    evaluate them as usual. ``inverted_elements(u)`` lists them either way. An exponential
    overflow (Veronda-Westmann at large strain) raises ``snede.DomainError``.

    ``formulation``: how displacements become strains (``snede.formulations()``): "p1", the
    thesis's constant-strain simplex, or "smoothed", strains averaged over edge and vertex
    patches, which does not lock for nearly incompressible tissue (ν up to 0.499) and bends
    more accurately on coarse meshes, for about twice the cost per operator product
    (docs/results/locking.md). Both keep one unknown per vertex, so cuts, refinement, needles
    and preconditioners work unchanged; membranes take "p1" only, and MPI solves too (for now).

    ``comm`` (an mpi4py communicator, issue 18): the communicator its solvers run on when they
    are not given one (``StaticSolver``, ``DynamicRelaxation``: rank 0's body is distributed
    and the answer gathered back into every rank's). The body itself stays a serial
    description, the same on every rank; None (default): serial solves. A convenience for
    bodies one process holds easily; a larger one is made on the ranks: ``Body(part, ...)`` of a
    :class:`snede.DistributedMesh` is a :class:`snede.PartBody`, this rank's share of the body.
    """

    def __new__(cls, mesh=None, *arguments, **keywords):  # mesh=None: copy and pickle make one empty
        if isinstance(mesh, DistributedMesh):
            return PartBody(mesh, *arguments, **keywords)
        return super().__new__(cls)

    def __init__(self, mesh: Mesh, material, density: float = 1000.0, thickness: float | None = None, comm=None,
                 formulation: str = "p1"):
        check_body(mesh, material, thickness, formulation, stacklevel=2)
        if comm is not None and not (hasattr(comm, "rank") and hasattr(comm, "size") and hasattr(comm, "bcast")):
            raise TypeError(f"comm must be an mpi4py communicator (or None), got {type(comm).__name__}")
        self.mesh = mesh
        self.material = material
        self.comm = comm
        self._impl = _snede.ElasticBody(mesh._impl, material, float(density), float(thickness or 0.0), formulation)
        self._model = _snede.Model(self._impl)

    @property
    def dim(self) -> int:
        return self.mesh.dim

    formulation = engine_property("formulation")
    density = engine_property("density")

    @property
    def thickness(self) -> float | None:
        return self._impl.thickness if self.mesh.cell_dim == 2 else None

    def _field(self, name: str, value) -> np.ndarray:
        return displacement_field(self.mesh, self.dim, name, value)

    def energy(self, u) -> float:
        """Internal elastic energy Π_int(u) (joules); +inf if an element is inverted under a
        material that forbids inversion."""
        return self._impl.energy(self._field("u", u))

    def internal_forces(self, u) -> np.ndarray:
        """−∂Π_int/∂u at u, shape (n_points, dim)."""
        return self._impl.internal_forces(self._field("u", u))

    def tangent_apply(self, u, d) -> np.ndarray:
        """K(u)·d with K = ∂²Π_int/∂u², without forming K; shape (n_points, dim)."""
        return self._impl.tangent_apply(self._field("u", u), self._field("d", d))

    def inverted_elements(self, u) -> np.ndarray:
        """Row indices (into ``mesh.cells``) of the cells with det F ≤ 0 at u (on a membrane:
        the cells collapsed to zero area)."""
        ids = np.asarray(self._impl.inverted_elements(self._field("u", u)), dtype=np.int64)
        return np.searchsorted(self.mesh.cell_ids, ids)

    def element_stress(self, u) -> np.ndarray:
        """Second Piola-Kirchhoff stress per cell (σ for LinearElastic): (n_cells, dim, dim).
        On a membrane the in-plane stress, (n_cells, 2, 2), in each cell's reference tangent
        frame: t₁ along its first edge (``mesh.cells[row][1] − mesh.cells[row][0]``), t₂ = n × t₁
        with n its normal (the right-hand rule over the cell's vertex order)."""
        return self._impl.element_stress(self._field("u", u))

    def element_stiffness(self, row: int, u) -> np.ndarray:
        """Stiffness matrix of cell ``row`` at u: (corners·dim)², ordered by the cell's
        vertices (``mesh.cells[row]``) then components. For checks and preconditioners."""
        row = _checks.index(row, "row", self.mesh.n_cells, "rows of mesh.cells")
        return self._impl.element_stiffness(int(self.mesh.cell_ids[row]), self._field("u", u))

    def tangent_operator(self, u=None):
        """The tangent J = P K(u) P + c (I − P) as a petsc4py ``Mat`` applied matrix-free (a
        ``MatShell`` over the element kernels; P projects out the constrained motions, so a
        fixed vertex's rows are c times the identity, c a stiffness of the body's units about a
        diagonal entry of K, which keeps every preconditioner independent of E and the length
        unit). ``u``: (n_points, dim), default the current
        displacement. The shell is the body's own: a later solve moves its linearisation point,
        and after a cut or refinement the body makes a new one (ask again). It also gives its
        diagonal (``getDiagonal``)."""
        return self._model.tangent_operator(self._field("u", self.displacement if u is None else u))

    def assemble_tangent(self, u=None, format: str = "baij"):
        """J at ``u`` (default the current displacement) assembled from the same element kernels
        into a new petsc4py ``Mat``: ``format`` "baij" (blocks of dim × dim) or "aij". For
        preconditioners and comparison; it does not follow later mesh changes. (The solvers'
        preconditioners take a membrane element's positive part instead, where the sheet is
        compressed.) A dropped one is freed when snede next hands out a PETSc handle (petsc4py
        defers the destroy)."""
        return self._model.assemble_tangent(self._field("u", self.displacement if u is None else u), str(format))

    def lumped_mass(self) -> np.ndarray:
        """Mass per vertex (kg): 1/(cell_dim+1) of each incident cell's mass (§2.5); (n_points,)."""
        return np.asarray(self._impl.lumped_mass())

    def gravity_forces(self, g=(0.0, 0.0, -9.81)) -> np.ndarray:
        """Nodal gravity load ρ|τ|g/(cell_dim+1) per cell and vertex; (n_points, dim)."""
        g = np.asarray(g, dtype=np.float64)
        if g.shape != (self.dim,):
            raise ValueError(f"g must have {self.dim} components, got shape {g.shape}")
        return self._impl.gravity_forces(g)

    # -- constraints, loads and state (the model, §3.1, §6.6) ----------------------------
    def _vertices(self, vertices) -> np.ndarray:
        return vertex_selection(self.mesh, vertices)

    def fix(self, vertices, value=None) -> None:
        """Fix vertices (indices, a boolean mask, or the name of one of the mesh's boundary or
        cell groups: ``mesh.boundary_groups``, ``mesh.cell_groups``) at displacement ``value``: None for zero,
        one (dim,) vector for all, or (n_vertices, dim). The state is moved onto it."""
        vertices = self._vertices(vertices)
        if value is None:
            values = np.zeros((len(vertices), self.dim))
        else:
            values = np.broadcast_to(np.asarray(value, dtype=np.float64), (len(vertices), self.dim))
        self._model.fix(vertices, np.ascontiguousarray(values))

    def slide(self, vertices, direction) -> None:
        """Let vertices move only along ``direction`` (a line through where they are now)."""
        self._model.slide(self._vertices(vertices), np.asarray(direction, dtype=np.float64))

    def fix_free_pieces(self) -> int:
        """Fix every piece of the body (cells joined through faces) that its constraints do not
        hold: the corners of one of its cells, where they are now, so that the static problem
        stays well posed (§3.3). Returns how many pieces it fixed. A piece is held when its
        constraints stop all its rigid motions (3 in 2D, 6 in 3D: two fixed vertices leave the
        rotation about the line through them), or on a membrane, which tension holds, when it has
        6 constrained displacement components; a static solve refuses a body with a piece that
        is not. For pieces cut
        free by ``mesh.dissect`` or a ``DelaunayCutter``; a ``TetrahedralCutter`` fixes them as it
        cuts (``fix_free_pieces=True``)."""
        corners = self._model.loose_piece_cells().ravel()
        if len(corners):
            self.fix(corners, self.displacement[corners])
        return len(corners) // (self.mesh.cell_dim + 1)

    def release(self, vertices) -> None:
        """Remove the constraints of these vertices."""
        self._model.release(self._vertices(vertices))

    # Loads are separate terms of the potential (§6.6): gravity and named nodal-force
    # channels ("nodal" by default; a needle keeps its friction in "friction"), each set,
    # changed or cleared without touching the others.
    def add_gravity(self, g=(0.0, 0.0, -9.81)) -> None:
        """Gravity (m/s²) acting on the element masses; replaces a previous gravity."""
        g = np.asarray(g, dtype=np.float64)
        if g.shape != (self.dim,):
            raise ValueError(f"g must have {self.dim} components, got shape {g.shape}")
        self._model.set_gravity(g)

    def clear_gravity(self) -> None:
        self._model.clear_gravity()

    has_gravity = engine_property("has_gravity", "Whether gravity acts (``add_gravity`` until ``clear_gravity`` or "
                                                 "``clear_loads()``).", source="_model")

    def add_nodal_force(self, vertices, force, channel: str = "nodal") -> None:
        """Add a force (newtons) to load channel ``channel``: one (dim,) vector on every listed
        vertex, or (n_vertices, dim)."""
        self._model.add_nodal_force(str(channel), self._vertices(vertices), np.asarray(force, dtype=np.float64))

    def boundary_faces(self) -> np.ndarray:
        """The body's boundary faces, ``mesh.boundary_faces()`` (as a PartBody gives its rank's
        share of them)."""
        return self.mesh.boundary_faces()

    def add_traction(self, faces, traction, channel: str = "nodal") -> None:
        """Add a uniform traction (force per unit area of the reference boundary, a (dim,)
        vector) on boundary faces — the name of one of ``mesh.boundary_groups`` or (n, cell_dim)
        vertex indices — lumped to their vertices: each face's force (traction × area; edges in
        2D and on membranes: × length × thickness) split equally among its corners."""
        faces = traction_faces(self.mesh, faces)
        shares = face_forces(self.mesh, faces, traction, self.dim, self.thickness)
        forces = np.zeros((self.mesh.n_points, self.dim))
        for corner in range(self.mesh.cell_dim):
            np.add.at(forces, faces[:, corner], shares)
        loaded = np.unique(faces)
        self.add_nodal_force(loaded, forces[loaded], channel)

    def set_nodal_forces(self, vertices, force, channel: str = "nodal") -> None:
        """Replace the whole channel ``channel`` by these forces (other channels unchanged)."""
        self._model.set_nodal_forces(str(channel), self._vertices(vertices), np.asarray(force, dtype=np.float64))

    def clear_loads(self, channel: str | None = None) -> None:
        """Clear one nodal-force channel, or with no argument every channel and gravity."""
        if channel is None:
            self._model.clear_loads()
        else:
            self._model.clear_channel(str(channel))

    load_channels = engine_property(
        "load_channels", """Names of the nodal-force channels in use, those ``external_forces(channel)`` and
        ``clear_loads(channel)`` take. Gravity is not among them: it is a body force on the
        element masses, not forces on named vertices, set by ``add_gravity`` and cleared by
        ``clear_gravity``; ``has_gravity`` says whether it acts.""", list, "_model")

    def external_forces(self, channel: str | None = None) -> np.ndarray:
        """Gravity plus every channel's nodal forces, or one channel's, (n_points, dim)."""
        if channel is None:
            return self._model.external_forces()
        return self._model.channel_forces(str(channel))

    def reaction_forces(self) -> np.ndarray:
        """Forces the supports exert on the body at the current state, (I − P)∇Π(u)."""
        return self._model.reaction_forces()

    @property
    def displacement(self) -> np.ndarray:
        """The state u, (n_points, dim) (a copy; assign to set it)."""
        return self._model.displacement

    @displacement.setter
    def displacement(self, u) -> None:
        self._model.displacement = self._field("displacement", u)

    def refine_near_segment(self, a, b, h: float, radius: float = 0.0) -> int:
        """Refine the mesh along a segment (see ``Mesh.refine_near_segment``); the state is
        interpolated to the new vertices, and solver vectors are reissued once."""
        return self.mesh.refine_near_segment(a, b, h, radius)

    def refine_around(self, point, h: float) -> int:
        """Refine the mesh around ``point`` to edge length ``h`` (see ``Mesh.refine_around``)
        in the middle of a simulation: new midpoints get the mean of their edge ends'
        displacement (and constraints), so the state carries over and the next solve starts
        from it. The whole refinement is one mesh change, so solver vectors are reissued once.
        Returns how many cells were split."""
        return self.mesh.refine_around(point, h)

    def flops_per_element(self) -> dict:
        """Flops per element of the energy, force and tangent-action kernels, counted by
        running them on a counting scalar type (Table 4.3's measure)."""
        return self._impl.flops_per_element()

    def __repr__(self) -> str:
        return f"<snede.Body {type(self.material).__name__} on {self.mesh!r}>"
