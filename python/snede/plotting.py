"""Pictures of a body: the reference mesh as a wireframe and the deformed mesh coloured by
displacement magnitude (matplotlib, off-screen), and animations of 2D frames (GIF)."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _figure():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def draw_2d(ax, points, cells, u, scale: float = 1.0, vmax: float | None = None):
    """Reference wireframe (grey) and the deformed mesh coloured by |u|; returns the colour mapping."""
    deformed = points + scale * u
    ax.triplot(points[:, 0], points[:, 1], cells, color="0.75", linewidth=0.4)
    shaded = ax.tripcolor(deformed[:, 0], deformed[:, 1], cells, np.linalg.norm(u, axis=1), shading="gouraud",
                          cmap="viridis", vmin=0.0 if vmax is not None else None, vmax=vmax)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return shaded


def plot_body(body, path, title: str = "", displacement=None, scale: float = 1.0, decorate=None) -> Path:
    """Save a PNG of the body: reference wireframe (grey) and deformed surface coloured by
    |u| (metres). ``scale`` exaggerates the displacement (stated in the title if ≠ 1);
    ``decorate(ax)`` draws on top of a 2D picture."""
    plt = _figure()
    u = body.displacement if displacement is None else np.asarray(displacement)
    magnitude = np.linalg.norm(u, axis=1)
    mesh = body.mesh
    points, deformed = mesh.points, mesh.points + scale * u
    if scale != 1.0:
        title = f"{title} (displacement ×{scale:g})"
    if mesh.dim == 2:
        fig, ax = plt.subplots(figsize=(6, 5))
        shaded = draw_2d(ax, points, mesh.cells, u, scale)
        if decorate is not None:
            decorate(ax)
    else:
        from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

        faces = mesh.boundary_faces()
        fig = plt.figure(figsize=(7, 5))
        ax = fig.add_subplot(projection="3d")
        edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
        ax.add_collection3d(Line3DCollection(points[edges], colors="0.7", linewidths=0.3))
        face_magnitude = magnitude[faces].mean(axis=1)
        import matplotlib.cm as cm
        import matplotlib.colors as colors

        norm = colors.Normalize(vmin=magnitude.min(), vmax=max(magnitude.max(), 1e-300))
        surface = Poly3DCollection(deformed[faces], facecolors=cm.viridis(norm(face_magnitude)),
                                   edgecolors="k", linewidths=0.05)
        ax.add_collection3d(surface)
        both = np.concatenate([points, deformed])
        low, high = both.min(axis=0), both.max(axis=0)
        centre, radius = (low + high) / 2, (high - low).max() / 2
        for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
            setter(c - radius, c + radius)
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


def animate(frames, path, draw, fps: int = 10) -> Path:
    """Save a GIF (matplotlib's Pillow writer) with one picture per frame: ``draw(ax, frame)``
    draws it on an axis without ticks or frame, emptied before each frame."""
    plt = _figure()
    from matplotlib.animation import PillowWriter

    fig = plt.figure(figsize=(4.5, 4))
    ax = fig.add_axes((0, 0, 1, 1))
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
