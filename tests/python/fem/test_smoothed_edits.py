"""The smoothed formulation (issue 35) through topology edits, adversarially: after every edit
of random sequences (edge splits, collapses and flips, vertex insertions and removals, bisection
around points, along segments and everywhere, dissections of interior faces, batches of edits)
the body's operators keep the invariants smoothed_checks.check_invariants lists, and an affine
field is carried exactly through the edits; bad input is refused naming the value; what fails is
marked with its reproducer. (The cutters, the needle and the solvers on smoothed bodies are
tested beside them: cutting/test_smoothed_cuts.py, needle/test_smoothed_needle.py,
solve/test_smoothed_solves.py.) References independent of the formulation: a fresh P1 body on
the same mesh, the P1 energy of a fully dissected mesh (single-simplex patches), finite
differences."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import snede
from smoothed_checks import (check_affine_state_carried, check_invariants, distorted_grid, interior_vertices,
                             min_altitude, p1_twin, smoothed_body, vertex_scales)

pytestmark = pytest.mark.filterwarnings("ignore::snede.LockingWarning")  # the P1 twins at ν ≥ 0.45


def edges_of(mesh):
    cells = mesh.cells
    k = cells.shape[1]
    pairs = np.concatenate([cells[:, [i, j]] for i in range(k) for j in range(i + 1, k)])
    return np.unique(np.sort(pairs, axis=1), axis=0)


def random_interior_faces(mesh, rng, count):
    """Up to ``count`` distinct interior faces (cell_dim vertices each) of random cells."""
    boundary = {tuple(sorted(f)) for f in mesh.boundary_faces()}
    cells = mesh.cells
    faces = []
    for row in rng.permutation(len(cells)):
        for k in rng.permutation(cells.shape[1]):
            face = tuple(sorted(np.delete(cells[row], k)))
            if face not in boundary and face not in faces:
                faces.append(face)
        if len(faces) >= count:
            break
    return np.array(faces[:count], dtype=np.int64)


def try_edges(mesh, rng, edit, tries=30):
    """Applies ``edit(a, b)`` to random edges until one is done; whether one was."""
    edges = edges_of(mesh)
    for row in rng.integers(len(edges), size=tries):
        if edit(int(edges[row, 0]), int(edges[row, 1])):
            return True
    return False


def random_edit(mesh, op, rng):
    """One edit of kind ``op``; True when the mesh changed."""
    dim = mesh.dim
    if op == "split":
        return try_edges(mesh, rng, lambda a, b: mesh.split_edge(a, b, rng.uniform(0.25, 0.75)))
    if op == "collapse":
        return try_edges(mesh, rng, lambda a, b: mesh.collapse_edge(a, b, rng.uniform()))
    if op == "flip":
        return try_edges(mesh, rng, mesh.flip_edge)
    if op == "insert":
        for _ in range(30):
            row = int(rng.integers(mesh.n_cells))
            if mesh.insert_vertex(int(mesh.cell_ids[row]), rng.dirichlet(np.full(dim + 1, 3.0))):
                return True
        return False
    if op == "remove_by_flips":
        for v in rng.permutation(np.flatnonzero(interior_vertices(mesh)))[:30]:
            if mesh.remove_vertex_by_flips(int(v)):
                return True
        return False
    if op in ("refine_around", "refine_near_segment"):
        # Around the centroid of a random cell, finer than its longest edge: it must split.
        corners = mesh.points[mesh.cells[rng.integers(mesh.n_cells)]]
        centre = corners.mean(axis=0)
        h = 0.6 * max(np.linalg.norm(a - b) for a in corners for b in corners)
        if op == "refine_around":
            return mesh.refine_around(centre, h) > 0
        direction = rng.standard_normal(dim)
        direction *= 1.5 * h / np.linalg.norm(direction)
        return mesh.refine_near_segment(centre - direction, centre + direction, h, 0.2 * h) > 0
    if op == "refine_uniform":
        return mesh.refine_uniform(1) > 0
    if op == "dissect":
        faces = random_interior_faces(mesh, rng, 3)
        mesh.dissect(faces)  # may duplicate no vertex yet (Figure 7.7): the faces stay joined
        return len(faces) > 0
    if op == "batch":
        with mesh.batch():
            random_edit(mesh, "split", rng)
            random_edit(mesh, "refine_around", rng)
            random_edit(mesh, "collapse", rng)
        return True
    raise AssertionError(op)


EDITS_3D = ["split", "collapse", "insert", "refine_around", "refine_near_segment", "dissect", "batch"]
EDITS_2D = EDITS_3D + ["flip", "remove_by_flips"]


@pytest.mark.parametrize("dim, seed", [(2, 0), (2, 1), (2, 2), (2, 3), (3, 0), (3, 1), (3, 2), (3, 3)])
def test_random_edits_keep_every_invariant_and_carry_an_affine_state(dim, seed):
    rng = np.random.default_rng(100 * dim + seed)
    mesh = distorted_grid(dim)
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.45))
    A = 0.02 * rng.standard_normal((dim, dim))
    body.displacement = mesh.points @ A.T
    check_invariants(body, seed, "fresh")
    ops = list(EDITS_2D if dim == 2 else EDITS_3D) * 2
    rng.shuffle(ops)
    ops.insert(int(rng.integers(len(ops) // 3)), "refine_uniform")  # early: the meshes stay small
    done = {}
    for step, op in enumerate(ops):
        changed = random_edit(mesh, op, rng)
        done[op] = done.get(op, 0) + changed
        mesh.validate()
        what = f"step {step}: {op}"
        check_affine_state_carried(body, A, what)
        check_invariants(body, 1000 * seed + step, what)
    assert all(done[op] > 0 for op in ops), done  # every kind of edit was exercised
    assert mesh.n_cells > (100 if dim == 2 else 300)


@pytest.mark.parametrize("dim", [2, 3])
def test_a_fully_dissected_mesh_makes_the_smoothed_body_a_p1_body(dim):
    """Once every interior face is dissected each simplex is its own piece, and its edge and
    vertex patches hold only it: the smoothed energy, forces and tangent are P1's for any
    displacement (the shear and bulk parts add up to the material). A patch left over from
    before the cut would reach across and differ."""
    mesh = distorted_grid(dim)
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.49))
    rng = np.random.default_rng(dim)
    u = 0.02 * rng.standard_normal((mesh.n_points, dim))
    before = body.energy(u)
    assert before != pytest.approx(p1_twin(body).energy(u), rel=1e-3)  # joined: patches average
    mesh.dissect(mesh.faces_where(lambda x: np.ones(len(x), dtype=bool)))
    assert mesh.connected_components()[0] == mesh.n_cells
    twin = p1_twin(body)
    u = 0.01 * min_altitude(mesh) * rng.standard_normal((mesh.n_points, dim))
    d = rng.standard_normal(u.shape)
    assert body.energy(u) == pytest.approx(twin.energy(u), rel=1e-12)
    f = twin.internal_forces(u)
    np.testing.assert_allclose(body.internal_forces(u), f, rtol=0, atol=1e-12 * np.abs(f).max())
    Kd = twin.tangent_apply(u, d)
    np.testing.assert_allclose(body.tangent_apply(u, d), Kd, rtol=0, atol=1e-12 * np.abs(Kd).max())
    check_invariants(body, 7, "fully dissected")


@pytest.mark.parametrize("dim", [2, 3])
def test_the_tangent_at_an_unchanged_state_follows_an_edit_that_keeps_the_vertices(dim):
    """The tangent reuses the patch gradients of the last state it was applied at (compared
    exactly). An edit that keeps every vertex (a flip in 2D, a moved vertex in 3D) leaves the
    same u valid but changes the patches: the next product must be the edited mesh's, as a
    fresh body on it gives, and a second body applied in between must not mix them up."""
    mesh = distorted_grid(dim)
    material = snede.NeoHookean(1e4, 0.45)
    body = smoothed_body(mesh, material)
    other = smoothed_body(snede.Mesh(mesh.points, mesh.cells), material)  # same numbers, own patches
    rng = np.random.default_rng(dim)
    u = 0.01 * vertex_scales(mesh) * rng.standard_normal((mesh.n_points, dim))
    d = rng.standard_normal(u.shape)
    before = body.tangent_apply(u, d)
    np.testing.assert_array_equal(other.tangent_apply(u, d), before)
    if dim == 2:
        assert try_edges(mesh, rng, mesh.flip_edge)
    else:
        vertex = int(np.flatnonzero(interior_vertices(mesh))[0])
        mesh.move_vertex(vertex, point=mesh.points[vertex] + 0.02)
    assert mesh.n_points == len(u)
    after = body.tangent_apply(u, d)
    fresh = smoothed_body(mesh, material)
    expected = fresh.tangent_apply(u, d)
    assert np.abs(expected - before).max() > 1e-3 * np.abs(before).max()  # the edit matters
    np.testing.assert_allclose(after, expected, rtol=0, atol=1e-13 * np.abs(expected).max())
    np.testing.assert_array_equal(other.tangent_apply(u, d), before)  # the unedited twin's
    np.testing.assert_allclose(body.tangent_apply(u, d), expected, rtol=0, atol=1e-13 * np.abs(expected).max())
    check_invariants(body, dim, "edit at an unchanged state")


def test_membranes_take_only_p1_naming_the_formulation():
    surface, _ = snede.meshing.boundary_surface(snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2)))
    with pytest.raises(ValueError, match="formulation 'smoothed' .*membrane"):
        snede.Body(surface, snede.NeoHookean(1e3, 0.3), thickness=0.001, formulation="smoothed")
    with pytest.raises(ValueError, match="formulation 'smoothed' .*membrane"):
        snede._snede.ElasticBody(surface._impl, snede.NeoHookean(1e3, 0.3), 1000.0, 0.001, "smoothed")
    assert snede.Body(surface, snede.NeoHookean(1e3, 0.3), thickness=0.001).formulation == "p1"


@pytest.mark.parametrize("name", ["q2", "P1", "Smoothed", "", " smoothed", None, 3])
def test_unknown_formulations_are_refused_naming_them(name):
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (1, 1, 1))
    with pytest.raises(ValueError, match=f"unknown formulation {name!r}.*p1.*smoothed"):
        snede.Body(mesh, snede.LinearElastic(1e3, 0.3), formulation=name)
    if isinstance(name, str):
        with pytest.raises(ValueError, match=f"unknown formulation '{name}'"):
            snede._snede.ElasticBody(mesh._impl, snede.LinearElastic(1e3, 0.3), 1000.0, 0.0, name)


def test_a_formulation_that_is_not_a_string_is_refused_naming_it():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (1, 1, 1))
    with pytest.raises((ValueError, TypeError), match="formulation.*smoothed"):
        snede.Body(mesh, snede.LinearElastic(1e3, 0.3), formulation=["smoothed"])


def test_other_names_are_refused_naming_them_on_a_smoothed_body():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.3))
    zero = np.zeros((mesh.n_points, 3))
    with pytest.raises(ValueError, match="format must be 'aij' or 'baij', got 'dense'"):
        body.assemble_tangent(zero, "dense")
    with pytest.raises(ValueError, match="element_stiffness is a P1 element's; under formulation 'smoothed'"):
        body.element_stiffness(0, zero)
    with pytest.raises(ValueError, match="method must be 'cg', 'ncg' or 'newton', got 'gauss-seidel'"):
        snede.StaticSolver(body, "gauss-seidel")
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    with pytest.raises(snede.PetscError, match="bogus"):
        snede.StaticSolver(body, "newton", preconditioner="bogus").solve()
    with pytest.raises(ValueError, match="needs LinearElastic"):
        snede.StaticSolver(body, "cg").solve()
    assert not body.displacement.any()


def test_a_domain_error_names_each_element_once_and_counts_at_most_the_cells():
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.3))
    with pytest.raises(snede.DomainError) as raised:
        body.energy(np.full((mesh.n_points, 3), np.nan))
    message = str(raised.value)
    count = int(message.split()[0])
    listed = [int(word) for word in message.split("e.g. element")[1].split()]
    assert count <= mesh.n_cells, message
    assert len(set(listed)) == len(listed), message


# -- crashes -------------------------------------------------------------------------------

LIFECYCLE = """
import gc
import numpy as np
import snede
from petsc4py import PETSc

# A smoothed body's operators kept past a mesh change: the stale assembled matrix multiplies,
# the stale shell refuses (PETSc error), nothing crashes.
mesh = snede.meshing.box((1.0, 1.0, 1.0), (3, 3, 3))
body = snede.Body(mesh, snede.NeoHookean(1e4, 0.3), formulation="smoothed")
zero = np.zeros((mesh.n_points, 3))
J, shell = body.assemble_tangent(zero), body.tangent_operator(zero)
mesh.refine_around(np.full(3, 0.5), 0.1)
x = PETSc.Vec().createSeq(J.getSize()[0]); y = x.duplicate(); x.set(1.0)
J.mult(x, y)
try:
    shell.mult(x, y)
except Exception:
    pass
# The body dropped while its mesh is edited further; a new one on the edited mesh.
del body, J, shell
gc.collect()
mesh.dissect(mesh.faces_where(lambda p: np.isclose(p[:, 0], 1 / 3)))
mesh.refine_uniform(1)
body = snede.Body(mesh, snede.NeoHookean(1e4, 0.3), formulation="smoothed")
assert body.energy(np.zeros((mesh.n_points, 3))) == 0.0
# A body whose mesh Python no longer names, refined and solved.
def make():
    sheet = snede.meshing.rectangle((1.0, 1.0), (4, 4))
    return snede.Body(sheet, snede.NeoHookean(1e4, 0.3), density=10.0, thickness=0.01, formulation="smoothed")
sheet_body = make()
gc.collect()
sheet_body.mesh.refine_uniform(1)
sheet_body.fix(np.isclose(sheet_body.mesh.points[:, 1], 0.0))
sheet_body.add_gravity((0.0, -9.81))
assert snede.StaticSolver(sheet_body, "newton", preconditioner="mg").solve().converged
# One tetrahedron, and a box cut into single tetrahedra (patches of one cell), each solved
# with every preconditioner.
one = snede.Mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]), np.array([[0, 1, 2, 3]]))
pieces = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
pieces.dissect(pieces.faces_where(lambda p: np.ones(len(p), dtype=bool)))
for m in (one, pieces):
    b = snede.Body(m, snede.NeoHookean(1e4, 0.49), density=10.0, formulation="smoothed")
    b.fix(np.isclose(m.points[:, 2], 0.0))
    b.fix_free_pieces()
    b.add_gravity((0.0, 0.0, -9.81))
    for P in ("none", "mg", "gamg", "jacobi"):
        b.displacement = np.zeros((m.n_points, 3))
        assert snede.StaticSolver(b, "newton", rtol=1e-8, preconditioner=P).solve().converged, P
print("done")
"""


def test_lifecycle_and_degenerate_patches_do_not_crash():
    """Run in a subprocess, so that a crash (segfault, abort) fails this test instead of the
    suite: stale operators past a mesh change, bodies dropped while their mesh is edited, a
    single tetrahedron and a box cut into single tetrahedra, solved with every preconditioner."""
    run = subprocess.run([sys.executable, "-c", textwrap.dedent(LIFECYCLE)], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, (run.returncode, run.stderr[-3000:])
    assert run.stdout.strip().endswith("done"), run.stdout + run.stderr[-3000:]
