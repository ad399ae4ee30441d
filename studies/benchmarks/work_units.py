"""The work unit of the loop benchmarks (issue 49): 1 WU is one product of PETSc's assembled AIJ
tangent of the body's current mesh, timed in the same process as the loop, so that costs per
move compare across machines (whose clock rates differ 2.5×, their WU far less)."""
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
