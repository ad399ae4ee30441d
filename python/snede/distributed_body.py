"""A serial Body solved over MPI ranks (issue 18): what ``StaticSolver(body, ..., comm=...)``
and ``DynamicRelaxation(body, ..., comm=...)`` do, on any number of ranks.

Every rank runs the same script and holds the same serial Body: a body that differs on some
rank (its mesh, constraints, loads or displacement) raises ValueError on every rank, naming
what differs, instead of being ignored for rank 0's (issue 38). Rank 0's mesh is distributed
(``snede.distribute``; a membrane's too), its fixed and sliding vertices and external forces
(gravity and the nodal-force channels, which do not depend on the state) become a
:class:`snede.DistributedStatic` that
starts from the body's displacement, the solve runs on all ranks to the serial solver's
criterion, and the displacement is gathered back into the Body on every rank, so the script
goes on as serially. The distribution is kept while the mesh is unchanged (a cut or a
refinement of the serial body, done on every rank, makes the next solve distribute anew), and
the distributed problem while the conditions are too (the next solve starts from the body's
displacement). What cannot be taken over raises NotImplementedError on every rank: a smoothed
formulation.
"""
from __future__ import annotations

import numpy as np

from snede import _snede
from snede.distributed import DistributedStatic, agreed, distribute
from snede.part_body import PartBody


class DistributedBody:
    """The distributed copy of a serial ``body`` over ``comm`` (collective); ``part`` is this
    rank's part of the latest distribution (None before the first)."""

    def __init__(self, body, comm):
        self.body, self.comm = body, comm
        self.part, self._revision, self._last = None, None, None
        self._problem, self._conditions = None, None

    def problem(self) -> DistributedStatic:
        """A DistributedStatic with the body's current conditions, on the mesh as it is now,
        starting from the body's displacement (the previous one while mesh and conditions are
        unchanged). Every rank's body must be rank 0's: one that differs (a load, a fixed vertex, an edit
        made on some ranks only) makes every rank raise ValueError naming what differs."""
        body, comm = self.body, self.comm
        inputs = _inputs(body)
        self._require_same_on_every_rank({name: value for name, value in inputs.items() if name != "gravity"})
        # The gravity is the loads less the nodal forces, comparable once those agree.
        self._require_same_on_every_rank({"gravity": inputs["gravity"]})
        fixed, anchors, _ = body._model.constraint_table()
        sliding, directions, sliding_anchors = _snede.sliding_lines(body._model)
        if body.formulation != "p1":
            raise NotImplementedError(f"a solve on {comm.size} MPI ranks: formulation {body.formulation!r} is not "
                                      "distributed yet (its vertex patches need two layers of ghost cells); use 'p1'")
        # The meshes are equal; rank 0 decides whether its mesh changed since the last
        # distribution, so that every rank distributes or none does.
        revision = comm.bcast(body.mesh._impl.revision if comm.rank == 0 else None, root=0)
        if self.part is None or revision != self._revision:
            self.part = distribute(body.mesh if comm.rank == 0 else None, comm)
            self._revision, self._problem = revision, None
        conditions = {name: value for name, value in inputs.items() if name != "displacement"}
        if self._problem is None or conditions != self._conditions:
            loads = body.external_forces()
            loaded = np.flatnonzero(np.any(loads != 0, axis=1))
            self._problem = DistributedStatic(self.part, body.material, density=body.density,
                                              thickness=body.thickness, fixed=fixed, fixed_values=anchors,
                                              sliding=sliding, sliding_directions=directions,
                                              sliding_anchors=sliding_anchors,
                                              forces={int(v): f for v, f in zip(loaded, loads[loaded])})
            self._conditions = conditions
        self._problem.set_displacement(body.displacement)  # where the serial solve would start
        self._last = inputs
        return self._problem

    def require_held(self) -> None:
        """The serial body's check that every piece is held (ValueError naming a loose one)."""
        self.body._model.require_held()

    def gather_into_body(self, problem: DistributedStatic) -> None:
        """The answer into the body on every rank; should it not fit one rank's body, every
        rank raises."""
        u = problem.gathered_displacement()

        def assign():
            self.body.displacement = u

        agreed(self.comm, assign)
        self._last = _inputs(self.body)

    def changed(self) -> bool:
        """Collective: whether the body's mesh, conditions or displacement changed on any rank
        since the latest problem() or gather_into_body()."""
        return self.comm.allreduce(int(_inputs(self.body) != self._last)) > 0

    def _require_same_on_every_rank(self, inputs: dict) -> None:
        _snede.require_same_on_every_rank(self.comm.py2f(), f"a Body solved on {self.comm.size} MPI ranks",
                                          list(inputs.items()))


def _inputs(body) -> dict:
    """What a distributed solve of ``body`` is made of, as bytes, by the names an error gives
    when the ranks' bodies differ."""
    mesh = body.mesh
    fixed, anchors, _ = body._model.constraint_table()
    sliding, directions, sliding_anchors = _snede.sliding_lines(body._model)
    channels = {name: body.external_forces(name) for name in body.load_channels}
    loads = body.external_forces()
    return {"mesh": mesh.points.tobytes() + mesh.cells.tobytes(), "fixed vertices": fixed.tobytes(),
            "prescribed displacements": anchors.tobytes(),
            "sliding vertices": sliding.tobytes() + directions.tobytes() + sliding_anchors.tobytes(),
            "nodal forces": b"".join(name.encode() + b"\0" + f.tobytes() for name, f in sorted(channels.items())),
            "displacement": body.displacement.tobytes(),
            "gravity": (loads - sum(channels.values(), np.zeros_like(loads))).tobytes()}


def on_ranks(body, comm):
    """What a solver of ``body`` runs on over MPI ranks: a :class:`snede.PartBody` itself (on its
    part's communicator), a serial Body given a communicator (``comm`` or the body's own) as a
    :class:`DistributedBody`, or None: a serial solve."""
    if isinstance(body, PartBody):
        if comm is not None and comm is not body.comm:
            raise ValueError("a PartBody is solved on its part's communicator; leave comm out")
        return body
    comm = getattr(body, "comm", None) if comm is None else comm
    return None if comm is None else DistributedBody(body, comm)


class RunsOnRanks:
    """Mixed into the serial solvers: ``part``, and a guard on what only the serial solver has.
    The solver sets ``_distributed`` (a DistributedBody or None) and ``_impl``, the engine object
    it wraps (None when distributed, until its solve makes one); reading ``_impl`` while it is
    None raises NotImplementedError, ``_on_ranks`` naming what remains available then."""

    _on_ranks = "solve() and part"
    _wrapped = None

    @property
    def part(self):
        """This rank's :class:`snede.DistributedMesh` when given a communicator (after the
        first solve), else None."""
        return None if self._distributed is None else self._distributed.part

    @property
    def _impl(self):
        if self._wrapped is None:
            raise NotImplementedError(f"this {type(self).__name__} runs on MPI ranks (comm): only {self._on_ranks} "
                                      "are available")
        return self._wrapped

    @_impl.setter
    def _impl(self, engine_object) -> None:
        self._wrapped = engine_object
