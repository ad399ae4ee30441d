"""The matrix-free tangent against assembled matrices (§2.3, §3.3, §4.6): time per product,
assembly cost and memory of the MatShell against PETSc's AIJ and BAIJ (block size 3) on
Kuhn boxes, and CG iterations per second on the 7986-element cube of §3.3 without a
preconditioner, with Jacobi and with GAMG.

    .venv/bin/python -m studies.experiments.performance [--quick] [--out DIR]

Writes performance.md, performance.csv (one row per measurement, column ``part``) and
performance.png (time per product and bytes per tetrahedron against size).
"""
from __future__ import annotations

import time

import numpy as np

import snede
from snede import PETSc
from studies.experiments.common import (
    Column, PageTemplate, best_seconds, markdown_table, options_prefix, parse_arguments, pyplot, save_figure,
    write_csv,
)

YOUNG, POISSON = 1e6, 0.25  # §3.3
CUBE_DIVISIONS = 11  # 6·11³ = 7986 tetrahedra on 12³ = 1728 nodes: the cube of Figure 3.12
DILATION = 10.0  # N per metre from the face centre, on the loaded face
CG_RTOL = 1e-3  # §3.3: ‖r‖ < 1e-3‖f_ext‖
THESIS_ITERATIONS_PER_SECOND = 55  # §3.3, Pentium III 1 GHz
THESIS_ITERATIONS = (100, 300)
STIFFNESS_SAMPLE = 200  # element_stiffness calls timed per size (the public call is O(n_cells), see below)
# Per-element data the kernels stream (engine/fem/element_stream): Z⁻¹ (9 doubles), |τ| and the
# four vertex ids (int32)
REFERENCE_BYTES_PER_TET = 96


def lame(young: float, poisson: float) -> tuple[float, float]:
    return young * poisson / ((1 + poisson) * (1 - 2 * poisson)), young / (2 * (1 + poisson))


def linear_elastic_element_matrices(points: np.ndarray, cells: np.ndarray, young: float, poisson: float,
                                    chunk: int = 65536) -> np.ndarray:
    """Stiffness of every linear tetrahedron, vectorised over cells, (n_cells, 12, 12), dofs
    ordered by the cell's vertices then components (as ``Body.element_stiffness``):
    K_(a,i)(b,j) = |τ| (λ ∂_i N_a ∂_j N_b + μ ∂_j N_a ∂_i N_b + μ δ_ij ∇N_a·∇N_b)."""
    lam, mu = lame(young, poisson)
    matrices = np.empty((len(cells), 12, 12))
    for start in range(0, len(cells), chunk):
        corners = points[cells[start:start + chunk]]  # (n, 4, 3)
        e1, e2, e3 = (corners[:, k] - corners[:, 0] for k in (1, 2, 3))
        # ∇N_1..∇N_3 are the columns of [e1 e2 e3]ᵀ⁻¹: cross products over the determinant
        normals = np.stack([np.cross(e2, e3), np.cross(e3, e1), np.cross(e1, e2)], axis=1)
        determinant = np.einsum("ni,ni->n", e1, normals[:, 0])
        gradients = normals / determinant[:, None, None]
        gradients = np.concatenate([-gradients.sum(axis=1, keepdims=True), gradients], axis=1)  # (n, 4, 3)
        g = gradients * np.sqrt(np.abs(determinant) / 6.0)[:, None, None]  # √|τ| ∇N_a
        products = g[:, :, :, None, None] * g[:, None, None, :, :]  # [n, a, i, b, j] = g_ai g_bj
        dots = np.einsum("nak,nbk->nab", g, g)
        block = lam * products + mu * np.swapaxes(products, 1, 3)
        block += mu * dots[:, :, None, :, None] * np.eye(3)[None, None, :, None, :]
        matrices[start:start + chunk] = block.reshape(-1, 12, 12)
    return matrices


def node_adjacency(cells: np.ndarray, n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Compressed rows of the node graph including the diagonal: (indptr, indices), int32."""
    pairs = np.stack(np.meshgrid(np.arange(4), np.arange(4), indexing="ij"), axis=-1).reshape(-1, 2)
    rows = cells[:, pairs[:, 0]].ravel().astype(np.int64)
    cols = cells[:, pairs[:, 1]].ravel().astype(np.int64)
    keys = np.unique(rows * n_points + cols)
    indptr = np.zeros(n_points + 1, dtype=PETSc.IntType)
    np.cumsum(np.bincount(keys // n_points, minlength=n_points), out=indptr[1:])
    return indptr, (keys % n_points).astype(PETSc.IntType)


def scalar_pattern(indptr: np.ndarray, indices: np.ndarray, block: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The dof-level compressed rows of a block pattern with block × block dense blocks: dof
    row (r, i) has the dof columns of node row r, (c, j) for every node c of the row and j < block."""
    block_columns = (block * indices[:, None].astype(np.int64) + np.arange(block)).ravel()  # node rows' dof columns
    lengths = np.repeat(block * np.diff(indptr).astype(np.int64), block)  # per dof row
    starts = np.repeat(block * indptr[:-1].astype(np.int64), block)  # where its node row's columns begin
    scalar_indptr = np.zeros(len(lengths) + 1, dtype=np.int64)
    np.cumsum(lengths, out=scalar_indptr[1:])
    positions = np.arange(scalar_indptr[-1]) + np.repeat(starts - scalar_indptr[:-1], lengths)
    return scalar_indptr.astype(PETSc.IntType), block_columns[positions].astype(PETSc.IntType)


def assemble(kind: str, n_points: int, cells: np.ndarray, element_matrices: np.ndarray, pattern) -> tuple:
    """AIJ or BAIJ(3) from element matrices: preallocation from the node graph, then one
    MatSetValues per element (petsc4py's RCV loop, in C) with ADD_VALUES, then assembly.
    Returns (mat, preallocation seconds, insertion + assembly seconds)."""
    n = 3 * n_points
    start = time.perf_counter()
    if kind == "AIJ":
        mat = PETSc.Mat().createAIJ((n, n), bsize=3, csr=scalar_pattern(*pattern))
    else:
        mat = PETSc.Mat().createBAIJ((n, n), 3, csr=pattern)
    preallocated = time.perf_counter()
    nodes = np.ascontiguousarray(cells, dtype=PETSc.IntType)
    if kind == "AIJ":
        dofs = (3 * nodes[:, :, None] + np.arange(3, dtype=PETSc.IntType)).reshape(-1, 12)
        mat.setValuesRCV(dofs, dofs, element_matrices, addv=PETSc.InsertMode.ADD_VALUES)
    else:
        mat.setValuesBlockedRCV(nodes, nodes, element_matrices, addv=PETSc.InsertMode.ADD_VALUES)
    mat.assemble()
    assembled = time.perf_counter()
    return mat, preallocated - start, assembled - preallocated


def matrix_bytes(mat, kind: str) -> int:
    """Values and column indices plus row pointers (PETSc 3.18's MatGetInfo reports memory 0
    for sequential AIJ/BAIJ): AIJ nz·(8 + 4) + (rows + 1)·4, BAIJ nz/9·(72 + 4) + (rows/3 + 1)·4."""
    nonzeros, rows = mat.getInfo()["nz_used"], mat.getSize()[0]
    if kind == "AIJ":
        return int(nonzeros * 12 + (rows + 1) * 4)
    return int(nonzeros / 9 * 76 + (rows / 3 + 1) * 4)


def element_stiffness_loop(body, rows: np.ndarray) -> tuple[np.ndarray, float]:
    """Element matrices of ``rows`` through the public ``Body.element_stiffness``, and the
    seconds per call."""
    u = np.zeros((body.mesh.n_points, 3))
    start = time.perf_counter()
    matrices = np.array([body.element_stiffness(int(row), u) for row in rows])
    return matrices, (time.perf_counter() - start) / len(rows)


def product_rows(divisions, repeats: int) -> list[dict]:
    """For each Kuhn box: element matrices, AIJ and BAIJ assembly, memory and time per product
    against the shell, with the relative difference of the products."""
    rows = []
    for n in divisions:
        mesh = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))
        body = snede.Body(mesh, snede.LinearElastic(YOUNG, POISSON))
        points, cells = mesh.points, mesh.cells
        start = time.perf_counter()
        element_matrices = linear_elastic_element_matrices(points, cells, YOUNG, POISSON)
        vectorised_seconds = time.perf_counter() - start
        sample = np.linspace(0, mesh.n_cells - 1, min(STIFFNESS_SAMPLE, mesh.n_cells)).astype(int)
        engine_matrices, seconds_per_call = element_stiffness_loop(body, sample)
        element_matrix_error = float(np.max(np.abs(engine_matrices - element_matrices[sample]))
                                     / np.max(np.abs(engine_matrices)))
        start = time.perf_counter()
        pattern = node_adjacency(cells, mesh.n_points)
        pattern_seconds = time.perf_counter() - start

        shell = body._model.tangent_mat
        x, y_shell = shell.createVecs()
        x.setArray(np.random.default_rng(n).standard_normal(x.getSize()))
        shell_seconds = best_seconds(lambda: shell.mult(x, y_shell), repeats)
        tangent_flops = body.flops_per_element()["tangent"] * mesh.n_cells
        common = {"part": "product", "divisions": n, "tetrahedra": mesh.n_cells, "nodes": mesh.n_points,
                  "dofs": 3 * mesh.n_points}
        rows.append({**common, "format": "shell", "seconds_per_product": shell_seconds,
                     "flops_per_product": tangent_flops, "bytes": REFERENCE_BYTES_PER_TET * mesh.n_cells,
                     "mesh_bytes": mesh.memory_bytes(), "relative_difference": 0.0,
                     "element_matrix_seconds_vectorised": vectorised_seconds,
                     "element_stiffness_call_seconds": seconds_per_call,
                     "element_stiffness_loop_seconds_estimate": seconds_per_call * mesh.n_cells,
                     "element_matrix_relative_error": element_matrix_error, "pattern_seconds": pattern_seconds})
        for kind in ("AIJ", "BAIJ"):
            mat, preallocation, insertion = assemble(kind, mesh.n_points, cells, element_matrices, pattern)
            y = mat.createVecLeft()
            seconds = best_seconds(lambda: mat.mult(x, y), repeats)
            difference = (y - y_shell).norm() / y_shell.norm()
            rows.append({**common, "format": kind, "seconds_per_product": seconds,
                         "flops_per_product": 2 * mat.getInfo()["nz_used"], "bytes": matrix_bytes(mat, kind),
                         "nonzeros": int(mat.getInfo()["nz_used"]),
                         "relative_difference": difference, "preallocation_seconds": preallocation,
                         "insertion_assembly_seconds": insertion})
            mat.destroy()
        del element_matrices
        print(f"{mesh.n_cells} tetrahedra: shell {1e3 * shell_seconds:.2f} ms, AIJ "
              f"{1e3 * rows[-2]['seconds_per_product']:.2f} ms, BAIJ {1e3 * rows[-1]['seconds_per_product']:.2f} ms",
              flush=True)
    return rows


# -- CG on the §3.3 cube ---------------------------------------------------------------------------
def cube_body() -> tuple[snede.Body, np.ndarray]:
    """The §3.3 cube: 7986 tetrahedra, 1728 nodes, E = 1e6, ν = 0.25, fixed at x = 0, the
    face x = 1 pulled outwards from its centre (a dilating load). Returns (body, fixed mask)."""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (CUBE_DIVISIONS,) * 3)
    body = snede.Body(mesh, snede.LinearElastic(YOUNG, POISSON))
    fixed = np.isclose(mesh.points[:, 0], 0.0)
    body.fix(fixed)
    loaded = np.flatnonzero(np.isclose(mesh.points[:, 0], 1.0))
    radial = mesh.points[loaded] - [1.0, 0.5, 0.5]
    body.add_nodal_force(loaded, DILATION * radial)
    return body, fixed


PRECONDITIONER_LABELS = {"jacobi-shell": "Jacobi (assembled diagonal, Python PC)",
                         "gamg": "GAMG + rigid-body near-null space"}
KSP_REASONS = {value: name for name, value in vars(PETSc.KSP.ConvergedReason).items() if isinstance(value, int)}


class DiagonalScaling:
    """A petsc4py Python PC: y = D⁻¹x (Jacobi from an assembled diagonal)."""

    def __init__(self, inverse_diagonal):
        self.inverse_diagonal = inverse_diagonal

    def apply(self, pc, x, y):
        y.pointwiseMult(self.inverse_diagonal, x)


def krylov_solve(operator, rhs, preconditioner: str, label: str, inverse_diagonal=None) -> tuple:
    """KSPCG until ‖b − Ax‖ ≤ 1e-3‖b‖ (unpreconditioned norm, zero initial guess).
    Returns (solution, iterations, setup seconds, solve seconds, reason)."""
    ksp = PETSc.KSP().create()
    ksp.setOptionsPrefix(options_prefix(label))
    ksp.setType("cg")
    ksp.setOperators(operator)
    ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
    ksp.setTolerances(rtol=CG_RTOL, atol=0.0, max_it=100000)
    pc = ksp.getPC()
    if preconditioner == "jacobi-shell":
        pc.setType("python")
        pc.setPythonContext(DiagonalScaling(inverse_diagonal))
    else:
        pc.setType(preconditioner)
    ksp.setFromOptions()
    solution = rhs.duplicate()
    solution.set(0.0)
    start = time.perf_counter()
    ksp.setUp()
    setup = time.perf_counter() - start
    start = time.perf_counter()
    ksp.solve(rhs, solution)
    solve = time.perf_counter() - start
    result = (solution, ksp.getIterationNumber(), setup, solve, KSP_REASONS[ksp.getConvergedReason()])
    ksp.destroy()
    return result


def constrained_matrix(body, fixed: np.ndarray, kind: str):
    """P K P + (I − P) assembled: the stiffness with the fixed dofs' rows and columns replaced
    by the identity, the operator the shell applies. Returns (mat, assembly seconds)."""
    mesh = body.mesh
    start = time.perf_counter()
    element_matrices = linear_elastic_element_matrices(mesh.points, mesh.cells, YOUNG, POISSON)
    pattern = node_adjacency(mesh.cells, mesh.n_points)
    mat, _, _ = assemble(kind, mesh.n_points, mesh.cells, element_matrices, pattern)
    fixed_dofs = (3 * np.flatnonzero(fixed)[:, None] + np.arange(3)).ravel().astype(PETSc.IntType)
    mat.zeroRowsColumns(fixed_dofs, diag=1.0)
    return mat, time.perf_counter() - start


def rigid_body_modes(points: np.ndarray):
    coordinates = PETSc.Vec().createWithArray(np.ascontiguousarray(points).ravel().copy())
    coordinates.setBlockSize(3)
    return PETSc.NullSpace().createRigidBody(coordinates)


def cube_cg_rows() -> list[dict]:
    """§3.3's relaxation speed: CG iterations and iterations per second on the cube."""
    body, fixed = cube_body()
    shell = body._model.tangent_mat
    rhs = shell.createVecRight()
    rhs.setArray(np.where(np.repeat(fixed, 3), 0.0, body.external_forces().ravel()))
    result = snede.StaticSolver(body, "cg", preconditioner="none", rtol=CG_RTOL, criterion="6.8", max_iterations=100000,
                                options_prefix=options_prefix("cube_shell")).solve()
    shell_solution = body.displacement.ravel()
    aij, aij_assembly = constrained_matrix(body, fixed, "AIJ")
    baij, baij_assembly = constrained_matrix(body, fixed, "BAIJ")
    aij.setNearNullSpace(rigid_body_modes(body.mesh.points))
    inverse_diagonal = aij.getDiagonal()
    inverse_diagonal.reciprocal()
    common = {"part": "cube_cg", "tetrahedra": body.mesh.n_cells, "nodes": body.mesh.n_points}
    rows = [{**common, "operator": "shell", "preconditioner": "none (snede StaticSolver cg)",
             "iterations": result.iterations, "setup_seconds": 0.0, "solve_seconds": result.seconds,
             "reason": result.reason, "solution_difference": 0.0, "assembly_seconds": 0.0}]
    runs = [("shell", shell, "none", 0.0), ("shell", shell, "jacobi-shell", aij_assembly),
            ("AIJ", aij, "none", aij_assembly), ("AIJ", aij, "jacobi", aij_assembly),
            ("BAIJ", baij, "pbjacobi", baij_assembly), ("AIJ", aij, "gamg", aij_assembly)]
    for operator_name, operator, preconditioner, assembly in runs:
        solution, iterations, setup, solve, reason = krylov_solve(operator, rhs, preconditioner,
                                                                  f"cube_{operator_name}_{preconditioner}",
                                                                  inverse_diagonal)
        residual = rhs.duplicate()
        shell.mult(solution, residual)
        residual.aypx(-1.0, rhs)
        rows.append({**common, "operator": operator_name,
                     "preconditioner": PRECONDITIONER_LABELS.get(preconditioner, preconditioner),
                     "iterations": iterations, "setup_seconds": setup, "solve_seconds": solve, "reason": reason,
                     "assembly_seconds": assembly, "relative_residual": residual.norm() / rhs.norm(),
                     "solution_difference": float(np.linalg.norm(solution.getArray() - shell_solution)
                                                  / np.linalg.norm(shell_solution))})
    for row in rows:
        row["iterations_per_second"] = row["iterations"] / row["solve_seconds"]
        row["thesis_iterations_per_second"] = THESIS_ITERATIONS_PER_SECOND
    return rows


# -- output --------------------------------------------------------------------------------------
def plot(rows, path) -> None:
    plt = pyplot()
    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for kind, marker in (("shell", "o"), ("AIJ", "s"), ("BAIJ", "^")):
        selected = [row for row in rows if row["format"] == kind]
        tets = [row["tetrahedra"] for row in selected]
        left.loglog(tets, [1e3 * row["seconds_per_product"] for row in selected], marker + "-", label=kind)
        label = "shell (reference data)" if kind == "shell" else kind
        right.loglog(tets, [row["bytes"] / row["tetrahedra"] for row in selected], marker + "-", label=label)
    shell = [row for row in rows if row["format"] == "shell"]
    right.loglog([row["tetrahedra"] for row in shell], [row["mesh_bytes"] / row["tetrahedra"] for row in shell],
                 "x:", color="0.4", label="mesh (both need it)")
    left.set_ylabel("time per product [ms] (best of several)")
    right.set_ylabel("bytes per tetrahedron")
    for ax in (left, right):
        ax.set_xlabel("tetrahedra")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    left.set_title("tangent action: MatShell against MatMult")
    right.set_title("memory")
    save_figure(figure, path, 110)


PRODUCT_COLUMNS = [
    Column("tetrahedra", "tetrahedra"), Column("dofs", "dofs"), Column("format", "format"),
    Column("ms_per_product", "ms / product", "{:.3f}"), Column("ns_per_tet", "ns / tet", "{:.1f}"),
    Column("speed_vs_shell", "× shell speed", "{:.2f}"), Column("mflop_per_s", "MFLOP/s", "{:.0f}"),
    Column("bytes_per_tet", "bytes / tet", "{:.0f}"),
    Column("relative_difference", "‖Ax − Jx‖/‖Jx‖", "{:.1e}")]
ASSEMBLY_COLUMNS = [
    Column("tetrahedra", "tetrahedra"), Column("element_matrix_seconds_vectorised", "element matrices, numpy [s]",
                                               "{:.3f}"),
    Column("element_stiffness_call_us", "element_stiffness call [µs]", "{:.1f}"),
    Column("element_stiffness_loop_seconds_estimate", "element_stiffness loop, all cells [s] (est.)", "{:.1f}"),
    Column("pattern_seconds", "node graph [s]", "{:.3f}"),
    Column("aij_preallocation", "AIJ prealloc [s]", "{:.3f}"),
    Column("aij_insertion", "AIJ set+assemble [s]", "{:.3f}"),
    Column("baij_preallocation", "BAIJ prealloc [s]", "{:.3f}"),
    Column("baij_insertion", "BAIJ set+assemble [s]", "{:.3f}"),
    Column("products_to_repay_aij", "shell products ≙ AIJ assembly", "{:.0f}"),
    Column("element_matrix_relative_error", "numpy vs element_stiffness", "{:.1e}")]
CG_COLUMNS = [
    Column("operator", "operator"), Column("preconditioner", "preconditioner"), Column("iterations", "iterations"),
    Column("setup_seconds", "PC setup [s]", "{:.4f}"), Column("solve_seconds", "solve [s]", "{:.4f}"),
    Column("iterations_per_second", "iterations/s", "{:.0f}"), Column("assembly_seconds", "assembly [s]", "{:.3f}"),
    Column("solution_difference", "‖x − x_shell‖/‖x_shell‖", "{:.1e}"), Column("reason", "reason")]


def product_table(rows) -> list[dict]:
    shell_time = {row["tetrahedra"]: row["seconds_per_product"] for row in rows if row["format"] == "shell"}
    return [{**row, "ms_per_product": 1e3 * row["seconds_per_product"],
             "ns_per_tet": 1e9 * row["seconds_per_product"] / row["tetrahedra"],
             "speed_vs_shell": shell_time[row["tetrahedra"]] / row["seconds_per_product"],
             "mflop_per_s": row["flops_per_product"] / row["seconds_per_product"] / 1e6,
             "bytes_per_tet": row["bytes"] / row["tetrahedra"]}
            for row in rows]


def assembly_table(rows) -> list[dict]:
    table = []
    for shell in (row for row in rows if row["format"] == "shell"):
        aij = next(r for r in rows if r["format"] == "AIJ" and r["tetrahedra"] == shell["tetrahedra"])
        baij = next(r for r in rows if r["format"] == "BAIJ" and r["tetrahedra"] == shell["tetrahedra"])
        assembly = shell["element_matrix_seconds_vectorised"] + shell["pattern_seconds"] + \
            aij["preallocation_seconds"] + aij["insertion_assembly_seconds"]
        table.append({**shell, "element_stiffness_call_us": 1e6 * shell["element_stiffness_call_seconds"],
                      "aij_preallocation": aij["preallocation_seconds"],
                      "aij_insertion": aij["insertion_assembly_seconds"],
                      "baij_preallocation": baij["preallocation_seconds"],
                      "baij_insertion": baij["insertion_assembly_seconds"],
                      "products_to_repay_aij": assembly / shell["seconds_per_product"]})
    return table


def total_seconds(row) -> float:
    return row["assembly_seconds"] + row["setup_seconds"] + row["solve_seconds"]


def describe(products, assemblies, cube, quick: bool, divisions) -> str:
    """performance.md: studies/templates/performance.md filled with the three tables and the
    numbers the comparisons quote."""
    template = PageTemplate("performance")
    largest = max(row["tetrahedra"] for row in products)
    at_largest = {row["format"]: row for row in products if row["tetrahedra"] == largest}
    shell, aij = at_largest["shell"], at_largest["AIJ"]
    shell_cg = cube[0]
    gamg = next(row for row in cube if row["preconditioner"].startswith("GAMG"))
    jacobi = next(row for row in cube if row["operator"] == "AIJ" and row["preconditioner"] == "jacobi")
    aij_plain = next(row for row in cube if row["operator"] == "AIJ" and row["preconditioner"] == "none")
    repay = [row["products_to_repay_aij"] for row in assemblies]
    in_range = THESIS_ITERATIONS[0] <= shell_cg["iterations"] <= THESIS_ITERATIONS[1]
    return template.page(
        quick_flag=" --quick" if quick else "",
        run=template.snippet("quick_run") if quick else template.snippet(
            "full_run", divisions=", ".join(map(str, divisions)), largest=largest),
        young=YOUNG, poisson=POISSON, reference_bytes=REFERENCE_BYTES_PER_TET,
        product_table=markdown_table(products, PRODUCT_COLUMNS),
        call_growth=assemblies[-1]["element_stiffness_call_us"] / assemblies[0]["element_stiffness_call_us"],
        assembly_table=markdown_table(assemblies, ASSEMBLY_COLUMNS),
        tetrahedra=shell_cg["tetrahedra"], nodes=shell_cg["nodes"], dilation=DILATION, rtol=CG_RTOL,
        cg_table=markdown_table(cube, CG_COLUMNS),
        iterations=shell_cg["iterations"], iterations_per_second=shell_cg["iterations_per_second"],
        iterations_range=template.snippet("inside_range" if in_range else "outside_range"),
        rate_ratio=shell_cg["iterations_per_second"] / THESIS_ITERATIONS_PER_SECOND,
        jacobi_iterations=jacobi["iterations"], gamg_iterations=gamg["iterations"],
        gamg_setup=gamg["setup_seconds"], gamg_assembly=gamg["assembly_seconds"],
        shell_seconds=shell_cg["solve_seconds"], aij_seconds=total_seconds(aij_plain),
        jacobi_seconds=total_seconds(jacobi), gamg_seconds=total_seconds(gamg),
        largest=largest, aij_ms=1e3 * aij["seconds_per_product"], baij_ms=1e3 * at_largest["BAIJ"]["seconds_per_product"],
        shell_ms=1e3 * shell["seconds_per_product"], aij_bytes_per_tet=aij["bytes"] / largest,
        mesh_bytes_per_tet=shell["mesh_bytes"] / largest, flops_per_tet=shell["flops_per_product"] / largest,
        gflops=shell["mflop_per_s"] / 1e3, aij_mb=aij["bytes"] / 1e6,
        aij_gb_per_s=aij["bytes"] / aij["seconds_per_product"] / 1e9, repay_min=min(repay), repay_max=max(repay),
        largest_difference=max(row["relative_difference"] for row in products),
        solution_difference=aij_plain["solution_difference"], aij_iterations=aij_plain["iterations"])


def main(argv=None) -> dict:
    arguments = parse_arguments(__doc__, argv)
    divisions = (4, 8) if arguments.quick else (12, 18, 26, 38, 55)
    products = product_table(product_rows(divisions, repeats=3 if arguments.quick else 7))
    print(markdown_table(products, PRODUCT_COLUMNS), flush=True)
    assemblies = assembly_table(products)
    print(markdown_table(assemblies, ASSEMBLY_COLUMNS), flush=True)
    cube = cube_cg_rows()
    print(markdown_table(cube, CG_COLUMNS), flush=True)
    out = arguments.out
    write_csv(out / "performance.csv", products + cube)
    plot(products, out / "performance.png")
    (out / "performance.md").write_text(describe(products, assemblies, cube, arguments.quick, divisions))
    print(f"wrote {out / 'performance.md'}, performance.csv, performance.png")
    return {"products": products, "assemblies": assemblies, "cube": cube}


if __name__ == "__main__":
    main()
