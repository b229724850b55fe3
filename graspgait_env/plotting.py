"""Figures of objects, grasp maps and workspace maps (thesis ch. 3, 4.4–4.5, 6.1–6.2).

Every function draws on a :class:`matplotlib.figure.Figure` built directly (no
``pyplot``), so nothing here touches pyplot's global figure list or the interactive
backend: figures are garbage-collected like any object and saving works headless.

Every figure reads without the thesis: its axes say in words what they measure, and its
legend says what a dark cell, a box outline and each colour of a gait mean.

Conventions (as in the thesis and docs/conventions.md)
------------------------------------------------------
- Angles in degrees, counter-clockwise positive.
- Grasp map axes: horizontal ``phi_i`` (the contact of finger i), vertical ``phi_j``
  (the contact of finger j), both in the object frame ``f``; the origin of the map is at
  the bottom left (``imshow(..., origin="lower")``). A dark cell is a force-closure grasp
  at the map's friction ``mu`` (:data:`STABLE_LABEL`).
- Extended map (thesis fig. 3.3): the map tiled over [0°, 720°)². Overlaying the
  workspace map (fig. 4.5, 6.1–6.2) at object angle θ: a contact at ``phi`` lies at
  workspace angle ``phi + θ``, so, seen from the object frame, every finger pair box
  ``ws(fx) × ws(fy)`` is shifted by ``-θ`` along the diagonal; the workspace map repeats
  every 360° in each axis. A box labelled ``"fx-fy"`` holds the contact pairs that
  finger ``fx`` (horizontal axis) and finger ``fy`` (vertical axis) can both reach at θ.
- Gait figures (:func:`gait_figure`) colour the moves by :data:`GAIT_COLORS`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.ticker import MaxNLocator

from graspgait_env.atomic import atomic_write
from graspgait_env.grasp_map import GraspMap, grasp_map
from graspgait_env.shapes import Circle, Ellipse, Polygon, Shape
from graspgait_env.workspace import FingerPairBox, Hand

__all__ = [
    "plot_object",
    "plot_grasp_map",
    "plot_extended_map",
    "extended_box_rects",
    "map_figure",
    "sweep_objects",
    "sweep_figure",
    "save_figure",
    "atomic_write",
    "gait_path",
    "gait_figure",
    "SWEEP_MUS",
    "BOX_COLORS",
    "GAIT_COLORS",
    "STABLE_LABEL",
    "PHI_I_LABEL",
    "PHI_J_LABEL",
]

SWEEP_MUS: tuple[float, ...] = (0.9, 0.7, 0.5, 0.3, 0.1)  # thesis figs. 3.9, 3.11
BOX_COLORS = {"inner": "tab:blue", "outer": "tab:red"}  # finger pair box outlines
# gait figures: rotation and regrasp segments, the grasps, the first and the last state
GAIT_COLORS = {"rotate": "tab:orange", "regrasp": "magenta", "grasp": "white",
               "start": "tab:green", "end": "gold"}
_STABLE_CMAP = "Greys"  # stable cells dark, as the thesis shades them
STABLE_LABEL = "dark: the two contacts make a force-closure grasp at mu={mu:g}"
PHI_I_LABEL = "contact of finger i: object angle phi_i (deg)"
PHI_J_LABEL = "contact of finger j: object angle phi_j (deg)"
_SWEEP_SIZE = 0.08  # (m) larger semi-axis / circumradius of the sweep objects


def _contour(shape: Shape) -> np.ndarray:
    """Closed outline (m): polygon vertices exactly, smooth shapes sampled every 0.5°."""
    if isinstance(shape, Polygon):
        v = shape.vertices
        return np.vstack([v, v[:1]])
    return shape.contour_point(np.linspace(0.0, 360.0, 721))


def plot_object(
    ax: Axes,
    shape: Shape,
    *,
    normals_every_deg: float = 30.0,
    labels_deg: Sequence[float] = (0.0, 90.0, 180.0, 270.0),
    grasp: tuple[float, float] | None = None,
    mu: float | None = None,
    title: str | None = None,
    legend: bool = False,
) -> Figure:
    """Draw an object's contour in its frame ``f`` (thesis figs. 2.11, 3.1, 3.5).

    Parameters
    ----------
    ax
        Axes to draw on.
    shape
        The object.
    normals_every_deg
        Inward unit normals (arrows) are drawn at contacts every this many degrees,
        starting at 0°; contacts on a vertex (no normal) are skipped. ``0`` draws none.
    labels_deg
        Contact angles labelled with their degrees, a dotted ray from the origin to each.
    grasp
        Optional ``(phi_i, phi_j)`` (degrees): the two contacts of a grasp, marked and
        joined by a line.
    mu
        With ``grasp``, also draw each contact's friction cone (half-angle ``atan mu``).
    title
        Axes title; default the object's name.
    legend
        Add a legend below the axes naming the origin of ``f``, the normals and the
        contact angles.

    Returns
    -------
    Figure
        The figure ``ax`` belongs to.
    """
    xy = _contour(shape)
    r = shape.r_max
    ax.fill(xy[:, 0], xy[:, 1], color="0.92", zorder=0)
    ax.plot(xy[:, 0], xy[:, 1], color="k", lw=1.2)
    ax.plot([0.0], [0.0], marker="+", color="k", ms=8, mew=1.2)  # origin of f
    if normals_every_deg and normals_every_deg > 0:
        phi = np.arange(0.0, 360.0, float(normals_every_deg))
        phi = phi[~shape.is_vertex(phi)]
        p = shape.contour_point(phi)
        nrm = shape.inward_normal(phi) * (0.25 * r)
        ax.quiver(p[:, 0], p[:, 1], nrm[:, 0], nrm[:, 1], angles="xy", scale_units="xy",
                  scale=1.0, color="tab:green", width=0.006)
    for a in labels_deg:
        p = shape.contour_point(a)
        ax.plot([0.0, p[0]], [0.0, p[1]], ls=":", lw=0.7, color="0.5")
        q = (float(shape.radius(a)) + 0.18 * r) * np.array([math.cos(math.radians(a)),
                                                             math.sin(math.radians(a))])
        ax.text(q[0], q[1], f"{a:g}°", ha="center", va="center", fontsize=7, color="0.3")
    if grasp is not None:
        pts = shape.contour_point(np.asarray(grasp, dtype=float))
        ax.plot(pts[:, 0], pts[:, 1], color="tab:orange", lw=1.0, ls="--")
        ax.plot(pts[:, 0], pts[:, 1], "x", color="tab:orange", ms=9, mew=2)
        for name, phi_c, pt in zip(("i", "j"), grasp, pts, strict=True):
            ax.annotate(name, pt, xytext=(4, 4), textcoords="offset points",
                        color="tab:orange", fontsize=9)
            if mu is not None and not bool(shape.is_vertex(phi_c)):
                nv = shape.inward_normal(phi_c)
                half = math.atan(mu)
                for s in (-1.0, 1.0):
                    c, si = math.cos(s * half), math.sin(s * half)
                    d = np.array([c * nv[0] - si * nv[1], si * nv[0] + c * nv[1]]) * 0.5 * r
                    ax.plot([pt[0], pt[0] + d[0]], [pt[1], pt[1] + d[1]],
                            color="tab:orange", lw=0.8)
    lim = 1.35 * r
    ax.xaxis.set_major_locator(MaxNLocator(nbins=5, symmetric=True))
    ax.yaxis.set_major_locator(MaxNLocator(nbins=5, symmetric=True))
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x in the object frame f (m)")
    ax.set_ylabel("y in the object frame f (m)")
    ax.set_title(shape.name if title is None else title)
    if legend:
        handles = [Line2D([], [], ls="none", marker="+", color="k", ms=8,
                          label="origin of f: the centre of rotation")]
        if normals_every_deg and normals_every_deg > 0:
            handles.append(Line2D([], [], color="tab:green",
                                  label=f"inward normal, every {normals_every_deg:g} deg"))
        if len(labels_deg):
            handles.append(Line2D([], [], ls=":", color="0.5",
                                  label="contact named by its polar angle phi (deg)"))
        if grasp is not None:
            handles.append(Line2D([], [], ls="none", marker="x", color="tab:orange",
                                  label="grasp: contacts of fingers i and j"))
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.12),
                  ncol=1, fontsize=7, frameon=False)
    return ax.figure


def _map_extent(gm: GraspMap, span: float) -> list[float]:
    # cell k is centred on phi_k = k * step
    h = gm.step_deg / 2.0
    return [-h, span - h, -h, span - h]


def _degree_axes(ax: Axes, span: float, step: float) -> None:
    ticks = np.arange(0.0, span + 1e-9, step)
    ax.set_xticks(ticks)
    ax.set_yticks(ticks)
    ax.set_xlim(0.0, span)
    ax.set_ylim(0.0, span)
    ax.set_aspect("equal")
    ax.set_xlabel(PHI_I_LABEL)
    ax.set_ylabel(PHI_J_LABEL)


def _stable_handles(mu: float, short: bool = False) -> list[Patch]:
    """Legend entries for the shading of a grasp map at friction ``mu``."""
    if short:
        return [Patch(facecolor="black", edgecolor="0.5",
                      label=f"dark: force-closure grasp at mu={mu:g}"),
                Patch(facecolor="white", edgecolor="0.5", label="white: not force-closure")]
    return [Patch(facecolor="black", edgecolor="0.5", label=STABLE_LABEL.format(mu=mu)),
            Patch(facecolor="white", edgecolor="0.5",
                  label="white: not force-closure (or a contact on a vertex / out of reach)")]


def plot_grasp_map(
    ax: Axes,
    gm: GraspMap,
    *,
    grasp: tuple[float, float] | None = None,
    title: str | None = None,
    labels: bool = True,
) -> Figure:
    """Shade the stable cells of a grasp map (thesis figs. 2.11, 3.1–3.13).

    The horizontal axis is ``phi_i`` (the contact of finger i), the vertical ``phi_j``
    (finger j), in degrees of the object frame, origin at the bottom left; cell
    ``(i, j)`` is centred on ``(phi_i, phi_j)`` and dark when the pair is force-closure.

    Parameters
    ----------
    ax
        Axes to draw on.
    gm
        The grasp map.
    grasp
        Optional ``(phi_i, phi_j)`` to mark with an ``x`` (as the thesis does).
    title
        Axes title; default ``"grasp map, mu=..."``.
    labels
        Axis labels, ticks every 90° and a legend below the axes saying what a dark
        cell means; ``False`` for small multiples (ticks only).

    Returns
    -------
    Figure
        The figure ``ax`` belongs to.
    """
    # imshow puts array rows on the vertical axis: transpose so that x = phi_i
    ax.imshow(gm.stable.T, origin="lower", extent=_map_extent(gm, 360.0), cmap=_STABLE_CMAP,
              vmin=0, vmax=1, interpolation="nearest")
    _degree_axes(ax, 360.0, 90.0)
    if not labels:
        ax.set_xlabel("")
        ax.set_ylabel("")
    handles: list = _stable_handles(gm.mu)
    if grasp is not None:
        ax.plot([grasp[0] % 360.0], [grasp[1] % 360.0], "x", color="tab:orange", ms=9, mew=2)
        handles.append(Line2D([], [], ls="none", marker="x", color="tab:orange", mew=2,
                              label="the grasp (phi_i, phi_j)"))
    if labels:
        ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=1,
                  fontsize=7, frameon=False)
    ax.set_title(f"grasp map, mu={gm.mu:g}" if title is None else title)
    return ax.figure


def extended_box_rects(hand: Hand, theta_deg: float = 0.0,
                       span: float = 720.0) -> list[tuple[FingerPairBox, float, float]]:
    """Lower-left corners of the finger pair boxes in the extended map at angle θ.

    Seen from the object frame at object angle ``theta_deg``, the box
    ``ws(fx) × ws(fy)`` covers ``phi_i ∈ [xl - θ, xh - θ]``, ``phi_j ∈ [yl - θ, yh - θ]``
    and its copies every 360° in each axis (thesis 4.4, fig. 4.5 (b)).

    Returns
    -------
    list of (box, x0, y0)
        Every copy that overlaps the open square ``(0, span)²``; the copy spans
        ``[x0, x0 + width] × [y0, y0 + height]`` with the box's own width and height.
    """
    t = float(theta_deg) % 360.0
    out = []
    reps = range(-1, int(math.ceil(span / 360.0)) + 1)
    for box in hand.finger_pair_boxes:
        (xl, xh), (yl, yh) = box.x_deg, box.y_deg
        for a in reps:
            x0 = xl - t + 360.0 * a
            if x0 + (xh - xl) <= 0.0 or x0 >= span:
                continue
            for b in reps:
                y0 = yl - t + 360.0 * b
                if y0 + (yh - yl) <= 0.0 or y0 >= span:
                    continue
                out.append((box, x0, y0))
    return out


def plot_extended_map(
    ax: Axes,
    gm: GraspMap,
    hand: Hand | None = None,
    theta_deg: float = 0.0,
    *,
    box_labels: bool = True,
    title: str | None = None,
) -> Figure:
    """Extended grasp map over [0°, 720°)² with the workspace map overlaid (figs. 4.5, 6.1).

    The stable cells are shaded as in :func:`plot_grasp_map`; each finger pair box of
    ``hand`` is drawn as a rectangle outline (inner boxes blue, outer red) at its place
    seen from the object frame at object angle ``theta_deg``: shifted by ``-theta_deg``
    along the diagonal and repeated every 360° (see :func:`extended_box_rects`). Boxes
    are labelled ``"fx-fy"`` (finger on the horizontal axis first, e.g. ``"1-3"``).
    Each rectangle's ``gid`` is ``"box fx-fy kind"``. A legend below the axes says what
    a dark cell and a box mean: box ``fx-fy`` holds the contact pairs that finger
    ``fx`` and finger ``fy`` can both reach at θ.

    Parameters
    ----------
    ax
        Axes to draw on.
    gm
        The grasp map (object frame).
    hand
        The hand; default :meth:`Hand.default` (thesis fig. 4.1).
    theta_deg
        Object angle θ (degrees, counter-clockwise).
    box_labels
        Write the finger pair at the centre of each visible box.
    title
        Axes title; default names θ.

    Returns
    -------
    Figure
        The figure ``ax`` belongs to.
    """
    hand = Hand.default() if hand is None else hand
    span = 720.0
    ax.imshow(gm.extended().T, origin="lower", extent=_map_extent(gm, span), cmap=_STABLE_CMAP,
              vmin=0, vmax=1, interpolation="nearest")
    for box, x0, y0 in extended_box_rects(hand, theta_deg, span):
        w = box.x_deg[1] - box.x_deg[0]
        h = box.y_deg[1] - box.y_deg[0]
        color = BOX_COLORS.get(box.kind, "k")
        rect = Rectangle((x0, y0), w, h, fill=False, edgecolor=color, lw=1.2,
                         gid=f"box {box.finger_x}-{box.finger_y} {box.kind}")
        ax.add_patch(rect)
        cx, cy = x0 + w / 2, y0 + h / 2
        if box_labels and 0.0 < cx < span and 0.0 < cy < span:
            ax.text(cx, cy, f"{box.finger_x}-{box.finger_y}", color=color, fontsize=7,
                    ha="center", va="center", clip_on=True,
                    bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                          "alpha": 0.7})
    _degree_axes(ax, span, 180.0)
    ax.plot([0.0, span], [0.0, span], ls=":", lw=0.6, color="0.5")  # the +1 diagonal
    # compact (two columns): the GraspGait environments draw this panel in a small frame
    dark, white = _stable_handles(gm.mu, short=True)
    ax.legend(handles=[dark, Line2D([], [], color=BOX_COLORS["inner"],
                                    label="inner finger pair box"),
                       white, Line2D([], [], color=BOX_COLORS["outer"],
                                     label="outer finger pair box")],
              title=(f"box a-b: pairs fingers a (x) and b (y) both reach at "
                     f"theta={theta_deg:g} deg"),
              title_fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2,
              fontsize=7, frameon=False)
    ax.set_title(f"extended map and finger pair boxes, theta={theta_deg:g} deg"
                 if title is None else title)
    return ax.figure


def _smooth_label(shape: Shape) -> str:
    return "inf" if math.isinf(shape.smoothness) else str(int(shape.smoothness))


def map_figure(
    shape: Shape,
    mu: float,
    n: int = 180,
    hand: Hand | None = None,
    theta_deg: float = 0.0,
    *,
    gm: GraspMap | None = None,
    max_radius: float | None = None,
) -> Figure:
    """Three panels: the object with normals, its grasp map, the extended map with boxes.

    Parameters
    ----------
    shape
        The object.
    mu
        Coulomb friction coefficient.
    n
        Grid size of the grasp map.
    hand
        Hand whose finger pair boxes are overlaid; default the thesis hand.
    theta_deg
        Object angle at which the boxes are seen (thesis fig. 4.5).
    gm
        A grasp map already computed for ``(shape, mu, n)``; computed when ``None``.
    max_radius
        Reach cap passed to :func:`graspgait_env.grasp_map` when computing the map.

    Returns
    -------
    Figure
        A new figure (not registered with pyplot).
    """
    if gm is None:
        gm = grasp_map(shape, mu, n, max_radius=max_radius)
    hand = Hand.default() if hand is None else hand
    fig = Figure(figsize=(15.0, 6.0), layout="constrained")
    ax_o, ax_g, ax_e = fig.subplots(1, 3, width_ratios=[1.0, 1.0, 1.0])
    plot_object(ax_o, shape, title="object in its frame f", legend=True)
    plot_grasp_map(ax_g, gm)
    plot_extended_map(ax_e, gm, hand, theta_deg)
    fig.suptitle(
        f"{shape.name}: mu={gm.mu:g}, E={shape.eccentricity:.3g} (r_max / r_min), "
        f"S={_smooth_label(shape)} (sides; inf: smooth)"
        f" (n={gm.n}, {100 * gm.fraction_stable():.1f}% of pairs stable; hand {hand.name},"
        f" gap w={hand.w_deg:g} deg)"
    )
    return fig


def sweep_objects(kind: str) -> list[tuple[str, Shape]]:
    """The rows of a sweep figure (thesis figs. 3.8–3.11), as ``(label, shape)``.

    As in the thesis (figs. 3.9, 3.11), the property decreases down the rows.
    ``"eccentricity"``: ellipses of E = 100, 3, 2, 1.5 and a circle (E = 1), larger
    semi-axis 0.08 m along x (the map depends only on the shape, not its size; E = 100
    is a thin sliver). ``"smoothness"``: a circle, then regular polygons of 8, 6, 5, 4, 3
    sides of the same circumradius, a vertex at 90° (E as near 1 as a polygon allows).
    """
    r = _SWEEP_SIZE
    if kind == "eccentricity":
        out: list[tuple[str, Shape]] = []
        for e in (100.0, 3.0, 2.0, 1.5):
            out.append((f"E={e:g}", Ellipse(r, r / e, name=f"E={e:g}")))
        out.append(("E=1", Circle(r, name="E=1")))
        return out
    if kind == "smoothness":
        out = [("S=inf", Circle(r, name="circle"))]
        for sides in (8, 6, 5, 4, 3):
            a = np.deg2rad(90.0 + 360.0 * np.arange(sides) / sides)
            out.append((f"S={sides}", Polygon(np.stack([r * np.cos(a), r * np.sin(a)], 1),
                                              name=f"{sides}-gon")))
        return out
    raise ValueError(f"kind={kind!r}: use 'eccentricity' or 'smoothness'")


def sweep_figure(kind: str, mus: Sequence[float] = SWEEP_MUS, n: int = 180) -> Figure:
    """Grasp maps of a family of objects at decreasing friction (thesis figs. 3.8–3.11).

    Rows are the objects of :func:`sweep_objects` (eccentricity or smoothness
    decreasing down the rows); the first column shows each object's outline, the next
    ones its grasp map for each ``mu`` in ``mus`` (friction decreasing to the right).

    Parameters
    ----------
    kind
        ``"eccentricity"`` or ``"smoothness"``.
    mus
        Friction coefficients, one column each (thesis: .9, .7, .5, .3, .1).
    n
        Grid size of each grasp map.

    Returns
    -------
    Figure
        A new figure (not registered with pyplot).
    """
    rows = sweep_objects(kind)
    mus = tuple(mus)
    cols = 1 + len(mus)
    fig = Figure(figsize=(2.1 * cols, 2.1 * len(rows) + 0.6), layout="constrained")
    axes = fig.subplots(len(rows), cols, squeeze=False)
    for r, (label, shape) in enumerate(rows):
        ax = axes[r, 0]
        plot_object(ax, shape, normals_every_deg=0, labels_deg=(), title="")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_xlabel("")
        ax.set_ylabel(label, fontsize=11)
        if r == 0:
            ax.set_title("object", fontsize=10)
        for c, mu in enumerate(mus, start=1):
            ax = axes[r, c]
            gm = grasp_map(shape, mu, n)
            plot_grasp_map(ax, gm, title="", labels=False)
            ax.set_xticks([0, 180, 360])
            ax.set_yticks([0, 180, 360])
            ax.tick_params(labelsize=6)
            frac = gm.fraction_stable()
            ax.text(0.98, 0.02, f"{100 * frac:.0f}%", transform=ax.transAxes, ha="right",
                    va="bottom", fontsize=6, color="tab:blue",
                    bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none"})
            if frac == 0.0:  # thesis fig. 3.11: low friction, no stable grasp at all
                ax.text(0.5, 0.5, "no stable\ngrasps", transform=ax.transAxes, ha="center",
                        va="center", fontsize=8, color="0.4")
            if r == 0:
                ax.set_title(f"mu={mu:g}", fontsize=10)
            if r == len(rows) - 1:
                ax.set_xlabel("finger i contact phi_i (deg)", fontsize=7)
            if c == 1:
                ax.set_ylabel("finger j contact phi_j (deg)", fontsize=7)
    what = "eccentricity" if kind == "eccentricity" else "smoothness"
    fig.suptitle(f"Grasp maps: {what} decreasing down the rows, friction decreasing to the "
                 f"right (n={n}; % = stable fraction)")
    fig.legend(handles=[Patch(facecolor="black", edgecolor="0.5",
                              label="dark: the two contacts (phi_i, phi_j), object frame, "
                              "make a force-closure grasp at the column's mu"),
                        Patch(facecolor="white", edgecolor="0.5", label="white: not "
                              "force-closure"),
                        Line2D([], [], ls="none",
                               label="rows: E = r_max / r_min (1: circle)"
                               if kind == "eccentricity"
                               else "rows: S = number of sides (inf: smooth)")],
               loc="outside lower center", ncol=3, fontsize=8, frameon=False)
    return fig


def save_figure(fig: Figure, path: str | os.PathLike[str], *, dpi: int = 110) -> Path:
    """Write ``fig`` to ``path`` atomically (see :func:`atomic_write`), creating parents.

    The format follows the suffix (``.png``, ``.pdf``, ``.svg``...); PNG without one.

    Returns
    -------
    Path
        The path written.
    """
    fmt = Path(path).suffix[1:].lower() or "png"
    return atomic_write(path, lambda fh: fig.savefig(fh, format=fmt, dpi=dpi))


def gait_path(plan_steps: Sequence[dict]) -> list[dict]:
    """Replay a plan's steps into the points a gait figure draws (thesis figs. 4.6–4.8, 6.10).

    The two held contacts are put on the axes (the lower-numbered finger of the first
    grasp on x); at a regrasp the new contact takes the axis of the lifted one, unwrapped
    to within 180° of it, so the path is continuous in the extended map.

    Returns
    -------
    list of dict
        One entry per state: ``op`` (grasp/rotate/regrasp), ``obj`` = (x, y) unwrapped
        object-frame contacts (deg), ``ws`` = (x, y) unwrapped workspace-frame angles
        (contacts plus θ), ``fingers`` = (finger on x, finger on y), ``theta`` (deg).
    """
    first = plan_steps[0]["contacts"]
    (fx, px), (fy, py) = sorted((int(f), float(v)) for f, v in first.items())
    theta = 0.0
    pts = [{"op": "grasp", "obj": (px, py), "fingers": (fx, fy), "theta": theta}]
    for st in plan_steps[1:]:
        if st["op"] == "rotate":
            theta += float(st["delta"])
            pts.append({**pts[-1], "op": "rotate", "theta": theta})
            continue
        new = {int(f): float(v) for f, v in st["contacts"].items()}
        (x, y), (fx, fy) = pts[-1]["obj"], pts[-1]["fingers"]
        if fx in new:  # x kept: the new finger takes y
            (h,) = set(new) - {fx}
            y = y + ((new[h] - y + 180.0) % 360.0 - 180.0)
            fy = h
        else:
            (h,) = set(new) - {fy}
            x = x + ((new[h] - x + 180.0) % 360.0 - 180.0)
            fx = h
        pts.append({"op": "regrasp", "obj": (x, y), "fingers": (fx, fy), "theta": theta})
    for p in pts:
        p["ws"] = (p["obj"][0] + p["theta"], p["obj"][1] + p["theta"])
    return pts


def _box_label(ax: Axes, text: str, x: float, y: float, color: str, fontsize: float) -> None:
    ax.text(x, y, text, color=color, fontsize=fontsize, ha="center", va="center",
            clip_on=True, bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                                "alpha": 0.7})


def _segments(xy: np.ndarray, pts: Sequence[dict], op: str) -> np.ndarray:
    """The path segments that end in an ``op`` step, NaN-separated for one ``plot``."""
    out = []
    for i in range(1, len(pts)):
        if pts[i]["op"] == op:
            out += [xy[i - 1], xy[i], (np.nan, np.nan)]
    return np.array(out, dtype=float).reshape(-1, 2)


def gait_figure(gm: GraspMap, hand: Hand, plan_steps: Sequence[dict],
                title: str = "") -> Figure:
    """A gait drawn two ways (thesis figs. 4.6–4.8, 6.10).

    Left, the **workspace frame**: the finger pair boxes of the extended workspace map
    stand still (each labelled ``a-b``: finger a on the horizontal axis, finger b on the
    vertical); rotations are diagonal segments (both workspace angles grow by the same
    amount), regrasps horizontal or vertical moves into another box. Right, the
    **object frame**: the extended grasp map with the sequence of grasps; rotations
    leave the grasp point in place (the boxes slide instead, fig. 4.5) and regrasps are
    horizontal or vertical moves, giving the staircase or plus patterns of fig. 6.10.

    Colours (:data:`GAIT_COLORS`, named in the figure's legend below the panels):
    rotations orange, regrasps magenta, grasps white dots numbered in order with their
    fingers (``k: a-b``), the start a green square, the end a gold star; boxes inner
    blue, outer red; dark cells force-closure at the map's ``mu``.
    """
    pts = gait_path(plan_steps)
    fig = Figure(figsize=(13, 7.6), layout="constrained")
    axes = fig.subplots(1, 2)
    col = GAIT_COLORS
    for ax, key in zip(axes, ("ws", "obj"), strict=True):
        xy = np.array([p[key] for p in pts])
        # a square window round the path, 60 degrees of margin on its longer side
        mid = (xy.min(axis=0) + xy.max(axis=0)) / 2.0
        half = float(np.ptp(xy, axis=0).max()) / 2.0 + 60.0
        (xlo, ylo), (xhi, yhi) = mid - half, mid + half
        lo, hi = min(xlo, ylo), max(xhi, yhi)
        if key == "obj":
            # tile the grasp map over the window (cell k centred on k * step)
            n, step = gm.n, gm.step_deg
            ix = np.arange(int(np.floor(xlo / step)), int(np.ceil(xhi / step)) + 1)
            iy = np.arange(int(np.floor(ylo / step)), int(np.ceil(yhi / step)) + 1)
            tile = gm.stable[np.ix_(ix % n, iy % n)]
            ax.imshow(tile.T, origin="lower", cmap=_STABLE_CMAP, vmin=0, vmax=1,
                      interpolation="nearest",
                      extent=[ix[0] * step - step / 2, ix[-1] * step + step / 2,
                              iy[0] * step - step / 2, iy[-1] * step + step / 2])
            ax.set_title("object frame f: extended grasp map and the grasps\n"
                         "(a rotation leaves the grasp in place; the boxes slide instead)")
        else:
            reps = range(int(np.floor(lo / 360.0)) - 1, int(np.ceil(hi / 360.0)) + 1)
            for box in hand.finger_pair_boxes:
                (xl, xh), (yl, yh) = box.x_deg, box.y_deg
                color = BOX_COLORS.get(box.kind, "k")
                for a in reps:
                    for b in reps:
                        x0, y0 = xl + 360.0 * a, yl + 360.0 * b
                        ax.add_patch(Rectangle((x0, y0), xh - xl, yh - yl, fill=False,
                                               edgecolor=color, lw=1.0,
                                               gid=f"box {box.finger_x}-{box.finger_y} "
                                               f"{box.kind}"))
                        cx, cy = x0 + (xh - xl) / 2, y0 + (yh - yl) / 2
                        if xlo < cx < xhi and ylo < cy < yhi:
                            _box_label(ax, f"{box.finger_x}-{box.finger_y}", cx, cy, color, 6)
            ax.set_title("workspace frame F: finger pair boxes stand still,\n"
                         "rotations are diagonal moves")
        rot = _segments(xy, pts, "rotate")
        reg = _segments(xy, pts, "regrasp")
        ax.plot(rot[:, 0], rot[:, 1], "-", color=col["rotate"], lw=1.8, zorder=3)
        ax.plot(reg[:, 0], reg[:, 1], "-", color=col["regrasp"], lw=1.8, zorder=3)
        grasps = [i for i, p in enumerate(pts) if p["op"] != "rotate"]
        ax.plot(xy[grasps, 0], xy[grasps, 1], "o", mfc=col["grasp"], mec="k", ms=5,
                zorder=4)
        ax.plot(*xy[0], "s", color=col["start"], mec="k", ms=9, zorder=5)
        ax.plot(*xy[-1], "*", color=col["end"], mec="k", ms=14, zorder=5)
        for num, i in enumerate(grasps):
            fx, fy = pts[i]["fingers"]
            ax.annotate(f"{num}: {fx}-{fy}", xy[i], textcoords="offset points", xytext=(5, -9),
                        fontsize=7, color="k",
                        bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none",
                              "alpha": 0.75})
        ax.set_xlim(xlo, xhi)
        ax.set_ylim(ylo, yhi)
        ax.set_aspect("equal")
        if key == "obj":
            ax.set_xlabel("finger on x: contact phi, object frame (deg, unwrapped)")
            ax.set_ylabel("finger on y: contact phi, object frame (deg, unwrapped)")
        else:
            ax.set_xlabel("finger on x: workspace angle phi + theta, frame F (deg, unwrapped)")
            ax.set_ylabel("finger on y: workspace angle phi + theta, frame F (deg, unwrapped)")
    dark, white = _stable_handles(gm.mu)
    dark.set_label("right, " + dark.get_label())
    white.set_label("right, " + white.get_label())
    handles = [  # filled column by column, three rows
        Line2D([], [], color=col["rotate"], lw=1.8,
               label="rotation: the object turns, both contacts held"),
        Line2D([], [], color=col["regrasp"], lw=1.8,
               label="regrasp: the free finger placed, then one old finger lifted"),
        Line2D([], [], ls="none", marker="o", mfc=col["grasp"], mec="k", ms=5,
               label="grasp k: a-b = finger a on x, finger b on y"),
        Line2D([], [], ls="none", marker="s", color=col["start"], mec="k", ms=8,
               label="start (theta = 0)"),
        Line2D([], [], ls="none", marker="*", color=col["end"], mec="k", ms=12,
               label="end (the turn achieved)"),
        Line2D([], [], color=BOX_COLORS["inner"],
               label="left, inner finger pair box a-b: fingers a (x) and b (y) reach"),
        Line2D([], [], color=BOX_COLORS["outer"],
               label="left, outer finger pair box a-b: fingers a (x) and b (y) reach"),
        dark, white,
    ]
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=8, frameon=False)
    fig.suptitle(title)
    return fig
