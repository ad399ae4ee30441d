"""What the scenes' pictures show (issue 14 item 9): the mesh's edges, the deformation to scale
or with its factor in the title, the loads, the fixed vertices, axes to scale. The figures are
inspected before they are saved (plotting.draw_body), against what the bodies hold."""

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.quiver import Quiver  # noqa: E402
from mpl_toolkits.mplot3d import proj3d  # noqa: E402

import snede  # noqa: E402
from snede.app import plotting, run_scene  # noqa: E402
from snede.app.plotting import ARROW, draw_body  # noqa: E402
from snede.app.scenes import Parameters, builders  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def options(**given):
    return Parameters(material=given.get("material"), divisions=given.get("divisions"),
                      mesh_size=given.get("mesh_size"), speed=given.get("speed"))


def by_gid(ax, gid):
    return [a for a in [*ax.collections, *ax.lines, *ax.texts, *ax.patches, *ax.get_children()]
            if a.get_gid() == gid]


def one(ax, gid):
    found = {id(a): a for a in by_gid(ax, gid)}
    assert len(found) == 1, f"{len(found)} artists {gid!r}"
    return next(iter(found.values()))


def edge_set(pairs):
    return {tuple(sorted(map(tuple, np.round(pair, 12)))) for pair in pairs}


def to_scale(ax, length=0.05) -> np.ndarray:
    """The Gram matrix (normalised to trace 2) of the pictures of three equal segments along x,
    y and z under an orthographic camera: the identity if and only if the axes are to scale
    (the picture is then a rotation and a uniform scaling, dropping the depth)."""
    ax.set_proj_type("ortho")
    ax.figure.canvas.draw()
    centre = np.array([np.mean(ax.get_xlim()), np.mean(ax.get_ylim()), np.mean(ax.get_zlim())])
    matrix = ax.get_proj()

    def pixel(p):
        x, y, _ = proj3d.proj_transform(*p, matrix)
        return ax.transData.transform((x, y))

    origin = pixel(centre)
    images = np.array([pixel(centre + length * e) - origin for e in np.eye(3)])
    gram = images.T @ images
    return 2 * gram / np.trace(gram)


def sheet(n=(4, 3)):
    """A 4 × 3 cm plane-stress sheet held on its left side, pushed on its right side."""
    mesh = snede.meshing.rectangle((0.04, 0.03), n)
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3), thickness=0.001)
    x = mesh.points
    left, right = np.flatnonzero(np.isclose(x[:, 0], 0.0)), np.flatnonzero(np.isclose(x[:, 0], 0.04))
    body.fix(left)
    body.add_nodal_force(right, np.c_[np.linspace(0.1, 0.3, len(right)), -0.05 * np.ones(len(right))])
    body.displacement = np.c_[1e-4 * x[:, 0] / 0.04, -2e-4 * (x[:, 0] / 0.04) ** 2]
    return body, left, right


def test_2d_picture_draws_the_deformed_mesh_with_every_edge_and_states_the_factor():
    """The slab's picture showed no mesh (the grey reference wireframe lay under the colours)
    and its half a millimetre of displacement at 1:1: nothing moved."""
    body, _, _ = sheet()
    fig, ax = draw_body(body, "sheet", scale=20.0)
    assert "×20" in ax.get_title() and ax.get_aspect() == 1.0
    n, m = 4, 3
    wire = one(ax, "mesh-edges")
    segments = wire.get_segments()
    assert len(segments) == n * (m + 1) + m * (n + 1) + n * m  # horizontal, vertical, diagonal edges
    deformed = body.mesh.points + 20.0 * body.displacement
    cells = body.mesh.cells
    expected = edge_set(deformed[np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]])])
    assert edge_set(segments) == expected  # on the deformed mesh, exaggerated 20 times
    assert np.max(wire.get_linewidths()) > 0 and wire.get_colors()[0][3] > 0
    outline = one(ax, "reference")  # the reference's boundary: 2(n + m) edges at rest
    assert edge_set(outline.get_segments()) <= edge_set(body.mesh.points[body.mesh.boundary_faces()])
    assert len(outline.get_segments()) == 2 * (n + m)
    _, ax = draw_body(body, "sheet")
    assert "to scale" in ax.get_title()


def test_2d_picture_marks_the_loads_and_the_fixed_vertices():
    body, left, right = sheet()
    fig, ax = draw_body(body, "sheet", scale=10.0, fixed=left)
    deformed = body.mesh.points + 10.0 * body.displacement
    forces = body.external_forces()
    quiver = one(ax, "loads")
    assert isinstance(quiver, Quiver) and quiver.N == len(right)
    heads = quiver.XY + np.c_[quiver.U, quiver.V]
    order = np.lexsort(heads.T)
    # Each arrow ends at a loaded vertex, along its force, the largest ARROW of the body's size long.
    np.testing.assert_allclose(heads[order], deformed[right][np.lexsort(deformed[right].T)], atol=1e-12)
    arrows = np.c_[quiver.U, quiver.V][order]
    pushed = forces[right[np.lexsort(deformed[right].T)]]  # in the same order
    np.testing.assert_allclose(np.cross(arrows, pushed), 0.0, atol=1e-12)
    assert np.all(np.einsum("ij,ij->i", arrows, pushed) > 0)
    extent = np.ptp(deformed, axis=0).max()
    assert np.linalg.norm(arrows, axis=1).max() == pytest.approx(ARROW * extent)
    fixed = one(ax, "fixed")
    np.testing.assert_allclose(np.c_[fixed.get_xdata(), fixed.get_ydata()], deformed[left])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert f"fixed ({len(left)} vertices)" in labels
    total = np.linalg.norm(forces.sum(axis=0))
    assert f"load: {total:.3g} N on {len(right)} nodes" in labels

    body.add_gravity((0.0, -9.81))
    _, ax = draw_body(body, loads=True)
    assert one(ax, "gravity-label").get_text() == "g = 9.81 m/s²"
    assert one(ax, "loads").N == len(right)  # the nodal loads still, gravity apart
    _, ax = draw_body(body, loads=False)
    assert not by_gid(ax, "loads") and not by_gid(ax, "gravity")


def test_applied_loads_separates_the_channels_and_gravity():
    body, _, right = sheet()
    body.add_nodal_force([0], (0.0, 1.0), channel="other")
    body.add_gravity((3.0, -4.0))
    forces, g = plotting.applied_loads(body)
    np.testing.assert_allclose(g, (3.0, -4.0))
    np.testing.assert_allclose(forces, body.external_forces("nodal") + body.external_forces("other"))
    forces, g = plotting.applied_loads(body, ["other"])
    assert set(plotting.loaded_vertices(forces)) == {0}
    body.clear_gravity()
    assert plotting.applied_loads(body)[1] is None


def box_beam():
    """A 1.2 × 0.2 × 0.3 m beam (the cantilever's) held at x = 0, 3 N down y on its tip face."""
    mesh = snede.meshing.box((1.2, 0.2, 0.3), (6, 1, 2))
    body = snede.Body(mesh, snede.LinearElastic(1e6, 0.0))
    x = mesh.points
    held, tip = np.isclose(x[:, 0], 0.0), np.flatnonzero(np.isclose(x[:, 0], 1.2))
    body.fix(held)
    body.add_nodal_force(tip, (0.0, -3.0 / len(tip), 0.0))
    body.displacement = np.c_[np.zeros(len(x)), -0.007 * (x[:, 0] / 1.2) ** 2, np.zeros(len(x))]
    return body, held, tip


@pytest.mark.parametrize("view", [None, (20.0, 30.0, 0.0, "y")])
def test_3d_picture_is_to_scale_and_fits_the_body(view):
    """The cantilever's axes: a cube around the beam (before: wasted room, now: each axis as
    long as what it shows); to scale also with y as the vertical axis, which matplotlib gets
    wrong when the box aspect is set before the view."""
    body, held, tip = box_beam()
    fig, ax = draw_body(body, "beam", scale=10.0, view=view, fixed=held)
    np.testing.assert_allclose(to_scale(ax), np.eye(2), atol=2e-3)
    deformed = body.mesh.points + 10.0 * body.displacement
    low = np.minimum(deformed.min(axis=0), body.mesh.points.min(axis=0))
    high = np.maximum(deformed.max(axis=0), body.mesh.points.max(axis=0))
    high[1] += 1.5 * ARROW * 1.2 + 0.01  # the load's arrow stands above the tip
    limits = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
    assert np.all(limits[:, 0] <= low + 1e-9) and np.all(limits[:, 1] >= deformed.max(axis=0) - 1e-9)
    assert np.all(np.diff(limits, axis=1).ravel() <= (high - low) + 0.1 * 1.2)  # no cube around the beam
    assert "×10" in ax.get_title()


def test_3d_picture_marks_the_load_and_the_fixed_vertices():
    body, held, tip = box_beam()
    fig, ax = draw_body(body, "beam", scale=10.0, fixed=held)
    deformed = body.mesh.points + 10.0 * body.displacement
    dots = one(ax, "loaded")
    np.testing.assert_allclose(np.sort(np.array(dots._offsets3d).T, axis=0), np.sort(deformed[tip], axis=0))
    arrow = one(ax, "loads")  # the resultant: one arrow down y onto the tip face's top edge
    shaft = np.asarray(arrow._segments3d[0])
    direction = (shaft[0] - shaft[1]) / np.linalg.norm(shaft[0] - shaft[1])
    np.testing.assert_allclose(direction, (0.0, -1.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(shaft[0], [deformed[tip, 0].mean(), deformed[tip, 1].max(), deformed[tip, 2].mean()],
                               atol=1e-12)
    fixed = one(ax, "fixed")
    np.testing.assert_allclose(np.sort(np.array(fixed._offsets3d).T, axis=0),
                               np.sort(deformed[np.flatnonzero(held)], axis=0))
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert f"fixed ({held.sum()} vertices)" in labels and f"load: 3 N on {len(tip)} nodes" in labels

    body.clear_loads()
    body.add_gravity((0.0, 0.0, -9.81))
    _, ax = draw_body(body)
    gravity = one(ax, "gravity")
    shaft = np.asarray(gravity._segments3d[0])
    np.testing.assert_allclose((shaft[0] - shaft[1]) / np.linalg.norm(shaft[0] - shaft[1]), (0, 0, -1), atol=1e-12)
    assert one(ax, "gravity-label").get_text().strip() == "g = 9.81 m/s²"
    assert not by_gid(ax, "loads")


SCENES = {"slab": dict(divisions=8), "cantilever": dict(divisions=8), "cylinder": dict(),
          "cut": dict(divisions=8), "sheet-cut": dict(divisions=10)}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_each_scene_picture_shows_its_supports_and_loads(name):
    """The arguments run_scene gives plot_body, for a scene as built (before its run)."""
    scene = builders()[name].build(options(**SCENES[name]))
    body = scene.body
    arguments = run_scene.picture_arguments(scene, "cg")
    if scene.evolve is not None:
        arguments["decorate"] = None  # draws what the run made (test_*_scene.py)
    fig, ax = draw_body(body, **arguments)
    # The vertices marked fixed are those the body holds (a count the engine keeps).
    assert arguments["fixed"].sum() == body._model.n_constrained > 0
    assert len(np.asarray(one(ax, "fixed").get_xdata() if body.dim == 2 else one(ax, "fixed")._offsets3d[0])) \
        == body._model.n_constrained
    scale = scene.plot_scale
    assert (f"×{scale:g}" if scale != 1 else "to scale") in ax.get_title()
    forces, gravity = plotting.applied_loads(body)
    loaded = plotting.loaded_vertices(forces)
    if body.dim == 2:
        assert ax.get_aspect() == 1.0
        assert len(one(ax, "mesh-edges").get_segments()) == len(plotting.mesh_edges(body.mesh.cells))
        if len(loaded):
            assert one(ax, "loads").N == len(loaded)
    else:
        np.testing.assert_allclose(to_scale(ax), np.eye(2), atol=2e-3)
        if len(loaded):
            assert len(one(ax, "loaded")._offsets3d[0]) == len(loaded)
    if gravity is not None:
        assert "g = 9.8" in one(ax, "gravity-label").get_text()
    assert len(loaded) or gravity is not None or name == "sheet-cut"  # the sheet is only stretched


def test_slab_picture_shows_the_exaggerated_slab_and_its_load_line():
    """The slab: the line load along y = 0.05 m over the 70 mm a needle would occupy, ×20."""
    scene = builders()["slab"].build(options(divisions=8))
    body = scene.body
    body.displacement = np.c_[2e-4 * (1 - body.mesh.points[:, 0] / 0.1), np.zeros(body.mesh.n_points)]
    fig, ax = draw_body(body, **run_scene.picture_arguments(scene, "cg"))
    assert scene.plot_scale == 20 and "×20" in ax.get_title()
    x = body.mesh.points
    on_line = np.flatnonzero(np.isclose(x[:, 1], 0.05) & (x[:, 0] <= 0.07 + 1e-12))
    quiver = one(ax, "loads")
    heads = quiver.XY + np.c_[quiver.U, quiver.V]
    deformed = x + 20 * body.displacement
    np.testing.assert_allclose(np.sort(heads[:, 0]), np.sort(deformed[on_line, 0]), atol=1e-12)
    np.testing.assert_allclose(heads[:, 1], 0.05)
    assert np.all(quiver.U > 0) and np.allclose(quiver.V, 0.0)  # pushed along the insertion
    line = one(ax, "load-line")
    np.testing.assert_allclose(np.sort(line.get_xdata()), np.sort(deformed[on_line, 0]))
    assert any("line load, 0.2 N" in t.get_text() for t in ax.get_legend().get_texts())
