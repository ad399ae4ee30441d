"""Random edit sequences on a clamped, deformed body (issue 48): tetrahedral cuts, refinement
around a point, edge splits and collapses, each followed by a solve. After every edit the
properties that the adversarial run found broken are checked against quantities computed here:

* the connectivity is valid (mesh.validate);
* the reference volume is conserved (the sum of the cells' signed volumes, computed here, to
  1e-9 of the box's), unless the edit reported removing cells (fragments, elements cut free);
  collapses moved boundary vertices off their faces, and the cells overlapped (item 6);
* the carried displacement inverts no cell (signed volumes of X + u computed here);
* after fix_free_pieces every piece is held, by the rank of its constraints on its rigid motions
  (item 1: a piece held on a line was counted as held): the solve is never refused as not held,
  and converges;
* no converged solve has an inverted cell or a non-finite displacement."""
import numpy as np
import pytest

import snede


def signed_volumes(points, cells):
    p = points[cells]
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6


def random_sweep(rng):
    """A triangle across (or into) the unit box, on a random plane through its middle part."""
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    c = 0.5 + rng.uniform(-0.3, 0.3) * n
    a = np.cross(n, rng.normal(size=3))
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    reach = rng.uniform(0.4, 2.0)
    return np.array([c + reach * a, c - reach * a + reach * b, c - reach * a - reach * b])


def random_edge(mesh, rng):
    cell = mesh.cells[rng.integers(mesh.n_cells)]
    i, j = rng.choice(4, size=2, replace=False)
    return int(cell[i]), int(cell[j])


@pytest.mark.parametrize("seed", range(10))
def test_random_edit_sequences_keep_the_body_whole_held_and_admissible(seed):
    rng = np.random.default_rng(seed)
    mesh = snede.meshing.box((1.0, 1.0, 1.0), (5, 5, 5))
    body = snede.Body(mesh, snede.NeoHookean(1e6, 0.3), density=1000.0)  # stiff: small strains, so a solve that fails is a fault
    body.fix(np.isclose(mesh.points[:, 2], 0.0))
    body.add_gravity((0.0, 0.0, -9.81))
    solver = snede.StaticSolver(body, "newton", rtol=1e-6, options_prefix=f"random_edits_{seed}_")
    assert solver.solve().converged
    cutter = snede.TetrahedralCutter(body)
    volume = signed_volumes(mesh.points, mesh.cells).sum()
    done = {"cut": 0, "refine": 0, "split": 0, "collapse": 0}
    for step in range(16):
        operation = rng.choice(list(done))
        removed_cells = False
        if operation == "cut":
            report = cutter.cut_triangle(random_sweep(rng))
            removed_cells = report.fragments_removed > 0 or report.elements_cut_free > 0
            done["cut"] += report.faces_dissected > 0
        elif operation == "refine":
            done["refine"] += mesh.refine_around(rng.uniform(0.1, 0.9, size=3), 0.12) > 0
        elif operation == "split":
            done["split"] += bool(mesh.split_edge(*random_edge(mesh, rng), t=rng.uniform(0.2, 0.8)))
        else:
            done["collapse"] += bool(mesh.collapse_edge(*random_edge(mesh, rng)))
        where = f"seed {seed}, step {step} ({operation})"
        mesh.validate()
        now = signed_volumes(mesh.points, mesh.cells).sum()
        if not removed_cells:
            assert abs(now - volume) <= 1e-9 * volume, f"{where}: volume {now!r}, was {volume!r}"
        volume = now
        u = body.displacement
        assert np.all(signed_volumes(mesh.points + u, mesh.cells) > 0), f"{where}: an edit inverted a cell"
        body.fix_free_pieces()
        result = solver.solve()
        assert result.converged, f"{where}: {result}"
        assert np.all(np.isfinite(body.displacement))
        assert len(body.inverted_elements(body.displacement)) == 0, where
    assert done["cut"] > 0 and sum(done.values()) > done["cut"], done
