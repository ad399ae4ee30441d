"""The smoothed formulation (issue 35) through topology edits and solvers, adversarially: after
every edit of random sequences (edge splits, collapses and flips, vertex insertions and
removals, bisection around points, along segments and everywhere, dissections of interior
faces, batches of edits), after every move of the tetrahedral and Delaunay cutters and after
needle insertions, the body's operators keep their invariants: zero energy and forces at
u = 0; forces are minus the energy's gradient and the tangent their derivative (Taylor
remainders falling like h²); the tangent is symmetric; the assembled tangent (aij and baij)
and its diagonal are the matrix-free shell's, which is tangent_apply on the free vertices; an
affine field has a P1 body's energy and forces on the same mesh and is carried exactly through
the edits. Static solves with every preconditioner converge to the same answer after cuts and
refinement; bad input is refused naming the value; what fails is marked with its reproducer.
References independent of the formulation: a fresh P1 body on the same mesh, the P1 energy of
a fully dissected mesh (single-simplex patches), finite differences, and PETSc's reasons."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from petsc4py import PETSc

import snede
from snede.subdivision_cutting import SubdivisionCutter

pytestmark = pytest.mark.filterwarnings("ignore::snede.LockingWarning")  # the P1 twins at ν ≥ 0.45

THICKNESS = 0.01


def thickness(mesh):
    return THICKNESS if mesh.dim == 2 else None


def smoothed_body(mesh, material, **options):
    return snede.Body(mesh, material, thickness=thickness(mesh), formulation="smoothed", **options)


def p1_twin(body):
    """A P1 body on the same mesh (a second Body watching it)."""
    return snede.Body(body.mesh, body.material, density=body.density, thickness=thickness(body.mesh))


def cell_altitudes(mesh) -> np.ndarray:
    """The smallest height of each cell (row of ``mesh.cells``)."""
    x = mesh.points[mesh.cells]
    if mesh.dim == 2:
        e1, e2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
        area = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / 2
        return np.min([2 * area / np.linalg.norm(x[:, (k + 1) % 3] - x[:, (k + 2) % 3], axis=1) for k in range(3)],
                      axis=0)
    volume = np.abs(np.einsum("ij,ij->i", x[:, 1] - x[:, 0], np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]))) / 6
    heights = []
    for k in range(4):
        a, b, c = (x[:, j] for j in range(4) if j != k)
        heights.append(3 * volume / (np.linalg.norm(np.cross(b - a, c - a), axis=1) / 2))
    return np.min(heights, axis=0)


def min_altitude(mesh) -> float:
    return float(cell_altitudes(mesh).min())


def vertex_scales(mesh) -> np.ndarray:
    """Per vertex, the smallest height of the cells around it (1 for a vertex of no cell):
    moving each vertex by a small fraction of its own scale inverts no cell, and keeps the
    strains, energies and round-off of large and small cells alike."""
    scale = np.full(mesh.n_points, np.inf)
    heights = cell_altitudes(mesh)
    for k in range(mesh.cells.shape[1]):
        np.minimum.at(scale, mesh.cells[:, k], heights)
    scale[~np.isfinite(scale)] = 1.0
    return scale[:, None]


def mult(matrix, v):
    x = PETSc.Vec().createWithArray(np.ascontiguousarray(v, dtype=np.float64).ravel().copy())
    y = x.duplicate()
    matrix.mult(x, y)
    out = y.getArray().copy().reshape(v.shape)
    x.destroy()
    y.destroy()
    return out


def used_vertices(mesh):
    used = np.zeros(mesh.n_points, dtype=bool)
    used[mesh.cells.ravel()] = True
    return used


def interior_vertices(mesh):
    """Vertices of some cell and on no boundary face (the lips of a cut are boundary)."""
    interior = used_vertices(mesh)
    interior[np.unique(mesh.boundary_faces())] = False
    return interior


def taylor_slopes(remainder, h0=1e-4, n=4):
    values = np.array([remainder(h0 / 2**k) for k in range(n)])
    return np.log2(values[:-1] / values[1:]), values


def check_invariants(body, seed, what=""):
    """Everything the smoothed operators promise at the mesh as it is now (see the module doc).
    ``what`` names the edit that came before, for the failure message."""
    mesh, dim = body.mesh, body.dim
    n = mesh.n_points
    zero = np.zeros((n, dim))
    assert body.energy(zero) == 0.0, what
    assert not body.internal_forces(zero).any(), what

    rng = np.random.default_rng(seed)
    h = vertex_scales(mesh)
    u = 0.02 * h * rng.standard_normal((n, dim))
    d = h * rng.standard_normal((n, dim))
    assert len(body.inverted_elements(u)) == 0, what
    energy, forces = body.energy(u), body.internal_forces(u)
    assert np.isfinite(energy) and np.isfinite(forces).all(), what
    # f = −∂Π/∂u: |Π(u + t d) − Π(u) + t f·d| falls like t² (like t where f is wrong, which
    # dominates at these t even for an error at a few vertices; the remainder is far above
    # round-off); and component by component, by central differences at 24 random unknowns.
    slope = -(forces * d).sum()
    slopes, values = taylor_slopes(lambda t: abs(body.energy(u + t * d) - energy - t * slope))
    assert np.all(np.abs(slopes - 2) < 0.05), (what, slopes, values)
    for k in rng.choice(n * dim, size=min(24, n * dim), replace=False):
        step = 1e-3 * h.flat[k // dim]
        e = np.zeros(n * dim)
        e[k] = step
        e = e.reshape(n, dim)
        derivative = (body.energy(u + e) - body.energy(u - e)) / (2 * step)
        assert abs(derivative + forces.flat[k]) <= 1e-5 * np.abs(forces).max(), (what, k, derivative, forces.flat[k])
    # K = −∂f/∂u: |−(f(u + t d) − f(u)) − t K d| falls like t².
    Kd = body.tangent_apply(u, d)

    def force_remainder(t):
        return np.abs(-(body.internal_forces(u + t * d) - forces) - t * Kd).max()

    if isinstance(body.material, snede.LinearElastic):  # linear forces: exact up to round-off
        assert force_remainder(1e-2) <= 1e-10 * np.abs(Kd).max(), what
    else:
        slopes, values = taylor_slopes(force_remainder)
        assert np.all(np.abs(slopes - 2) < 0.1), (what, slopes, values)
    # Symmetric.
    w = rng.standard_normal((n, dim))
    left, right = (w * Kd).sum(), (d * body.tangent_apply(u, w)).sum()
    assert abs(left - right) <= 1e-11 * np.linalg.norm(w) * np.linalg.norm(Kd), (what, left, right)

    # The shell J = P K P + (I − P) is tangent_apply on the free vertices; the assembled J and
    # its diagonal are the shell's, on every row (removed and constrained vertices included).
    fixed, _, sliding = body._model.constraint_table()
    held = ~mesh.live_vertices
    held[fixed] = True
    held[sliding] = True
    projected = np.where(held[:, None], 0.0, d)
    shell = body.tangent_operator(u)
    expected = body.tangent_apply(u, projected)
    np.testing.assert_allclose(mult(shell, projected)[~held], expected[~held], rtol=0,
                               atol=1e-11 * np.abs(expected).max(), err_msg=what)
    Jd, diagonal = mult(shell, d), shell.getDiagonal().getArray().copy()
    for format in ("aij", "baij"):
        J = body.assemble_tangent(u, format=format)
        np.testing.assert_allclose(mult(J, d), Jd, rtol=0, atol=1e-11 * np.abs(Jd).max(), err_msg=f"{what} {format}")
        np.testing.assert_allclose(J.getDiagonal().getArray(), diagonal, rtol=1e-12, atol=0, err_msg=f"{what} {format}")
        J.destroy()

    # Patch test against a fresh P1 body on the same mesh.
    A = 0.01 * rng.standard_normal((dim, dim))
    affine = mesh.points @ A.T
    twin = p1_twin(body)
    assert body.energy(affine) == pytest.approx(twin.energy(affine), rel=1e-10), what
    forces = body.internal_forces(affine)
    scale = np.abs(forces).max()
    np.testing.assert_allclose(forces, twin.internal_forces(affine), rtol=0, atol=1e-9 * scale, err_msg=what)
    stress = twin.element_stress(affine)  # row by row of mesh.cells, whatever ids edits left
    np.testing.assert_allclose(body.element_stress(affine), stress, rtol=0, atol=1e-9 * np.abs(stress).max(),
                               err_msg=what)
    inner = interior_vertices(mesh)
    if inner.any():
        assert np.abs(forces[inner]).max() <= 1e-9 * scale, what


def check_affine_state_carried(body, A, what=""):
    """The body's displacement, set to A·x before the edits, is still A·x at every live vertex:
    every edit interpolates it linearly to new and moved vertices."""
    live = body.mesh.live_vertices
    expected = body.mesh.points @ A.T
    error = np.abs(body.displacement - expected)[live].max()
    assert error <= 1e-12 * np.abs(expected).max(), (what, error)


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


def distorted_grid(dim):
    mesh = snede.meshing.rectangle((1.0, 1.0), (6, 6)) if dim == 2 else snede.meshing.box((1.0, 1.0, 1.0), (3, 3, 3))
    points = mesh.points.copy()
    inner = interior_vertices(mesh)
    points[inner] += 0.05 * np.random.default_rng(dim).uniform(-1, 1, (inner.sum(), dim))
    return snede.Mesh(points, mesh.cells)


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


def pieces_do_not_pull_on_each_other(body):
    """A random displacement of one piece leaves the vertices of the others without force."""
    mesh = body.mesh
    count, labels = mesh.connected_components()
    assert count >= 2
    vertex_piece = np.full(mesh.n_points, -1)
    vertex_piece[mesh.cells.ravel()] = np.repeat(labels, mesh.cells.shape[1])
    for piece in range(count):
        u = np.zeros((mesh.n_points, body.dim))
        mine = vertex_piece == piece
        u[mine] = 1e-3 * min_altitude(mesh) * np.random.default_rng(piece).standard_normal((mine.sum(), body.dim))
        f = body.internal_forces(u)
        assert np.abs(f[mine]).max() > 0
        assert np.abs(f[(vertex_piece >= 0) & ~mine]).max() == 0.0, piece


def solve_with_every_preconditioner(body, rtol=1e-8):
    """From the body's state, a Newton solve per preconditioner; all converge, to the same
    displacement as without one. Leaves the body at that displacement."""
    start = body.displacement
    answers = {}
    for preconditioner in ("none", "mg", "gamg", "jacobi"):
        body.displacement = start
        result = snede.StaticSolver(body, "newton", rtol=rtol, preconditioner=preconditioner).solve()
        assert result.converged, (preconditioner, result)
        answers[preconditioner] = body.displacement
    reference = answers["none"]
    for preconditioner, u in answers.items():
        assert np.abs(u - reference).max() <= 1e-6 * np.abs(reference).max(), preconditioner
    body.displacement = reference
    return reference


def test_tetrahedral_cutter_on_a_hanging_smoothed_body():
    """A box held at its bottom sags under gravity, then the scalpel (in deformed space) cuts it
    through: invariants after every move, two pieces that no patch joins, and solves that
    agree for every preconditioner."""
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (5, 5, 5))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.49), density=10.0)
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    assert snede.StaticSolver(body, "newton", rtol=1e-8).solve().converged
    cutter = snede.TetrahedralCutter(body)
    for step, y in enumerate((-0.5, 0.3, 0.7, 1.5)):
        report = cutter.move(np.array([[0.43, y, -1.0], [0.43, y, 2.0]]))
        mesh.validate()
        check_invariants(body, step, f"move {step}: {report}")
    assert report.components == 2
    assert len(cutter.incision_faces()) > 2 * 25  # both lips of at least the 5 × 5 faces of a plane
    pieces_do_not_pull_on_each_other(body)
    solve_with_every_preconditioner(body)
    check_invariants(body, 99, "solved after the cut")


@pytest.mark.parametrize("dim", [2, 3])
def test_cutters_carry_an_affine_state_exactly(dim):
    """Snapping, splitting, dissecting, collapsing and removing fragments all interpolate the
    displacement linearly: an affine state stays affine, and with it the smoothed body's
    energy is P1's after the cut."""
    rng = np.random.default_rng(dim)
    A = 0.01 * rng.standard_normal((dim, dim))
    if dim == 2:
        mesh = distorted_grid(2)
        body = smoothed_body(mesh, snede.StVenantKirchhoff(1e4, 0.45))
        body.displacement = mesh.points @ A.T
        cutter = snede.DelaunayCutter(body)
        cutter.cut(np.array([[-0.2, 0.42], [0.55, 0.6], [0.8, 0.3], [1.2, 0.35]]))
    else:
        mesh = snede.meshing.box((1.0, 1.0, 1.0), (4, 4, 4))
        body = smoothed_body(mesh, snede.StVenantKirchhoff(1e4, 0.45))
        body.displacement = mesh.points @ A.T
        cutter = snede.TetrahedralCutter(body, fix_free_pieces=False)
        for y in (-0.5, 0.4, 0.8, 1.5):  # the tilted plane x = 0.55 + 0.1 z through the whole box
            cutter.move(np.array([[0.45, y, -1.0], [0.75, y, 2.0]]))
    mesh.validate()
    assert mesh.connected_components()[0] == 2
    check_affine_state_carried(body, A, "cut")
    u = body.displacement
    assert body.energy(u) == pytest.approx(p1_twin(body).energy(u), rel=1e-10)
    check_invariants(body, dim, "cut")


def test_delaunay_and_subdivision_cutters_on_a_smoothed_sheet():
    mesh = snede.meshing.rectangle((1.0, 1.0), (10, 10))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.49), density=10.0)
    body.fix(np.isclose(mesh.points[:, 1], 0.0))
    body.add_gravity((0.0, -9.81))
    assert snede.StaticSolver(body, "newton", rtol=1e-8).solve().converged
    cutter = snede.DelaunayCutter(body)
    path = snede.planar_cutting.sample_path(np.array([[-0.2, 0.55], [0.5, 0.62], [0.7, 0.45], [1.3, 0.5]]),
                                            cutter.eps_edge)
    flips = 0
    for step, point in enumerate(path):
        report = cutter.move(point)
        flips += report.flips
        if step % 3 == 0 or step == len(path) - 1:
            mesh.validate()
            check_invariants(body, step, f"move {step} to {point}")
    assert flips > 0 and mesh.connected_components()[0] == 2
    pieces_do_not_pull_on_each_other(body)
    assert body.fix_free_pieces() == 1  # the upper part, cut free of the fixed bottom
    solve_with_every_preconditioner(body)
    # The subdivision baseline edits the same mesh under the body (splits and dissections).
    report = SubdivisionCutter(mesh).cut([np.array([0.3, -0.1]), np.array([0.45, 0.4])])
    assert report.nodes_inserted > 0
    mesh.validate()
    check_invariants(body, 5, "subdivision cut")
    solve_with_every_preconditioner(body)


def test_needle_insertion_into_a_smoothed_sheet_and_block():
    """2D: the §6.8.1 slab, refined at the tip as the needle goes in; 3D: the cube of §6.9 with
    its needle refined along the shaft. Every update converges, the free vertices off the
    needle are in equilibrium, and the invariants hold on the refined meshes (with the needle
    nodes' constraints in the assembled tangent)."""
    size = 0.1
    mesh = snede.meshing.rectangle((size, size), (8, 8))
    body = smoothed_body(mesh, snede.LinearElastic(34e3, 0.45))
    body.fix(np.isclose(mesh.points[:, 0], size))
    needle = snede.NeedleInsertion(body, (0.0, 0.05), (1.0, 0.0), snede.FrictionProfile.figure_6_4(),
                                   h_ref=size / 32, rtol=1e-8)
    report = needle.insert(0.05, size / 32)
    assert report.converged, report
    assert mesh.n_cells > 2 * 64 and len(needle.needle_nodes) >= 5
    residual = body.internal_forces(body.displacement) + body.external_forces()
    off = np.ones(mesh.n_points, dtype=bool)
    off[body._model.constraint_table()[0]] = False
    off[needle.needle_nodes] = False
    off &= used_vertices(mesh)
    assert np.abs(residual[off]).max() <= 1e-6 * np.abs(body.internal_forces(body.displacement)).max()
    check_invariants(body, 1, "2D needle")

    mesh = snede.meshing.box((size, size, size), (2, 2, 2))
    mesh.refine_uniform(2)
    body = smoothed_body(mesh, snede.LinearElastic(34e3, 0.45))
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    needle = snede.NeedleInsertion(body, (-0.01, 0.05, 0.05), (1.0, 0.0, 0.0), snede.FrictionProfile.uniform(2000.0),
                                   radius=0.004, h_ref=0.012, rtol=1e-8)
    report = needle.insert(0.05, 0.012)
    assert report.converged, report
    assert len(needle.needle_nodes) >= 3
    check_invariants(body, 2, "3D needle")


def loaded_beam(dim, formulation="smoothed", levels=None, density=10.0):
    """A cantilever 1 × 0.4 (× 0.4) m, neo-Hookean at ν = 0.49, fixed at x = 0, under gravity;
    its mesh made by bisection (``levels`` of refine_uniform) so that "mg" starts on its tree."""
    if dim == 2:
        mesh = snede.meshing.rectangle((1.0, 0.4), (5, 2))
        mesh.refine_uniform(4 if levels is None else levels)
    else:
        mesh = snede.meshing.box((1.0, 0.4, 0.4), (5, 2, 2))
        mesh.refine_uniform(2 if levels is None else levels)
    body = snede.Body(mesh, snede.NeoHookean(1e4, 0.49), density=density, thickness=thickness(mesh),
                      formulation=formulation)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity(np.r_[np.zeros(dim - 1), -9.81])
    return body


@pytest.mark.parametrize("dim", [2, 3])
def test_static_solves_agree_for_every_preconditioner_through_cuts_and_refinement(dim):
    """One solver per preconditioner, kept through the edits (it follows each change: new
    vectors, assembled tangent on the patches' two-edge sparsity, multigrid levels): fresh
    (bisection multigrid), after a cut (grid multigrid), after refine_around and after a
    uniform refinement. Each solve converges, to the answer without a preconditioner, in
    equilibrium; and in 3D the smoothed beam sags more than P1's, which locks at ν = 0.49."""
    bodies = {P: loaded_beam(dim) for P in ("none", "mg", "gamg", "jacobi")}
    solvers = {P: snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner=P) for P, body in bodies.items()}

    def solve_all(stage):
        for P, solver in solvers.items():
            result = solver.solve()
            assert result.converged, (stage, P, result)
        reference = bodies["none"].displacement
        for P, body in bodies.items():
            u = body.displacement
            assert np.abs(u - reference).max() <= 1e-6 * np.abs(reference).max(), (stage, P)
            fixed = np.zeros(body.mesh.n_points, dtype=bool)
            fixed[body._model.constraint_table()[0]] = True
            residual = (body.internal_forces(u) + body.external_forces())[~fixed & used_vertices(body.mesh)]
            assert np.linalg.norm(residual) <= 1e-6 * np.linalg.norm(body.external_forces()), (stage, P)
        return reference

    fresh = solve_all("fresh")
    assert solvers["mg"].multigrid_source == "bisection"
    p1 = loaded_beam(dim, "p1")
    assert snede.StaticSolver(p1, "newton", rtol=1e-8).solve().converged
    if dim == 3:
        assert np.abs(fresh).max() > 1.05 * np.abs(p1.displacement).max()
    for body in bodies.values():
        mesh = body.mesh
        assert len(mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.6) & (x[:, dim - 1] > 0.15)))) > 0
    solve_all("cut")
    assert solvers["mg"].multigrid_source == "grid"
    for body in bodies.values():
        body.mesh.refine_around(np.r_[0.6, np.full(dim - 1, 0.15)], 0.04)
    solve_all("refine_around")
    for body in bodies.values():
        body.mesh.refine_uniform(1)
    solve_all("refine_uniform")
    check_invariants(bodies["gamg"], 3, "after the solves")


def test_dynamic_relaxation_reaches_the_static_answer_after_a_cut():
    mesh = snede.meshing.rectangle((1.0, 0.4), (10, 4))
    body = smoothed_body(mesh, snede.LinearElastic(1e4, 0.3), density=10.0)
    body.fix(np.isclose(mesh.points[:, 0], 0.0))
    body.add_gravity((0.0, -9.81))
    mesh.dissect(mesh.faces_where(lambda x: np.isclose(x[:, 0], 0.5) & (x[:, 1] > 0.15)))
    assert snede.StaticSolver(body, "cg", rtol=1e-10).solve().converged
    static = body.displacement
    body.displacement = np.zeros_like(static)
    assert snede.DynamicRelaxation(body, 20.0).run(rtol=1e-7, max_steps=100000).converged
    assert np.abs(body.displacement - static).max() <= 1e-4 * np.abs(static).max()


def test_bisection_multigrid_under_a_load_that_bends_the_beam_a_quarter_of_its_length():
    """Under this load a coarse level linearised at the injected fine state is indefinite (P1 and
    smoothed alike): the solver then linearises the coarse levels at rest and converges."""
    body = loaded_beam(3, levels=3, density=30.0)
    reference = loaded_beam(3, levels=3, density=30.0)
    assert snede.StaticSolver(reference, "newton", rtol=1e-8, preconditioner="none").solve().converged
    assert np.abs(reference.displacement).max() > 0.2  # a large, but regular, deflection
    solver = snede.StaticSolver(body, "newton", rtol=1e-8, preconditioner="mg")
    result = solver.solve()
    assert solver.multigrid_source == "bisection"
    assert result.converged, result
    assert np.abs(body.displacement - reference.displacement).max() <= 1e-6 * np.abs(reference.displacement).max()


# -- bad input ------------------------------------------------------------------------------

def test_smoothed_bodies_on_mpi_ranks_are_refused_naming_the_formulation():
    MPI = pytest.importorskip("mpi4py.MPI")
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = smoothed_body(mesh, snede.NeoHookean(1e4, 0.3), comm=MPI.COMM_WORLD)
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    message = "formulation 'smoothed' is not distributed yet"
    with pytest.raises(NotImplementedError, match=message):
        snede.StaticSolver(body, "newton").solve()
    with pytest.raises(NotImplementedError, match=message):
        snede.DynamicRelaxation(body, 10.0)
    serial = smoothed_body(mesh, snede.NeoHookean(1e4, 0.3))
    serial.fix(np.isclose(mesh.points[:, 2], 0.0))
    with pytest.raises(NotImplementedError, match=message):
        snede.StaticSolver(serial, "newton", comm=MPI.COMM_WORLD).solve()
    assert not body.displacement.any() and not serial.displacement.any()
    serial.add_gravity((0.0, 0.0, -9.81))  # without a communicator the same body solves
    assert snede.StaticSolver(serial, "newton").solve().converged


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
    with pytest.raises(ValueError, match="method must be one of"):
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
