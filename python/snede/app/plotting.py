"""Pictures of a body: the deformed mesh with its edges, coloured by displacement magnitude,
over the reference, with its loads (orange arrows) and fixed vertices (black triangles), axes
to scale and the displacement's exaggeration in the title (matplotlib, off-screen); and
animations of frames (GIF)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from snede.app._extras import need

HIGHLIGHT = (0.84, 0.15, 0.16, 1.0)  # faces or edges picked out (an incision): red, not in viridis
LOAD = (1.0, 0.5, 0.05, 1.0)  # loads (arrows, the gravity arrow): orange, neither viridis nor the incision's red
SUPPORT = (0.0, 0.0, 0.0, 1.0)  # markers on the fixed vertices
ARROW = 0.12  # the longest load arrow, as a fraction of the body's largest extent


def _figure():
    matplotlib = need("matplotlib", "snede's pictures")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def mesh_edges(cells) -> np.ndarray:
    """(m, 2) the edges of triangles or tetrahedra ``cells``, each once (vertex ids sorted)."""
    cells = np.asarray(cells, dtype=np.int64)
    corners = cells.shape[1]
    pairs = [(a, b) for a in range(corners) for b in range(a + 1, corners)]
    edges = np.sort(np.concatenate([cells[:, pair] for pair in pairs]), axis=1)
    return np.unique(edges, axis=0) if len(edges) else edges.reshape(0, 2)


def outline_edges(cells) -> np.ndarray:
    """(m, 2) the boundary edges of a triangle mesh: the edges of exactly one triangle."""
    cells = np.asarray(cells, dtype=np.int64)
    edges = np.sort(np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]), axis=1)
    if not len(edges):
        return edges.reshape(0, 2)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    return unique[count == 1]


def _edge_width(n_edges: int) -> float:
    """Thin lines for large meshes, so that the colours still show between them."""
    return 0.4 if n_edges < 2000 else 0.25 if n_edges < 20000 else 0.12


def draw_2d(ax, points, cells, u, scale: float = 1.0, vmax: float | None = None, reference: bool = True,
            highlight=None, edges: bool = True):
    """The deformed mesh (``points + scale·u``) coloured by |u| with its edges drawn on top
    (``edges``) and, with ``reference``, the reference mesh's outline (grey, dashed); with
    ``reference=False`` an opened cut shows as a gap. The edges of ``highlight`` ((m, 2) vertex
    ids, e.g. the lips of an incision) in red on the deformed mesh. Returns the colour mapping."""
    from matplotlib.collections import LineCollection

    deformed = points + scale * u
    shaded = ax.tripcolor(deformed[:, 0], deformed[:, 1], cells, np.linalg.norm(u, axis=1), shading="gouraud",
                          cmap="viridis", vmin=0.0 if vmax is not None else None, vmax=vmax)
    if edges:
        wire = mesh_edges(cells)
        ax.add_collection(LineCollection(deformed[wire], colors=(0, 0, 0, 0.45), linewidths=_edge_width(len(wire)),
                                         gid="mesh-edges"))
    if reference:
        ax.add_collection(LineCollection(points[outline_edges(cells)], colors="0.45", linewidths=0.8,
                                         linestyles=(0, (3, 2)), gid="reference"))
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
    of ``highlight`` ((m, 3) vertex ids) in red, or, for a surface mesh, its edges ((m, 2): the
    lips of an incision) as red lines; returns how many were highlighted."""
    import matplotlib.cm as cm
    import matplotlib.colors as colors
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    lines = highlight is not None and np.shape(highlight)[-1] == 2

    deformed = points + scale * u
    magnitude = np.linalg.norm(u, axis=1)
    if norm is None:
        norm = colors.Normalize(vmin=magnitude.min(), vmax=max(magnitude.max(), 1e-300))
    colour = cm.viridis(norm(magnitude[faces].mean(axis=1)))
    marked = highlighted(faces, highlight) if highlight is not None and not lines else np.zeros(len(faces), dtype=bool)
    colour[marked] = HIGHLIGHT
    triangles = deformed[faces]
    normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1), 1e-300)[:, None]
    light = np.asarray(light, dtype=np.float64) / np.linalg.norm(light)
    colour[:, :3] *= (0.55 + 0.45 * np.clip(normal @ light, 0.0, 1.0))[:, None]
    ax.add_collection3d(Poly3DCollection(triangles, facecolors=colour, edgecolors=(0, 0, 0, 0.35),
                                         linewidths=0.75 * _edge_width(3 * len(faces) // 2), zorder=2,
                                         gid="surface"))
    if lines and len(highlight):
        ax.add_collection3d(Line3DCollection(deformed[np.asarray(highlight)], colors=[HIGHLIGHT], linewidths=1.5,
                                             zorder=3, gid="incision"))
        return len(highlight)
    return int(marked.sum())


def applied_loads(body, channels=None) -> tuple[np.ndarray, np.ndarray | None]:
    """What loads the body: the nodal forces of its load channels (``channels``: their names,
    None for all) summed, (n_points, dim) newtons, and the gravity acceleration (dim,) m/s² (what
    the external forces hold besides every channel, per unit of mass), None without gravity."""
    every = body.load_channels
    chosen = every if channels is None else [c for c in channels if c in every]
    forces = np.zeros((body.mesh.n_points, body.dim))
    for channel in chosen:
        forces += body.external_forces(channel)
    rest = body.external_forces() - sum((body.external_forces(c) for c in every), np.zeros_like(forces))
    weight = rest.sum(axis=0)
    mass = body.lumped_mass().sum()
    if not np.any(rest) or mass <= 0 or np.linalg.norm(weight) <= 1e-12 * np.abs(rest).sum():
        return forces, None
    return forces, weight / mass


def _extent(coordinates) -> float:
    return float(max(np.ptp(coordinates, axis=0).max(), 1e-12))


def loaded_vertices(forces) -> np.ndarray:
    """The rows of ``forces`` ((n, dim)) that are not zero (to rounding, against the largest)."""
    magnitude = np.linalg.norm(forces, axis=1)
    return np.flatnonzero(magnitude > 1e-12 * max(magnitude.max(initial=0.0), 1e-300))


def _newtons(force: float) -> str:
    return f"{force:.3g} N"


def draw_loads(ax, x, forces, length: float) -> np.ndarray:
    """The nodal ``forces`` ((n, dim) newtons) at the points ``x`` (deformed coordinates), in
    orange. In 2D an arrow on each loaded point, ending there, the largest ``length`` long
    (metres) and the others in proportion: a line load shows its profile. In 3D, where arrows on
    the nodes of a face would hide one another, a dot on each loaded point and one arrow
    1.5 ``length`` long for their resultant, pointing at their centre from outside them. Returns
    the (k, dim) points the arrows start from (none: nothing is loaded)."""
    magnitude, loaded = np.linalg.norm(forces, axis=1), loaded_vertices(forces)
    if not len(loaded):
        return np.zeros((0, x.shape[1]))
    if x.shape[1] == 2:
        arrows = forces[loaded] * (length / magnitude[loaded].max())
        tails = x[loaded] - arrows
        ax.quiver(tails[:, 0], tails[:, 1], arrows[:, 0], arrows[:, 1], angles="xy", scale_units="xy", scale=1.0,
                  color=LOAD, width=0.006, headwidth=3.5, headlength=4, headaxislength=3.5, zorder=4, gid="loads")
        return tails
    points, total = x[loaded], forces[loaded].sum(axis=0)
    if np.linalg.norm(total) <= 1e-12 * magnitude[loaded].sum():  # balanced: the largest force shows the way
        total = forces[loaded[np.argmax(magnitude[loaded])]]
    direction = total / np.linalg.norm(total)
    centre = points.mean(axis=0)
    head = centre + (np.min(points @ direction) - centre @ direction) * direction  # where the loaded points begin
    length *= 1.5  # one arrow for many: it may stand out more
    tail = head - length * direction
    ax.scatter(points[:, 0], points[:, 1], points[:, 2], s=6, color=LOAD, depthshade=False, zorder=4, gid="loaded")
    ax.quiver(*tail, *(length * direction), color=LOAD, arrow_length_ratio=0.3, linewidths=2.0, zorder=4, gid="loads")
    return tail[None]


def draw_gravity(ax, g, box) -> None:
    """An arrow along the gravity ``g`` (m/s²) labelled with it: in 2D in the axes' top left
    corner, in 3D beside the body's box ``box`` ((2, 3) low and high corners, which it extends)."""
    magnitude = float(np.linalg.norm(g))
    direction = np.asarray(g) / magnitude
    label = f"g = {magnitude:.3g} m/s²"
    if len(direction) == 2:
        ax.annotate("", xy=(0.08, 0.86), xycoords="axes fraction", xytext=-36 * direction, textcoords="offset points",
                    arrowprops=dict(arrowstyle="-|>", color=LOAD, lw=2.0, mutation_scale=14), gid="gravity")
        ax.text(0.11, 0.93, label, transform=ax.transAxes, fontsize=8, color="k", va="top", gid="gravity-label")
        return
    low, high = box
    extent = _extent(np.array([low, high]))
    tail = np.array([high[0] + 0.08 * extent, low[1], high[2]])  # past the body's far end, at its top
    arrow = 0.25 * extent * direction
    ax.quiver(*tail, *arrow, color=LOAD, arrow_length_ratio=0.3, linewidths=2.0, zorder=4, gid="gravity")
    ax.text(*tail, f"{label}  ", fontsize=8, color="k", ha="right", zorder=5, gid="gravity-label")
    box[0] = np.minimum.reduce([low, tail, tail + arrow])
    box[1] = np.maximum.reduce([high, tail, tail + arrow])


def draw_fixed(ax, x) -> int:
    """Markers (black triangles) on the fixed vertices, at ``x`` (deformed coordinates); how many."""
    if not len(x):
        return 0
    if x.shape[1] == 2:
        ax.plot(x[:, 0], x[:, 1], linestyle="none", marker="^", markersize=4, color=SUPPORT, zorder=4, gid="fixed")
    else:
        ax.scatter(x[:, 0], x[:, 1], x[:, 2], marker="^", s=10, color=SUPPORT, depthshade=False, zorder=4,
                   gid="fixed")
    return len(x)


def _fit_box(ax, box, pad: float = 0.03) -> None:
    """Limits around ``box`` ((2, 3) low and high corners) and a box aspect in proportion to
    them: the picture is to scale, with no room wasted on a cube around a long body."""
    from matplotlib.ticker import MaxNLocator

    low, high = np.asarray(box, dtype=np.float64)
    size = high - low
    margin = pad * size.max()
    low, high = low - margin, high + margin
    for setter, a, b in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), low, high):
        setter(a, b)
    ax.set_box_aspect(high - low, zoom=1.1)
    for axis, size in zip((ax.xaxis, ax.yaxis, ax.zaxis), high - low):  # fewer ticks on the short sides
        axis.set_major_locator(MaxNLocator(nbins=max(2, round(6 * size / (high - low).max()))))


def _scale_note(scale: float) -> str:
    return "displacement to scale" if scale == 1.0 else f"displacement ×{scale:g}"


def draw_body(body, title: str = "", displacement=None, scale: float = 1.0, decorate=None, highlight=None,
              view: tuple | None = None, reference: bool = True, fixed=None, loads=True):
    """The figure of ``plot_body`` (see there), not saved: (figure, axes)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    plt = _figure()
    u = body.displacement if displacement is None else np.asarray(displacement)
    magnitude = np.linalg.norm(u, axis=1)
    mesh = body.mesh
    points, deformed = mesh.points, mesh.points + scale * u
    note = _scale_note(scale)
    title = note if not title else f"{title} ({note})" if len(title) + len(note) < 45 else f"{title}\n({note})"
    live = np.unique(mesh.cells)
    length = ARROW * _extent(deformed[live])
    forces, gravity = applied_loads(body, None if loads is True else (loads or ()))
    if loads is not True and "gravity" not in (loads or ()):
        gravity = None
    held = np.zeros(0, dtype=np.int64) if fixed is None else np.asarray(fixed)
    if held.dtype == bool:
        held = np.flatnonzero(held)
    handles = []
    if highlight is not None:
        handles.append(Patch(color=HIGHLIGHT, label=None))  # labelled below, when counted
    if mesh.dim == 2:
        fig, ax = plt.subplots(figsize=(6, 5))
        shaded = draw_2d(ax, points, mesh.cells, u, scale, reference=reference, highlight=highlight)
        if highlight is not None:
            handles[0].set_label(f"incision ({len(highlight)} edges)")
        tails = draw_loads(ax, deformed, forces, length)
        if gravity is not None:
            draw_gravity(ax, gravity, None)
    else:
        import matplotlib.cm as cm
        import matplotlib.colors as colors
        from mpl_toolkits.mplot3d.art3d import Line3DCollection

        membrane = mesh.cell_dim == 2  # a surface mesh in 3D: its triangles are what is drawn
        faces = mesh.cells if membrane else mesh.boundary_faces()
        fig = plt.figure(figsize=(7, 5))
        ax = fig.add_subplot(projection="3d")
        ax.computed_zorder = False  # the wireframe behind the surface, markers and arrows on top
        if reference:
            edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
            ax.add_collection3d(Line3DCollection(points[edges], colors="0.7", linewidths=0.3, zorder=1,
                                                 gid="reference"))
        norm = colors.Normalize(vmin=magnitude.min(), vmax=max(magnitude.max(), 1e-300))
        marked = draw_3d(ax, points, faces, u, scale, norm, highlight)
        if highlight is not None:
            handles[0].set_label(f"incision ({marked} {'edges' if membrane else 'faces'})")
        surface = np.unique(faces)
        drawn = [deformed[surface]] + ([points[surface]] if reference else [])
        tails = draw_loads(ax, deformed, forces, length)
        every = np.concatenate(drawn + [tails])
        box = [every.min(axis=0), every.max(axis=0)]
        if gravity is not None:
            draw_gravity(ax, gravity, box)
        if view is not None:
            ax.view_init(*view)  # before the box aspect, which depends on the vertical axis it sets
        _fit_box(ax, box)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        shaded = cm.ScalarMappable(norm=norm, cmap="viridis")
    if decorate is not None:
        decorate(ax)
    if reference:
        handles.append(Line2D([], [], color="0.45", linewidth=0.8, linestyle=(0, (3, 2)), label="reference outline")
                       if mesh.dim == 2 else Line2D([], [], color="0.7", linewidth=0.8, label="reference"))
    if draw_fixed(ax, deformed[held]):
        handles.append(Line2D([], [], linestyle="none", marker="^", markersize=5, color=SUPPORT,
                              label=f"fixed ({len(held)} vertices)"))
    if len(tails):
        total = float(np.linalg.norm(forces.sum(axis=0)))
        handles.append(Line2D([], [], color=LOAD, linewidth=2, marker=">", markevery=[1], markersize=6,
                              label=f"load: {_newtons(total)} on {len(loaded_vertices(forces))} nodes"))
    existing, _ = ax.get_legend_handles_labels()  # a decoration's too
    if handles or existing:
        if mesh.dim == 2:  # below the axes, where it hides nothing
            ax.legend(handles=existing + handles, loc="upper center", bbox_to_anchor=(0.5, 0.0), borderaxespad=5.0,
                      ncol=2, fontsize=7, frameon=False)
        else:
            ax.legend(handles=existing + handles, loc="upper right", fontsize=7, framealpha=0.8)
    fig.colorbar(shaded, ax=ax, label="|u| [m]", shrink=0.7, pad=0.05 if mesh.dim == 2 else 0.15)
    ax.set_title(title)
    return fig, ax


def plot_body(body, path, title: str = "", displacement=None, scale: float = 1.0, decorate=None,
              highlight=None, view: tuple | None = None, reference: bool = True, fixed=None, loads=True) -> Path:
    """Save a PNG of the body: the deformed mesh (``displacement``, default the body's, times
    ``scale``) coloured by |u| (metres) with its edges, over the reference (grey: in 2D its
    outline, in 3D its boundary's wireframe; ``reference=False``: none). The title states the
    scale ("displacement ×20", or "to scale"); the axes are to scale. The loads are drawn as
    orange arrows (``loads``: True for every load channel and gravity, False for none, or the
    names of the channels to draw, "gravity" among them for gravity), ``fixed`` (vertex ids or
    a boolean mask) as black triangles. ``decorate(ax)`` draws on top (in 3D within the box of the body).
    ``highlight``, boundary faces ((m, 3) vertex ids, e.g. ``TetrahedralCutter.incision_faces()``)
    or in 2D and on a membrane (a surface mesh in 3D, whose triangles are drawn) boundary edges
    ((m, 2), e.g. ``DelaunayCutter.incision_edges()``), is drawn in red;
    ``view`` is the 3D camera: the arguments of ``Axes3D.view_init``, (elevation, azimuth) in
    degrees and optionally the roll and the vertical axis ("z", or "y" for a body loaded along y)."""
    plt = _figure()
    fig, ax = draw_body(body, title, displacement, scale, decorate, highlight, view, reference, fixed, loads)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    labels = [axis.label for axis in (ax.xaxis, ax.yaxis, getattr(ax, "zaxis", None)) if axis is not None]
    # the axis labels too: the tight box of a 3D axes may leave out one on its left
    fig.savefig(path, dpi=120, bbox_inches="tight", bbox_extra_artists=fig.get_default_bbox_extra_artists() + labels)
    plt.close(fig)
    return path


def save_3d(path, draw, title: str, figsize=(6, 5)) -> Path:
    """Save a PNG of one 3D picture: ``draw(ax)`` draws it on a 3D axis, titled ``title``."""
    plt = _figure()
    fig = plt.figure(figsize=figsize)
    ax = fig.add_subplot(projection="3d")
    draw(ax)
    ax.set_title(title)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return Path(path)


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
    # Not writer.saving(): on an exception (Ctrl-C while drawing) it would still call finish(),
    # which fails on a GIF without frames and hides the exception; nothing is written instead.
    writer.setup(fig, str(path), dpi=72)
    try:
        for frame in frames:
            for artist in [*ax.collections, *ax.lines, *ax.texts]:
                artist.remove()
            draw(ax, frame)
            writer.grab_frame()
        writer.finish()
    finally:
        plt.close(fig)
    return path
