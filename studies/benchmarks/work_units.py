"""The work unit of the loop benchmarks (issue 49): 1 WU is one product of PETSc's assembled AIJ
tangent of the body's current mesh, timed in the same process as the loop, so that costs per
move compare across machines (whose clock rates differ 2.5×, their WU far less). Times vary by
±20–35 % between runs on a shared virtual machine (the product's speed depends on what else is in
the caches); the flops a solve logs do not, so ``work_unit_flops`` counts the same unit in flops
(2 per stored entry), for comparisons of the solve's arithmetic that one run can decide."""
import time


def work_unit_seconds(body, repeats: int = 30) -> float:
    """The fastest of `repeats` products y = J x of `body.assemble_tangent(format="aij")` (s)."""
    tangent = body.assemble_tangent(format="aij")
    x, y = tangent.createVecs()
    x.setRandom()
    fastest = float("inf")
    for _ in range(repeats):
        began = time.perf_counter()
        tangent.mult(x, y)
        fastest = min(fastest, time.perf_counter() - began)
    for petsc_object in (x, y, tangent):
        petsc_object.destroy()
    return fastest


def work_unit_flops(body) -> float:
    """The flops of one product y = J x of `body.assemble_tangent(format="aij")`: 2 per stored entry."""
    tangent = body.assemble_tangent(format="aij")
    entries = tangent.getInfo()["nz_used"]
    tangent.destroy()
    return 2.0 * entries
