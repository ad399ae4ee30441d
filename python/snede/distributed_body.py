"""A serial Body solved over MPI ranks (issue 18): what ``StaticSolver(body, ..., comm=...)``
and ``DynamicRelaxation(body, ..., comm=...)`` do, on any number of ranks.

Every rank runs the same script and holds the same serial Body; rank 0's is the one used. Its
mesh is distributed (``snede.distribute``), its fixed vertices and external forces (gravity and
the nodal-force channels, which do not depend on the state) become a
:class:`snede.DistributedStatic` that starts from the body's displacement, the solve runs on all
ranks to the serial solver's criterion, and the displacement is gathered back into the Body on
every rank, so the script goes on as serially. The distribution is kept while the mesh is
unchanged (a cut or a refinement of the serial body, done on every rank, makes the next solve
distribute anew). What cannot be taken over raises
NotImplementedError on every rank: sliding constraints and membranes.
"""
from __future__ import annotations

import numpy as np

from snede.distributed import DistributedStatic, agreed, distribute


class DistributedBody:
    """The distributed copy of a serial ``body`` over ``comm`` (collective); ``part`` is this
    rank's part of the latest distribution (None before the first)."""

    def __init__(self, body, comm):
        self.body, self.comm = body, comm
        self.part, self._revision, self._last = None, None, None

    def problem(self) -> DistributedStatic:
        """A DistributedStatic with the body's current conditions, on the mesh as it is now."""
        body, comm = self.body, self.comm
        why = None
        if comm.rank == 0:
            fixed, anchors, sliding = body._model.constraint_table()
            loads = body.external_forces()
            loaded = np.flatnonzero(np.any(loads != 0, axis=1))
            if body.mesh.is_surface:
                why = "membranes (surface meshes) are not distributed yet"
            elif len(sliding):
                why = f"sliding constraints ({len(sliding)} vertices) are not distributed yet; fix them instead"
            conditions = (why, fixed, anchors, loaded, loads[loaded], body.mesh._impl.revision, body.displacement)
            self._last = _fingerprint(body.mesh._impl.revision, fixed, anchors, loads, body.displacement)
        why, fixed, anchors, loaded, loads, revision, start = comm.bcast(conditions if comm.rank == 0 else None, root=0)
        if why is not None:
            raise NotImplementedError(f"a solve on {comm.size} MPI ranks: {why}")
        if self.part is None or revision != self._revision:
            self.part = distribute(body.mesh if comm.rank == 0 else None, comm)
            self._revision = revision
        problem = DistributedStatic(self.part, body.material, density=body.density, thickness=body.thickness,
                                    fixed=fixed, fixed_values=anchors, forces={int(v): f for v, f in zip(loaded, loads)})
        problem.set_displacement(start)  # where the serial solve would start
        return problem

    def gather_into_body(self, problem: DistributedStatic) -> None:
        """The answer into the body on every rank; a rank whose body is not rank 0's (edited on
        one rank only) makes every rank raise."""
        u = problem.gathered_displacement()

        def assign():
            self.body.displacement = u

        agreed(self.comm, assign)
        self._last = self._state() if self.comm.rank == 0 else None

    def changed(self) -> bool:
        """Collective: whether the body's mesh, conditions or displacement changed since the
        latest problem() or gather_into_body() (rank 0's body decides)."""
        now = self._state() if self.comm.rank == 0 else None
        return bool(self.comm.bcast(now != self._last if self.comm.rank == 0 else None, root=0))

    def _state(self):
        body = self.body
        fixed, anchors, _ = body._model.constraint_table()
        return _fingerprint(body.mesh._impl.revision, fixed, anchors, body.external_forces(), body.displacement)


def _fingerprint(revision, fixed, anchors, loads, displacement):
    """What a problem is made of, to tell whether the body changed since."""
    return revision, fixed.tobytes(), anchors.tobytes(), loads.tobytes(), displacement.tobytes()


class RunsOnRanks:
    """Mixed into the serial solvers: ``part``, and a guard on what only the serial solver has.
    The solver sets ``_distributed`` (a DistributedBody or None) and ``_impl`` (None when
    distributed); ``_on_ranks`` names what remains available then."""

    _on_ranks = "solve() and part"

    @property
    def part(self):
        """This rank's :class:`snede.DistributedMesh` when given a communicator (after the
        first solve), else None."""
        return None if self._distributed is None else self._distributed.part

    @property
    def _engine(self):
        if self._impl is None:
            raise NotImplementedError(f"this {type(self).__name__} runs on MPI ranks (comm): only {self._on_ranks} "
                                      "are available")
        return self._impl
