"""The result every snede solve returns."""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class SolveResult:
    """``converged`` is False whenever the final state is not trustworthy: PETSc reported
    divergence, the iteration limit was hit, or the state holds NaN/Inf or an inverted
    element of a material that forbids inversion. ``reason`` is PETSc's converged reason
    (e.g. ``CONVERGED_FNORM_RELATIVE``, ``DIVERGED_LINE_SEARCH``) or snede's own
    (``DIVERGED_INVERTED_ELEMENTS``, ``DIVERGED_NONFINITE_STATE``, ``DIVERGED_BLOW_UP``).

    ``seconds`` is the solve's wall time; ``flops`` counts the floating-point operations PETSc
    logged during the solve on this rank, in FLOP (``str(result)`` shows them in MFLOP, 10⁶ FLOP)."""

    converged: bool
    reason: str
    iterations: int
    residual_norm: float
    energy: float
    seconds: float
    flops: float
    linear_iterations: int = 0
    initial_residual_norm: float = 0.0
    tolerance: float = 0.0
    residual_history: list = field(default_factory=list, repr=False)

    @classmethod
    def _from_engine(cls, r) -> "SolveResult":
        return cls(converged=r.converged, reason=r.reason, iterations=r.iterations,
                   residual_norm=r.residual_norm, energy=r.energy, seconds=r.seconds, flops=r.flops,
                   linear_iterations=r.linear_iterations, initial_residual_norm=r.initial_residual_norm,
                   tolerance=r.tolerance, residual_history=list(r.residual_history))

    def __str__(self) -> str:
        state = "converged" if self.converged else "NOT converged"
        return (f"{state} ({self.reason}) after {self.iterations} iterations"
                f"{f' ({self.linear_iterations} linear)' if self.linear_iterations else ''}: "
                f"|r| = {self.residual_norm:.3e} (tolerance {self.tolerance:.3e}), energy {self.energy:.6e} J, "
                f"{self.seconds:.3f} s, {self.flops / 1e6:.1f} MFLOP")
