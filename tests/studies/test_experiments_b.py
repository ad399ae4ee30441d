"""The relaxation study (chapter 4) and the matrix-free/assembled comparison, in their --quick
versions: their numbers against independent references (potential energies, assembled
products, rigid-body modes, a Newton reference) and the files they write."""
import numpy as np
import pytest

import snede
from studies.experiments import performance, relaxation

EXPECTED_RELAXATION_FILES = ("relaxation.md", "relaxation.csv", "relaxation_curves.csv", "relaxation_LinearElastic.png",
                             "relaxation_NeoHookean.png", "relaxation_short_edge.png")
EXPECTED_PERFORMANCE_FILES = ("performance.md", "performance.csv", "performance.png")


@pytest.fixture(scope="module")
def relaxation_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("relaxation")
    return out, relaxation.main(["--quick", "--out", str(out)])


@pytest.fixture(scope="module")
def performance_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("performance")
    return out, performance.main(["--quick", "--out", str(out)])


@pytest.fixture(scope="module")
def small_cylinder():
    return relaxation.CylinderMesh.read("small", relaxation.MESHES / "cylinder_small.msh")


# -- relaxation ---------------------------------------------------------------------------------
def test_relaxation_writes_its_outputs(relaxation_run):
    out, _ = relaxation_run
    for name in EXPECTED_RELAXATION_FILES:
        assert (out / name).stat().st_size > 0, name
    text = (out / "relaxation.md").read_text()
    assert "python -m studies.experiments.relaxation --quick" in text
    assert "Where this agrees with the thesis and where not" in text


def test_energy_error_is_the_potential_energy_difference_near_the_reference(small_cylinder):
    """(e,e)_K = ½eᵀK(û)e is Π(û + e) − Π(û) up to O(‖e‖³); Π comes from the energy kernel."""
    reference = relaxation.newton_reference(small_cylinder, relaxation.Case("NeoHookean"))
    assert reference.converged
    direction = np.random.default_rng(1).standard_normal(reference.displacement.shape)
    direction[np.isclose(small_cylinder.points[:, 0], 0.0)] = 0.0
    for scale in (1e-3, 3e-4):
        e = scale * np.abs(reference.displacement).max() * direction
        u = reference.displacement + e
        difference = reference.potential_energy(u) - reference.potential_energy(reference.displacement)
        assert reference.energy_error(u) == pytest.approx(difference, rel=2e-2)


def test_every_relaxation_run_converges_to_the_newton_reference(relaxation_run):
    _, results = relaxation_run
    for row in results["convergence"]:
        assert row["reference_converged"], row
        assert row["converged"], row
        # Within the run's stopping tolerance the state is the reference: relative energy-norm error
        assert np.sqrt(row["final_error"] / row["initial_error"]) < 1e-4, row
        assert abs(row["final_energy_difference"]) < 1e-6 * row["initial_error"], row


def test_energy_error_decreases_along_every_run(relaxation_run):
    _, results = relaxation_run
    for key, curve in results["curves"].items():
        errors = np.asarray(curve.energy_error)
        quarters = [errors[i * len(errors) // 4:(i + 1) * len(errors) // 4].min() for i in range(4)]
        assert all(a > b for a, b in zip(quarters, quarters[1:])), key
        assert errors[-1] < 1e-8 * errors[0], key
        assert np.all(np.diff(curve.mflop) >= 0) and np.all(np.diff(curve.seconds) >= 0), key


def test_recording_does_not_change_the_counted_cost(small_cylinder):
    """The monitor subtracts its own flops: a recorded run costs what an unrecorded one does
    (up to the final verdict's residual and energy evaluation, which only the latter counts)."""
    case = relaxation.Case("NeoHookean")
    reference = relaxation.newton_reference(small_cylinder, case)
    method = relaxation.STATIC_METHODS[0]
    curve = relaxation.static_curve(small_cylinder, case, reference, method, rtol=1e-5)
    body = small_cylinder.body(case.make_material())
    result = snede.StaticSolver(body, "ncg", rtol=1e-5, line_search=method.line_search, ncg_type=method.ncg_type,
                                options_prefix="test_unrecorded_").solve()
    assert curve.iterations[-1] == result.iterations
    assert curve.mflop[-1] == pytest.approx(result.flops / 1e6, rel=0.02)


def test_damping_and_critical_step_are_sensible(relaxation_run):
    _, results = relaxation_run
    grid = set(results["eta_grid"])
    for row in results["damping"]:
        assert row["eta_best"] in grid | {eta + d for eta in grid for d in (-1.0, 1.0)}
        assert 0.1 < row["critical_step_ms"] < 10.0  # the thesis: about 1 ms


def test_short_edge_geometry(small_cylinder):
    a, b = relaxation.short_edge_choice(small_cylinder, 1e-3)
    length = np.linalg.norm(small_cylinder.points[a] - small_cylinder.points[b])
    for ratio in (0.1, 1e-3):
        points = relaxation.moved_vertex(small_cylinder.points, a, b, ratio)
        assert np.linalg.norm(points[a] - points[b]) == pytest.approx(ratio * length)
        mesh = snede.Mesh(points, small_cylinder.cells)
        assert mesh.n_reoriented == 0 and mesh.quality().volume.min() > 0
        assert relaxation.edge_lengths(relaxation.CylinderMesh("s", points, small_cylinder.cells)).min() \
            == pytest.approx(ratio * length)


def test_machine_peak_is_plausible(relaxation_run):
    _, results = relaxation_run
    triad = relaxation.lookup(results["peak"], kernel="PETSc VecWAXPY triad")
    assert 0.5 < triad["gbytes_per_s"] < 1000
    assert triad["mflops"] == pytest.approx(triad["gbytes_per_s"] * 1e3 / 12)  # 2 flops per 24 bytes


# -- performance --------------------------------------------------------------------------------
def test_performance_writes_its_outputs(performance_run):
    out, _ = performance_run
    for name in EXPECTED_PERFORMANCE_FILES:
        assert (out / name).stat().st_size > 0, name
    assert "python -m studies.experiments.performance --quick" in (out / "performance.md").read_text()


def test_assembled_products_equal_the_shell(performance_run):
    _, results = performance_run
    assert {row["format"] for row in results["products"]} == {"shell", "AIJ", "BAIJ"}
    for row in results["products"]:
        assert row["relative_difference"] <= 1e-12, row
    for row in results["assemblies"]:
        assert row["element_matrix_relative_error"] <= 1e-12, row


def test_assembled_stiffness_annihilates_rigid_motions():
    mesh = snede.meshing.box((1.0, 2.0, 0.5), (3, 4, 2))
    K = performance.linear_elastic_element_matrices(mesh.points, mesh.cells, performance.YOUNG, performance.POISSON)
    mat, *_ = performance.assemble("AIJ", mesh.n_points, mesh.cells, K, performance.node_adjacency(mesh.cells,
                                                                                                 mesh.n_points))
    modes = performance.rigid_body_modes(mesh.points)
    y = mat.createVecLeft()
    scale = mat.norm()
    for mode in modes.getVecs():
        mat.mult(mode, y)
        assert y.norm() <= 1e-12 * scale * mode.norm()


def test_node_graph_of_a_kuhn_box():
    """In the Kuhn split every interior vertex has 14 neighbours (plus itself)."""
    n = 4
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (n, n, n))
    indptr, indices = performance.node_adjacency(mesh.cells, mesh.n_points)
    interior = np.flatnonzero(np.all((mesh.points > 0.01) & (mesh.points < 0.99), axis=1))
    assert np.all(np.diff(indptr)[interior] == 15)
    edges = {tuple(sorted((int(cell[i]), int(cell[j])))) for cell in mesh.cells for i in range(4) for j in range(i)}
    assert indptr[-1] == len(indices) == 2 * len(edges) + mesh.n_points


def test_cube_of_section_3_3_and_cg_on_shell_and_assembled(performance_run):
    _, results = performance_run
    rows = results["cube"]
    assert rows[0]["tetrahedra"] == 7986 and rows[0]["nodes"] == 1728
    for row in rows:
        assert row["reason"].startswith("CONVERGED"), row
    shell, aij = rows[0], next(r for r in rows if r["operator"] == "AIJ" and r["preconditioner"] == "none")
    assert abs(aij["iterations"] - shell["iterations"]) <= 1
    assert aij["solution_difference"] < 1e-10
    for row in rows[1:]:
        assert row["relative_residual"] <= performance.CG_RTOL * (1 + 1e-9), row
        assert row["solution_difference"] < 10 * performance.CG_RTOL, row
    gamg = next(r for r in rows if r["preconditioner"].startswith("GAMG"))
    assert gamg["iterations"] < shell["iterations"] / 3
