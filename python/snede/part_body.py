"""This rank's share of a body that no rank holds whole (issue 52): ``snede.Body(part, material,
...)`` of a :class:`snede.DistributedMesh` is a :class:`PartBody`, and the serial Body's calls
apply to it — ``fix``, ``slide``, ``release``, ``add_gravity``, ``add_nodal_force``,
``add_traction``, ``clear_loads``, ``displacement`` — as ``snede.StaticSolver(body, ...)`` and
``SeriesWriter(path, comm=comm).write(body)`` do.

Vertices and faces are named as serially, in the numbering of ``body.mesh`` (this rank's cells
and points, ``part.local``): local indices, a boolean mask over ``body.mesh.points``, or a group
of the local mesh. Every call that sets a condition is collective, each rank giving its own
selection: the ranks' selections are joined by serial vertex id, so a vertex that two ranks
hold and both select is fixed, or loaded, once; two ranks giving one vertex different values
raise ValueError on every rank. The conditions are held by serial id on every rank (as many
entries as constrained or loaded vertices, not the body's); the displacement is this rank's,
(n_local_points, dim); ``gathered_displacement()`` makes the whole one on purpose.
"""
from __future__ import annotations

import numpy as np

from snede import _checks, _snede, part_groups
from snede._body_arguments import check_body, displacement_field, face_forces, traction_faces, vertex_selection
from snede.distributed import DistributedMesh, DistributedStatic, _part, _world, agreed, refresh_part


class PartBody:
    """``PartBody(part, material, density=1000.0, thickness=None, formulation="p1")``: the
    serial :class:`snede.Body`'s arguments, on this rank's ``part`` (collective). The smoothed
    formulation is not distributed yet (its vertex patches need two ghost layers)."""

    def __init__(self, part: DistributedMesh, material, density: float = 1000.0, thickness: float | None = None,
                 formulation: str = "p1"):
        def checked():
            if not isinstance(part, DistributedMesh):
                raise TypeError(f"part must be a snede.DistributedMesh, got {type(part).__name__}")
            check_body(part.local, material, thickness, formulation, stacklevel=4)
            if formulation != "p1":
                raise NotImplementedError(f"formulation {formulation!r} is not distributed yet (its vertex patches "
                                          "need two layers of ghost cells); use 'p1'")
            if not (np.isfinite(float(density)) and density > 0):
                raise ValueError(f"density must be positive and finite, got {density}")

        agreed(part.comm if isinstance(part, DistributedMesh) else _world(), checked)
        self.part, self.mesh, self.comm = part, part.local, part.comm
        self.material, self.density, self.thickness, self.formulation = material, float(density), thickness, formulation
        self._fixed: dict[int, tuple] = {}  # serial id → prescribed displacement
        self._sliding: dict[int, tuple] = {}  # serial id → (unit direction, anchor displacement)
        self._channels: dict[str, dict[int, np.ndarray]] = {}  # channel → serial id → force
        self._gravity = None
        self._displacement = np.zeros((self.mesh.n_points, self.dim))
        self._local_order = np.argsort(part.global_vertex, kind="stable")
        self._problem, self._problem_conditions = None, None
        self._edits, self._edits_seen = 0, 0  # conditions or displacement set, and as of the latest solve
        self._refiner = None  # the part's refinement (rank_refinement.hpp), kept from edit to edit
        self._labels = None  # the cells' bisection labels after a refinement rebalanced the part
        self._cut_configuration = None  # the displacement an open incision began in (part_cutting.py)
        self._cut_ids = None  # on the cutting rank after a cut: each row's global id

    @property
    def dim(self) -> int:
        return self.mesh.dim

    # -- selections, joined over the ranks by serial id -------------------------------------
    def _joined(self, vertices, values) -> tuple[np.ndarray, np.ndarray]:
        """The serial ids every rank selected, with their values (``values(local indices)``, a
        row per selected local vertex), the same on every rank; ValueError on every rank for a bad
        selection on any, or for one vertex given different values."""
        def mine():
            local = vertex_selection(self.mesh, vertices)
            rows = np.broadcast_to(np.asarray(values(local), dtype=np.float64), (len(local), self.dim))
            if not np.all(np.isfinite(rows)):
                raise ValueError("values must be finite")
            return self.part.global_vertex[local], np.ascontiguousarray(rows)

        ids, rows = agreed(self.comm, mine)
        every = self.comm.allgather((ids, rows))
        ids = np.concatenate([i for i, _ in every]).astype(np.int64)
        rows = np.concatenate([r for _, r in every]).reshape(-1, self.dim)
        order = np.lexsort((*rows.T[::-1], ids))
        ids, rows = ids[order], rows[order]
        repeated = np.flatnonzero(ids[1:] == ids[:-1])
        differing = repeated[np.any(rows[repeated + 1] != rows[repeated], axis=1)]
        if len(differing):
            v = int(ids[differing[0]])
            raise ValueError(f"vertex {v} (serial id) was given different values by different ranks: "
                             f"{rows[differing[0]].tolist()} and {rows[differing[0] + 1].tolist()}")
        keep = np.concatenate([[True], ids[1:] != ids[:-1]]) if len(ids) else np.zeros(0, dtype=bool)
        return ids[keep], rows[keep]

    def _local_of(self, serial_ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The local indices of those serial ids this rank holds, and which of the ids they are."""
        held = self.part.global_vertex[self._local_order]
        at = np.clip(np.searchsorted(held, serial_ids), 0, max(len(held) - 1, 0))
        found = held[at] == serial_ids if len(held) else np.zeros(len(serial_ids), dtype=bool)
        return self._local_order[at[found]], np.flatnonzero(found)

    # -- constraints (§3.1) ----------------------------------------------------------------
    def fix(self, vertices, value=None) -> None:
        """Fix vertices at displacement ``value`` (None: zero; one (dim,) vector for all, or
        (n_selected, dim)); the state is moved onto it. Collective."""
        self._edits += 1
        given = np.zeros(self.dim) if value is None else value
        ids, rows = self._joined(vertices, lambda local: given)
        for v, row in zip(ids.tolist(), rows):
            self._sliding.pop(v, None)
            self._fixed[v] = tuple(row)
        local, which = self._local_of(ids)
        self._displacement[local] = rows[which]

    def slide(self, vertices, direction) -> None:
        """Let vertices move only along ``direction`` (a line through where they are now).
        Collective."""
        self._edits += 1
        direction = np.asarray(direction, dtype=np.float64)

        def anchors_of(local):  # checked inside the ranks' agreement: a bad direction raises on all
            if direction.shape != (self.dim,) or not np.all(np.isfinite(direction)) or not np.any(direction):
                raise ValueError(f"direction must be a non-zero finite {self.dim}-vector, got {direction.tolist()}")
            return self._displacement[local]

        ids, anchors = self._joined(vertices, anchors_of)
        unit = tuple(direction / np.linalg.norm(direction))
        for v, anchor in zip(ids.tolist(), anchors):
            self._fixed.pop(v, None)
            self._sliding[v] = (unit, tuple(anchor))

    def release(self, vertices) -> None:
        """Remove the constraints of these vertices. Collective."""
        self._edits += 1
        ids, _ = self._joined(vertices, lambda local: np.zeros(self.dim))
        for v in ids.tolist():
            self._fixed.pop(v, None)
            self._sliding.pop(v, None)

    def boundary_faces(self) -> np.ndarray:
        """The body's boundary faces among this rank's cells, (n, cell_dim) local vertex indices
        oriented as ``Mesh.boundary_faces`` orients them: the local mesh's boundary less the
        faces its cells share with another rank's (inside the body). Collective: each face is
        asked about at one rank chosen by its smallest serial vertex id (no rank gathers the
        whole surface)."""
        faces = self.mesh.boundary_faces()
        keys = np.sort(self.part.global_vertex[faces], axis=1)
        judge = keys[:, 0] % self.comm.size
        asked = self.comm.alltoall([keys[judge == r] for r in range(self.comm.size)])
        everyone = np.concatenate(asked).reshape(-1, faces.shape[1]) if asked else keys[:0]
        _, inverse, counts = np.unique(everyone, axis=0, return_inverse=True, return_counts=True)
        shared = counts[inverse.ravel()] > 1
        answers, start = [], 0
        for got in asked:
            answers.append(shared[start:start + len(got)])
            start += len(got)
        replies = self.comm.alltoall(answers)
        inside = np.zeros(len(faces), dtype=bool)
        for r in range(self.comm.size):
            inside[judge == r] = replies[r]
        return faces[~inside]

    def require_held(self) -> None:
        """ValueError on every rank unless the constraints hold every piece of the body (cells
        joined through faces, wherever they lie), as the serial Body checks before a static
        solve: each piece's fixed and sliding vertices must stop its rigid motions. Collective."""
        self.problem()._impl.require_held()

    # -- loads (§6.6: gravity and named nodal-force channels) --------------------------------
    def add_gravity(self, g=(0.0, 0.0, -9.81)) -> None:
        """Gravity (m/s²) acting on the element masses; replaces a previous gravity."""
        self._edits += 1
        g = np.asarray(g, dtype=np.float64)
        if g.shape != (self.dim,) or not np.all(np.isfinite(g)):
            raise ValueError(f"g must have {self.dim} finite components, got {g.tolist()}")
        self._gravity = tuple(g)

    def clear_gravity(self) -> None:
        """No gravity."""
        self._edits += 1
        self._gravity = None

    @property
    def has_gravity(self) -> bool:
        return self._gravity is not None

    def add_nodal_force(self, vertices, force, channel: str = "nodal") -> None:
        """Add a force (newtons) to channel ``channel`` on every selected vertex, once however
        many ranks select it: one (dim,) vector, or (n_selected, dim). Collective."""
        self._edits += 1
        ids, rows = self._joined(vertices, lambda local: force)
        forces = self._channels.setdefault(str(channel), {})
        for v, row in zip(ids.tolist(), rows):
            forces[v] = forces.get(v, 0.0) + row

    def set_nodal_forces(self, vertices, force, channel: str = "nodal") -> None:
        """Replace the whole channel ``channel`` by these forces. Collective."""
        self._channels.pop(str(channel), None)
        self.add_nodal_force(vertices, force, channel)

    def add_traction(self, faces, traction, channel: str = "nodal") -> None:
        """A uniform traction on boundary faces of this rank's mesh (a boundary group's name or
        (n, cell_dim) local vertex indices), lumped to their corners as serially; a face two
        ranks select is loaded once. Collective."""
        self._edits += 1
        def mine():
            chosen = traction_faces(self.mesh, faces)
            serial = np.sort(self.part.global_vertex[chosen], axis=1)
            return serial, face_forces(self.mesh, chosen, traction, self.dim, self.thickness)

        serial, shares = agreed(self.comm, mine)
        every = self.comm.allgather((serial, shares))
        serial = np.concatenate([f for f, _ in every]).reshape(-1, self.mesh.cell_dim)
        shares = np.concatenate([s for _, s in every]).reshape(-1, self.dim)
        _, first = np.unique(serial, axis=0, return_index=True)
        forces = self._channels.setdefault(str(channel), {})
        for face, share in zip(serial[first].tolist(), shares[first]):
            for v in face:
                forces[v] = forces.get(v, 0.0) + share

    def clear_loads(self, channel: str | None = None) -> None:
        """Clear one nodal-force channel, or with no argument every channel and gravity."""
        self._edits += 1
        if channel is None:
            self._channels.clear()
            self._gravity = None
        else:
            self._channels.pop(str(channel), None)

    @property
    def load_channels(self) -> list[str]:
        return sorted(self._channels)

    # -- state -----------------------------------------------------------------------------
    @property
    def displacement(self) -> np.ndarray:
        """This rank's vertices' displacement, (n_local_points, dim) (a copy; assign to set it:
        a solve starts from the owned vertices' values)."""
        return self._displacement.copy()

    @displacement.setter
    def displacement(self, u) -> None:
        self._displacement = displacement_field(self.mesh, self.dim, "displacement", u).copy()
        self._edits += 1

    def inverted_elements(self, u=None) -> np.ndarray:
        """This rank's cells (indices of ``body.mesh``'s cells) that ``u`` ((n_local_points,
        dim); None: the body's displacement) inverts. Collective (the first call makes the
        distributed problem)."""
        u = agreed(self.comm, lambda: self._displacement if u is None else displacement_field(self.mesh, self.dim, "u", u))
        return np.asarray(self.problem()._impl.inverted_local_elements(u.ravel()), dtype=np.int64).ravel()

    def gathered_displacement(self) -> np.ndarray:
        """The whole body's displacement, (n_global_vertices, dim) in serial vertex order, on
        every rank (collective; an array of the whole body, for small bodies and checks)."""
        part = self.part
        out = np.zeros((part.n_global_vertices, self.dim))
        for ids, values in self.comm.allgather((part.global_vertex[part.owned], self._displacement[part.owned])):
            out[ids] = values
        return out

    # -- refinement on ranks (§6.5) -----------------------------------------------------------
    def refine_uniform(self, levels: int = 1) -> int:
        """Bisect every cell ``levels`` times, as ``Mesh.refine_uniform`` does serially: the
        same cells however the body is partitioned (the ranks agree on the edges of their common
        boundary). Returns how many cells were split, over all ranks. Collective; see
        :meth:`refine_around` for what is carried to the refined part."""
        def checked():
            counted = _checks.count(levels, "levels", 0, 20)
            self._require_same("PartBody.refine_uniform", levels=np.int64(counted).tobytes())
            return counted

        counted = agreed(self.comm, checked)
        return self._refined(lambda refiner, field: refiner.refine_uniform(counted, field, self.dim))

    def refine_around(self, point, h: float) -> int:
        """Bisect until every cell containing ``point`` (shape (dim,)) has edges no longer than
        ``h``, as ``Mesh.refine_around`` does serially, on whichever ranks hold the point; the
        refinement spreads across the rank boundary as far as conformity needs. Collective.

        The first refinement copies the part once, its vertices in the order of their global ids;
        this and later ones then refine it in place, at the cost of the cells they split (``body.part``
        and ``body.mesh`` are the refined ones), until a rank holds more than 1.2 times the mean
        cells: DMPlex then rebalances them into a new part. The
        displacement is carried (a new vertex takes its parents' mean), a new vertex between two
        fixed ones is fixed (as serially), loads stay on their vertices and new vertices carry
        none, and the named groups follow (a cell in its parent's groups, a boundary face in its
        parent face's). Returns how many cells were split."""
        def checked():
            x, size = _checks.coordinates(point, (self.dim,), "point"), _checks.positive(h, "h")
            self._require_same("PartBody.refine_around", point=x.tobytes(), h=np.float64(size).tobytes())
            return x, size

        x, size = agreed(self.comm, checked)
        return self._refined(lambda refiner, field: refiner.refine_around(x, size, field, self.dim))

    def refine_near_segment(self, a, b, h: float, radius: float = 0.0) -> int:
        """Bisect until every cell that comes within ``radius`` of the segment ``a``–``b`` (a
        needle's shaft) has edges no longer than ``h``, as ``Mesh.refine_near_segment`` does
        serially. Collective; see :meth:`refine_around` for what is carried."""
        def checked():
            ends = [_checks.coordinates(end, (self.dim,), name) for end, name in ((a, "a"), (b, "b"))]
            size, reach = _checks.positive(h, "h"), _checks.non_negative(radius, "radius")
            self._require_same("PartBody.refine_near_segment", a=ends[0].tobytes(), b=ends[1].tobytes(),
                               h=np.float64(size).tobytes(), radius=np.float64(reach).tobytes())
            return ends, size, reach

        (start, end), size, reach = agreed(self.comm, checked)
        return self._refined(lambda refiner, field: refiner.refine_near_segment(start, end, size, reach, field, self.dim))

    def _require_same(self, caller: str, **inputs) -> None:
        _snede.require_same_on_every_rank(self.comm.py2f(), caller, list(inputs.items()))

    def _refined(self, edit) -> int:
        """``edit(refiner, displacement)`` on this body's part (collective)."""
        if self._refiner is None:
            self._start_refining()
        self._problem, self._problem_conditions = None, None  # its body watches the mesh the edit changes
        field, new_vertices, split, rebalanced, rule, labels = edit(
            self._refiner, np.ascontiguousarray(self._displacement).ravel())
        self._inherit_fixed(new_vertices)
        if rebalanced is None:  # refined in place: the same mesh, whose groups follow it as serially
            refresh_part(self.part)
        else:
            groups = part_groups.group_shapes(self.mesh, self.comm)
            self.part = _part(self.comm, rebalanced)
            self.mesh = self.part.local
            part_groups.give_group_shapes(self.mesh, self.boundary_faces(), *groups)
            self._refiner, self._labels = None, (rule, labels)  # labels for the next refiner
        self._displacement = np.ascontiguousarray(field).reshape(self.mesh.n_points, self.dim)
        self._local_order = np.argsort(self.part.global_vertex, kind="stable")
        self._edits += 1
        return int(split)

    def _start_refining(self) -> None:
        """The part copied in global-id order into a refinement kept from edit to edit (collective);
        the displacement and the named groups go to the copy's vertex order."""
        refiner = _snede.PartRefinement(self.part._impl, self._labels)
        old_of_new = refiner.original_vertex.ravel()
        new_of_old = np.empty_like(old_of_new)
        new_of_old[old_of_new] = np.arange(len(old_of_new))
        cell_groups = self.mesh.cell_groups
        face_groups = {name: faces for name, faces in self.mesh.boundary_groups.items() if name != part_groups.INCISION}
        self.part = _part(self.comm, refiner.part)
        self.mesh = self.part.local
        for name, rows in cell_groups.items():  # the copy keeps the cells' order
            self.mesh.add_cell_group(name, rows)
        for name, faces in face_groups.items():
            self.mesh.add_boundary_group(name, new_of_old[faces])
        self._displacement = self._displacement[old_of_new]
        self._local_order = np.argsort(self.part.global_vertex, kind="stable")
        self._refiner = refiner

    def _inherit_fixed(self, new_vertices: np.ndarray) -> None:
        """A new vertex both of whose parents are fixed is fixed at their mean (as the serial
        Constraints::inherit does); ``new_vertices`` are this rank's (id, parent, parent) rows.
        Rounds until no rank finds more (a midpoint of midpoints waits for its parents)."""
        waiting = np.asarray(new_vertices, dtype=np.int64).reshape(-1, 3)
        while True:
            fixed = np.fromiter(self._fixed, dtype=np.int64, count=len(self._fixed))
            ready = np.isin(waiting[:, 1], fixed) & np.isin(waiting[:, 2], fixed) & ~np.isin(waiting[:, 0], fixed)
            found = [(v, tuple(0.5 * np.asarray(self._fixed[a]) + 0.5 * np.asarray(self._fixed[b])))
                     for v, a, b in waiting[ready].tolist()]
            waiting = waiting[~ready]
            every = [entry for rank_found in self.comm.allgather(found) for entry in rank_found]
            if not every:
                return
            self._fixed.update(every)

    # -- a part made anew (part_cutting.py) ------------------------------------------------------
    def _take_part(self, part: DistributedMesh, displacement: np.ndarray, new_ids) -> None:
        """This body on ``part`` (collective): the displacement given on its vertices, the
        conditions' global ids mapped by ``new_ids`` (ids no longer used dropped)."""
        self.part, self.mesh = part, part.local
        self._displacement = np.ascontiguousarray(displacement, dtype=np.float64).reshape(self.mesh.n_points, self.dim)
        self._local_order = np.argsort(part.global_vertex, kind="stable")
        self._problem, self._problem_conditions = None, None
        self._refiner, self._labels = None, None  # a cut part is labelled afresh by its next refinement
        tables = [self._fixed, self._sliding] + list(self._channels.values())
        keys = np.fromiter((v for table in tables for v in table), dtype=np.int64)
        mapped = iter(new_ids(keys).tolist())
        for table in tables:
            entries = [(new, value) for new, value in zip(mapped, list(table.values()))]
            table.clear()
            table.update((new, value) for new, value in entries if new >= 0)
        self._edits += 1

    def _apply_conditions(self, replaced, fixed, sliding, channels) -> None:
        """The conditions of the vertices ``replaced`` (global ids) replaced by those given:
        ``fixed`` (ids, values), ``sliding`` (ids, directions, anchors), ``channels`` (name → ids,
        forces). The same on every rank."""
        for v in np.asarray(replaced).tolist():
            self._fixed.pop(v, None)
            self._sliding.pop(v, None)
            for forces in self._channels.values():
                forces.pop(v, None)
        for v, value in zip(*(np.asarray(a) for a in fixed)):
            self._fixed[int(v)] = tuple(value)
        for v, direction, anchor in zip(*(np.asarray(a) for a in sliding)):
            self._sliding[int(v)] = (tuple(direction), tuple(anchor))
        for name, (ids, forces) in channels.items():
            table = self._channels.setdefault(name, {})
            for v, force in zip(np.asarray(ids).tolist(), np.asarray(forces)):
                table[v] = force
        self._edits += 1

    # -- what a solver takes (StaticSolver) --------------------------------------------------
    def problem(self) -> DistributedStatic:
        """The distributed problem of the current conditions (made anew when they changed),
        starting from this body's displacement. Collective."""
        conditions = (dict(self._fixed), dict(self._sliding), self._gravity,
                      {name: {v: tuple(f) for v, f in forces.items()} for name, forces in self._channels.items()})
        if self._problem is None or conditions != self._problem_conditions:
            fixed, sliding = sorted(self._fixed), sorted(self._sliding)
            loads: dict[int, np.ndarray] = {}
            for forces in self._channels.values():
                for v, f in forces.items():
                    loads[v] = loads.get(v, 0.0) + f
            self._problem = DistributedStatic(
                self.part, self.material, density=self.density, thickness=self.thickness, fixed=fixed,
                fixed_values=np.array([self._fixed[v] for v in fixed]).reshape(len(fixed), self.dim),
                sliding=sliding,
                sliding_directions=np.array([self._sliding[v][0] for v in sliding]).reshape(len(sliding), self.dim),
                sliding_anchors=np.array([self._sliding[v][1] for v in sliding]).reshape(len(sliding), self.dim),
                forces={v: loads[v] for v in sorted(loads)}, gravity=self._gravity)
            self._problem_conditions = conditions
        self._problem.set_local_displacement(self._displacement)
        self._edits_seen = self._edits
        return self._problem

    def gather_into_body(self, problem: DistributedStatic) -> None:
        """The solve's answer, this rank's vertices, into the body's displacement."""
        self._displacement = problem.local_displacement()
        self._edits_seen = self._edits

    def changed(self) -> bool:
        """Collective: whether some rank's conditions or displacement were set since the latest
        problem() or gather_into_body()."""
        return self.comm.allreduce(int(self._edits != self._edits_seen)) > 0

