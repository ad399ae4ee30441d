"""Pictures of a body: the reference mesh as a wireframe and the deformed mesh coloured by
displacement magnitude (matplotlib, off-screen), and animations of frames (GIF)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

HIGHLIGHT = (0.84, 0.15, 0.16, 1.0)  # faces or edges picked out (an incision): red, not in viridis


def _figure():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def draw_2d(ax, points, cells, u, scale: float = 1.0, vmax: float | None = None, reference: bool = True,
            highlight=None):
    """The deformed mesh coloured by |u| over the reference wireframe (grey) or, with
    ``reference=False``, under its own edges, so that an opened cut shows as a gap; the edges
    of ``highlight`` ((m, 2) vertex ids, e.g. the lips of an incision) in red on the deformed
    mesh. Returns the colour mapping."""
    deformed = points + scale * u
    if reference:
        ax.triplot(points[:, 0], points[:, 1], cells, color="0.75", linewidth=0.4)
    shaded = ax.tripcolor(deformed[:, 0], deformed[:, 1], cells, np.linalg.norm(u, axis=1), shading="gouraud",
                          cmap="viridis", vmin=0.0 if vmax is not None else None, vmax=vmax)
    if not reference:
        ax.triplot(deformed[:, 0], deformed[:, 1], cells, color="k", linewidth=0.25, alpha=0.5)
    if highlight is not None and len(highlight):
        lips = deformed[np.asarray(highlight)]  # (m, 2 ends, 2 coordinates)
        ax.plot(lips[:, :, 0].T, lips[:, :, 1].T, color=HIGHLIGHT, linewidth=1.2, solid_capstyle="round")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return shaded


def _face_keys(faces, corners: int) -> np.ndarray:
    """One row per face (``corners`` vertex ids), its vertex ids sorted: the same for both orientations."""
    return np.sort(np.asarray(faces, dtype=np.int64).reshape(-1, corners), axis=1)


def highlighted(faces, highlight) -> np.ndarray:
    """(len(faces),) bool: which of ``faces`` ((n, k) vertex ids: k = 3 for faces, 2 for edges)
    are among ``highlight`` ((m, k) vertex ids, in any order and orientation)."""
    corners = np.shape(faces)[-1]
    keys, wanted = _face_keys(faces, corners), _face_keys(highlight, corners)
    if len(keys) == 0 or len(wanted) == 0:
        return np.zeros(len(keys), dtype=bool)
    rows = np.dtype((np.void, keys.dtype.itemsize * corners))
    return np.isin(np.ascontiguousarray(keys).view(rows).ravel(), np.ascontiguousarray(wanted).view(rows).ravel())


def draw_3d(ax, points, faces, u, scale: float = 1.0, norm=None, highlight=None, light=(-0.4, -0.7, 0.6)):
    """The deformed boundary surface (``faces``: (n, 3) vertex ids, outward) coloured by |u|
    (mean over each face's vertices) and shaded by its normal against ``light``, with the faces
    of ``highlight`` ((m, 3) vertex ids) in red; returns how many were highlighted."""
    import matplotlib.cm as cm
    import matplotlib.colors as colors
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    deformed = points + scale * u
    magnitude = np.linalg.norm(u, axis=1)
    if norm is None:
        norm = colors.Normalize(vmin=magnitude.min(), vmax=max(magnitude.max(), 1e-300))
    colour = cm.viridis(norm(magnitude[faces].mean(axis=1)))
    marked = highlighted(faces, highlight) if highlight is not None else np.zeros(len(faces), dtype=bool)
    colour[marked] = HIGHLIGHT
    triangles = deformed[faces]
    normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    light = np.asarray(light, dtype=np.float64) / np.linalg.norm(light)
    colour[:, :3] *= (0.55 + 0.45 * np.clip(normal @ light, 0.0, 1.0))[:, None]
    ax.add_collection3d(Poly3DCollection(triangles, facecolors=colour, edgecolors=(0, 0, 0, 0.25), linewidths=0.1))
    return int(marked.sum())


def _incision_legend(ax, label: str) -> None:
    from matplotlib.patches import Patch

    ax.legend(handles=[Patch(color=HIGHLIGHT, label=label)], loc="upper right", fontsize=8)


def _cube_limits(ax, coordinates) -> None:
    low, high = coordinates.min(axis=0), coordinates.max(axis=0)
    centre, radius = (low + high) / 2, (high - low).max() / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - radius, c + radius)
    ax.set_box_aspect((1, 1, 1))


def plot_body(body, path, title: str = "", displacement=None, scale: float = 1.0, decorate=None,
              highlight=None, view: tuple | None = None, reference: bool = True) -> Path:
    """Save a PNG of the body: reference wireframe (grey; ``reference=False``: none in 3D, the
    deformed mesh's edges in 2D) and deformed surface coloured by |u| (metres). ``scale``
    exaggerates the displacement (stated in the title if ≠ 1); ``decorate(ax)`` draws on top of
    a 2D picture. ``highlight``, boundary faces ((m, 3) vertex ids, e.g.
    ``TetrahedralCutter.incision_faces()``) or in 2D boundary edges ((m, 2), e.g.
    ``DelaunayCutter.incision_edges()``), is drawn in red; ``view`` is the 3D camera's
    (elevation, azimuth) in degrees."""
    plt = _figure()
    u = body.displacement if displacement is None else np.asarray(displacement)
    magnitude = np.linalg.norm(u, axis=1)
    mesh = body.mesh
    points, deformed = mesh.points, mesh.points + scale * u
    if scale != 1.0:
        title = f"{title} (displacement ×{scale:g})"
    if mesh.dim == 2:
        fig, ax = plt.subplots(figsize=(6, 5))
        shaded = draw_2d(ax, points, mesh.cells, u, scale, reference=reference, highlight=highlight)
        if highlight is not None:
            _incision_legend(ax, f"incision ({len(highlight)} edges)")
        if decorate is not None:
            decorate(ax)
    else:
        import matplotlib.cm as cm
        import matplotlib.colors as colors
        from mpl_toolkits.mplot3d.art3d import Line3DCollection

        faces = mesh.boundary_faces()
        fig = plt.figure(figsize=(7, 5))
        ax = fig.add_subplot(projection="3d")
        if reference:
            edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
            ax.add_collection3d(Line3DCollection(points[edges], colors="0.7", linewidths=0.3))
        norm = colors.Normalize(vmin=magnitude.min(), vmax=max(magnitude.max(), 1e-300))
        marked = draw_3d(ax, points, faces, u, scale, norm, highlight)
        if highlight is not None:
            _incision_legend(ax, f"incision ({marked} faces)")
        _cube_limits(ax, np.concatenate([points, deformed]) if reference else deformed[np.unique(faces)])
        if view is not None:
            ax.view_init(*view)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        shaded = cm.ScalarMappable(norm=norm, cmap="viridis")
    fig.colorbar(shaded, ax=ax, label="|u| [m]", shrink=0.7)
    ax.set_title(title)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def animate(frames, path, draw, fps: int = 10, projection: str | None = None) -> Path:
    """Save a GIF (matplotlib's Pillow writer) with one picture per frame: ``draw(ax, frame)``
    draws it on an axis without ticks or frame (``projection="3d"``: a 3D one), emptied before
    each frame."""
    plt = _figure()
    from matplotlib.animation import PillowWriter

    fig = plt.figure(figsize=(4.5, 4))
    ax = fig.add_axes((0, 0, 1, 1), projection=projection)
    ax.set_axis_off()  # clearing and laying out ticks would cost more than drawing the mesh
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, str(path), dpi=72):
        for frame in frames:
            for artist in [*ax.collections, *ax.lines, *ax.texts]:
                artist.remove()
            draw(ax, frame)
            writer.grab_frame()
    plt.close(fig)
    return path
