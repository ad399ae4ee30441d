"""Vertex removal on a deformed body (issue 48 item 7): remove_vertex_by_flips chose its ears in
the reference configuration only, and on a deformed neo-Hookean sheet it could leave a triangle
that the carried displacement inverts, after which every solve failed with
DIVERGED_INVERTED_ELEMENTS. The body now refuses such ears (a watcher's veto), so the removal
picks others or is refused, leaving the mesh as it was. The inversion is judged here
independently, by the signed areas of the deformed triangles."""
import numpy as np
import pytest

import snede


def signed_areas(points, triangles):
    a, b, c = (points[triangles[:, k]] for k in range(3))
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def deformed_sheet(neighbour_pull):
    """A 4 × 4 sheet whose centre vertex's `neighbour_pull`-th link vertex is pulled 80 % of the
    way towards it (the deformed link is then not convex there; no triangle inverted yet)."""
    mesh = snede.meshing.rectangle((1.0, 1.0), (4, 4))
    centre = int(np.argmin(np.linalg.norm(mesh.points - 0.5, axis=1)))
    link = np.unique(mesh.cells[np.any(mesh.cells == centre, axis=1)])
    link = link[link != centre]
    pulled = link[neighbour_pull % len(link)]
    u = np.zeros_like(mesh.points)
    u[pulled] = 0.8 * (mesh.points[centre] - mesh.points[pulled])
    return mesh, centre, u, len(link)


def removal(neighbour_pull, with_body):
    mesh, centre, u, _ = deformed_sheet(neighbour_pull)
    if with_body:
        body = snede.Body(mesh, snede.NeoHookean(1e4, 0.3), thickness=0.01)
        body.displacement = u
        assert len(body.inverted_elements(u)) == 0
    result = mesh.remove_vertex_by_flips(centre)
    return result, mesh, signed_areas(mesh.points + u, mesh.cells)  # a removed vertex keeps its row

def test_some_pull_makes_the_reference_only_removal_invert_a_triangle():
    """Without a body the removal looks at the reference only: for some pulled neighbour its
    triangulation is inverted in the deformed configuration (else the test below proves nothing)."""
    n_link = deformed_sheet(0)[3]
    assert any(removal(k, with_body=False)[2].min() <= 0 for k in range(n_link))


@pytest.mark.parametrize("neighbour_pull", range(6))
def test_a_removal_on_a_body_never_inverts_its_displacement(neighbour_pull):
    assert deformed_sheet(0)[3] == 6  # the centre's link: each neighbour pulled in turn
    result, mesh, areas = removal(neighbour_pull, with_body=True)
    if result.done:
        assert areas.min() > 0
    else:
        assert "would be inverted by the body's displacement" in result.reason, result.reason
        assert mesh.n_cells == 32  # left as it was


def test_the_sheet_solves_after_a_removal():
    for k in range(deformed_sheet(0)[3]):
        mesh, centre, u, _ = deformed_sheet(k)
        body = snede.Body(mesh, snede.NeoHookean(1e4, 0.3), thickness=0.01)
        body.displacement = u
        body.fix(np.isclose(mesh.points[:, 0], 0.0) | np.isclose(mesh.points[:, 0], 1.0))
        mesh.remove_vertex_by_flips(centre)
        result = snede.StaticSolver(body, "newton", rtol=1e-8, options_prefix="removal_solve_").solve()
        assert result.converged, (k, result)
