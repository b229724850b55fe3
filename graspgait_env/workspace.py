"""Finger workspaces, finger pair boxes and the workspace map (thesis 4.2).

A finger's workspace is the arc of workspace-frame (``F``) angles it can reach. The
thesis assumes three equal, non-overlapping workspaces; the default hand of fig. 4.1
has finger 1 on [0°, 90°], finger 2 on [120°, 210°], finger 3 on [240°, 330°], and
the gap between workspaces ``w = 30°``.

The workspace map is the grasp-map-like space of two ``F`` angles: ``(x, y)`` is a
valid grasp when ``x`` and ``y`` lie in the workspaces of two different fingers; the
regions of valid pairs are the *finger pair boxes* ``ws(fx) × ws(fy)``.

Inner and outer boxes: the thesis calls the boxes nearest the ``y = x`` line *inner*
and the farthest *outer* (fig. 4.4), and notes that in the extended map they lie in
bands along the diagonal. A gait climbs the positive diagonal with the ``y`` contact
ahead of the ``x`` contact, so we classify by the box's diagonal offset
``d = (c_y - c_x) mod 360`` (box centres): **inner when d < 180°, outer otherwise**.
For boxes above the ``y = x`` line of the [0, 360)² square this is exactly fig. 4.4
(box x=1, y=3 is outer, x=1, y=2 inner); the boxes below the line are the mirror
images of those above and take the kind of their place in the extended band
(x=2, y=1 lies at offset 240° in the extended map: outer). This choice is tested.

Effective workspaces (thesis 4.2, figs. 4.2–4.3): with circular reach limits, the arc
in which a finger can touch every radius between the object's smallest and largest
is the intersection of the arcs for those two radii (the reach condition is convex in
the radius, so the two extremes are the binding ones).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspgait_env.errors import ConfigError
from graspgait_env.objects import positive_length, read_yaml_mapping
from graspgait_env.resources import bundled_file, bundled_names, config_dir
from graspgait_env.shapes import Shape

__all__ = [
    "Hand",
    "FingerPairBox",
    "CircularReach",
    "workspace_map",
    "effective_workspace",
    "effective_hand",
    "load_hand",
    "bundled_hands",
    "DEFAULT_WORKSPACES_DEG",
]

HAND_DIR = config_dir("hands")
DEFAULT_WORKSPACES_DEG: tuple[tuple[float, float], ...] = ((0.0, 90.0), (120.0, 210.0),
                                                             (240.0, 330.0))
_EPS_DEG = 1e-9  # (degrees) slack on workspace edges, so a grid angle on an edge is inside


@dataclass(frozen=True)
class FingerPairBox:
    """The box ``ws(finger_x) × ws(finger_y)`` of the workspace map (degrees, frame F).

    ``x_deg`` and ``y_deg`` are ``(lo, hi)`` with ``0 <= lo < 360`` and ``hi > lo``
    (``hi`` may exceed 360 for a workspace that wraps through 0°).
    """

    finger_x: int
    finger_y: int
    x_deg: tuple[float, float]
    y_deg: tuple[float, float]
    kind: str  # "inner" | "outer"

    @property
    def index(self) -> tuple[int, int]:
        """(finger_x, finger_y), the fingers numbered from 1."""
        return (self.finger_x, self.finger_y)


@dataclass(frozen=True)
class Hand:
    """Three (or more) finger workspaces as arcs in frame ``F``.

    Parameters
    ----------
    workspaces_deg
        One ``(lo, hi)`` arc per finger, finger 1 first, degrees CCW, ``lo < hi``,
        width in (0, 360). Arcs may not overlap or touch (the thesis chooses
        non-overlapping workspaces to avoid finger cross-over, 4.2).
    name
        A label.

    Examples
    --------
    >>> h = Hand.default()
    >>> h.finger_at([45.0, 100.0, 210.0, 330.0]).tolist()
    [1, 0, 2, 3]
    >>> h.w_deg
    30.0
    """

    workspaces_deg: tuple[tuple[float, float], ...] = DEFAULT_WORKSPACES_DEG
    name: str = "thesis"

    def __post_init__(self) -> None:
        ws = _validate_workspaces(self.workspaces_deg, f"Hand {self.name!r}")
        object.__setattr__(self, "workspaces_deg", ws)

    @classmethod
    def default(cls) -> Hand:
        """The hand of thesis fig. 4.1 (90° workspaces, w = 30°)."""
        return cls(DEFAULT_WORKSPACES_DEG, "thesis")

    @property
    def n_fingers(self) -> int:
        """Number of fingers."""
        return len(self.workspaces_deg)

    @property
    def gaps_deg(self) -> tuple[float, ...]:
        """Gaps between consecutive workspaces going CCW round the palm (degrees)."""
        order = sorted(range(self.n_fingers), key=lambda k: self.workspaces_deg[k][0])
        gaps = []
        for a, b in zip(order, order[1:] + order[:1], strict=True):
            gaps.append((self.workspaces_deg[b][0] - self.workspaces_deg[a][1]) % 360.0)
        return tuple(gaps)

    @property
    def w_deg(self) -> float:
        """The gap ``w`` between workspaces (thesis 4.2); the smallest gap if unequal."""
        return float(min(self.gaps_deg))

    def finger_at(self, angle_deg: ArrayLike) -> NDArray[np.int8]:
        """Finger (1-based) whose workspace holds each ``F`` angle; 0 where none reaches."""
        a = np.asarray(angle_deg, dtype=np.float64)
        out = np.zeros(a.shape, dtype=np.int8)
        for k, (lo, hi) in enumerate(self.workspaces_deg):
            inside = np.mod(a - lo + _EPS_DEG, 360.0) <= (hi - lo) + 2 * _EPS_DEG
            out[inside] = k + 1
        return out

    @property
    def finger_pair_boxes(self) -> list[FingerPairBox]:
        """Every ordered pair of different fingers as a box of the workspace map."""
        boxes = []
        for i, (xl, xh) in enumerate(self.workspaces_deg):
            for j, (yl, yh) in enumerate(self.workspaces_deg):
                if i == j:
                    continue
                d = ((yl + yh) / 2 - (xl + xh) / 2) % 360.0
                boxes.append(FingerPairBox(i + 1, j + 1, (xl, xh), (yl, yh),
                                           "inner" if d < 180.0 else "outer"))
        return boxes

    def box_kind(self, finger_x: int, finger_y: int) -> str:
        """'inner' or 'outer' for the box of (finger_x, finger_y)."""
        for b in self.finger_pair_boxes:
            if b.index == (finger_x, finger_y):
                return b.kind
        raise ValueError(f"no finger pair box ({finger_x}, {finger_y}) on hand {self.name!r}")

    def to_dict(self) -> dict[str, Any]:
        """The hand as the ``workspaces_deg`` list of the plan JSON (docs/formats.md)."""
        return {"name": self.name, "workspaces_deg": [list(w) for w in self.workspaces_deg]}


def _validate_workspaces(ws: Any, src: str) -> tuple[tuple[float, float], ...]:
    field = "workspaces_deg"
    if not isinstance(ws, (list, tuple)) or len(ws) < 2:
        raise ConfigError(src, field, f"expected a list of at least 2 [lo, hi] arcs, got {ws!r}",
                          "give one [lo, hi] arc in degrees per finger, e.g. [[0, 90], ...]")
    out = []
    for k, arc in enumerate(ws):
        f = f"{field}[{k}]"
        if not isinstance(arc, (list, tuple)) or len(arc) != 2:
            raise ConfigError(src, f, f"expected [lo, hi], got {arc!r}", "give [lo, hi] in degrees")
        for v in arc:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ConfigError(src, f, f"{v!r} is not a finite number of degrees",
                                  "give [lo, hi] in degrees")
        lo, hi = float(arc[0]), float(arc[1])
        if not 0.0 <= lo < 360.0:
            raise ConfigError(src, f, f"lo={lo} is out of range",
                              "start each workspace at an angle in [0, 360)")
        if not 0.0 < hi - lo < 360.0:
            raise ConfigError(src, f, f"[{lo}, {hi}] is empty or a full turn",
                              "give hi > lo with a width below 360 degrees")
        out.append((lo, hi))
    for i in range(len(out)):
        for j in range(i + 1, len(out)):
            (a0, a1), (b0, b1) = out[i], out[j]
            # arcs overlap (or touch) when one's start lies inside the other, modulo 360
            if (b0 - a0) % 360.0 <= a1 - a0 or (a0 - b0) % 360.0 <= b1 - b0:
                raise ConfigError(src, f"{field}[{j}]",
                                  f"workspace of finger {j + 1} {list(out[j])} overlaps or touches "
                                  f"finger {i + 1}'s {list(out[i])}",
                                  "leave a gap between workspaces (thesis 4.2)")
    return tuple(out)


def workspace_map(hand: Hand, n: int = 180, theta_deg: float = 0.0) -> NDArray[np.int8]:
    """The workspace map seen from the object frame at object angle ``theta_deg``.

    Cell ``(i, j)`` is the grasp of contacts ``phi_i, phi_j`` (object frame, grid of
    :func:`graspgait_env.grid_angles_deg`); at object angle θ they lie at ``F`` angles
    ``phi + θ``. The value is the index into ``hand.finger_pair_boxes`` of the box
    holding that grasp, or -1 where the pair is not a valid two-finger grasp.
    At ``theta_deg = 0`` this is fig. 4.4; other angles slide the boxes along the
    diagonal (fig. 4.5).
    """
    phi = 360.0 * np.arange(n) / n
    f = hand.finger_at(phi + theta_deg).astype(np.int16)
    m = hand.n_fingers
    # ordered pair (fx, fy), fx != fy, to its box index in finger_pair_boxes order
    lut = -np.ones((m + 1, m + 1), dtype=np.int8)
    for k, b in enumerate(hand.finger_pair_boxes):
        lut[b.finger_x, b.finger_y] = k
    return lut[f[:, None], f[None, :]]


@dataclass(frozen=True)
class CircularReach:
    """A finger whose tip reaches a disc: centre ``base`` (m, frame F), radius ``reach`` (m)."""

    base: tuple[float, float]
    reach: float


def effective_workspace(finger: CircularReach, r_lo: float, r_hi: float) -> tuple[float, float]:
    """Effective workspace arc (degrees, F) of a circular-reach finger (thesis 4.2, fig. 4.2).

    The arc of angles ``phi`` at which the finger reaches the object's contour for any
    orientation: the circles of radius ``r_lo`` and ``r_hi`` about the origin must
    both cross the reach disc there; the conservative (narrower) pair of crossing
    angles bounds the arc.

    Raises
    ------
    ValueError
        When a circle misses the disc (the object is too large or small for the
        finger): lower ``r_hi`` with ``max_radius`` (fig. 4.3) or move the finger.
    """
    bx, by = finger.base
    D = math.hypot(bx, by)
    psi = math.degrees(math.atan2(by, bx))
    half = 180.0
    for r in (r_lo, r_hi):
        if D == 0:
            raise ValueError("finger base at the origin: the object occupies it; move the base")
        kappa = (r * r + D * D - finger.reach**2) / (2 * r * D)
        if kappa > 1:
            raise ValueError(
                f"radius {r:.4f} m is out of reach of the finger at {finger.base} "
                f"(reach {finger.reach} m); lower max_radius (thesis fig. 4.3) or move the finger"
            )
        if kappa > -1:
            half = min(half, math.degrees(math.acos(kappa)))
    if half >= 180.0:
        raise ValueError(f"finger at {finger.base} reaches all round the object; "
                         "the thesis's workspaces are arcs: shorten its reach")
    return ((psi - half) % 360.0, (psi - half) % 360.0 + 2 * half)


def effective_hand(fingers: Sequence[CircularReach], shape: Shape,
                   max_radius: float | None = None, name: str = "effective") -> Hand:
    """The :class:`Hand` of effective workspaces for ``shape`` (thesis 4.2).

    ``max_radius`` (fig. 4.3) caps the largest radius used; contacts beyond it must be
    marked unusable in the grasp map (``grasp_map(..., max_radius=...)``).
    """
    r_hi = shape.r_max if max_radius is None else min(shape.r_max, max_radius)
    r_lo = min(shape.r_min, r_hi)
    return Hand(tuple(effective_workspace(f, r_lo, r_hi) for f in fingers), name)


def bundled_hands() -> list[str]:
    """Names of the hand files shipped in ``configs/hands/``."""
    return bundled_names("hands")


def load_hand(name_or_path: str | Path | Hand | None = None,
              shape: Shape | None = None) -> tuple[Hand, float | None]:
    """Load a hand from a bundled name, a YAML path, or pass a :class:`Hand` through.

    Hand YAML, either explicit arcs::

        name: thesis
        workspaces_deg: [[0, 90], [120, 210], [240, 330]]

    or circular reach limits, turned into effective workspaces for ``shape``::

        name: reach
        reach: [{base: [0.07, 0.07], reach: 0.09}, ...]
        max_radius: 0.1       # optional, m (fig. 4.3)

    Returns
    -------
    hand, max_radius
        ``max_radius`` is the reach cap to pass to :func:`graspgait_env.grasp_map`
        (``None`` for an explicit-arc hand).
    """
    if name_or_path is None:
        return Hand.default(), None
    if isinstance(name_or_path, Hand):
        return name_or_path, None
    s = str(name_or_path)
    path = Path(s)
    if not (s.endswith((".yaml", ".yml")) or path.exists()):
        bundled = bundled_file("hands", s)
        if bundled is None:
            raise ConfigError(s, "hand", "no bundled hand of that name and no such file",
                              f"use one of {', '.join(bundled_hands())} or a hand YAML path")
        path = bundled
    src = str(path)
    data = read_yaml_mapping(path, "hand")
    allowed = {"name", "workspaces_deg", "reach", "max_radius", "description"}
    unknown = sorted(set(data) - allowed, key=str)
    if unknown:
        raise ConfigError(src, str(unknown[0]), "unknown key",
                          f"remove it; allowed keys: {', '.join(sorted(allowed))}")
    name = data.get("name", path.stem)
    if ("workspaces_deg" in data) == ("reach" in data):
        raise ConfigError(src, "workspaces_deg", "give exactly one of workspaces_deg or reach",
                          "describe the hand by arcs or by circular reach limits")
    if "workspaces_deg" in data:
        return Hand(_validate_workspaces(data["workspaces_deg"], src), str(name)), None
    if shape is None:
        raise ConfigError(src, "reach", "a reach hand needs the object to find its workspaces",
                          "pass the object (shape=...) along with the hand")
    fingers = []
    for k, f in enumerate(data["reach"] if isinstance(data["reach"], list) else [None]):
        fld = f"reach[{k}]"
        if not isinstance(f, dict) or set(f) != {"base", "reach"}:
            raise ConfigError(src, fld, f"expected {{base: [x, y], reach: r}}, got {f!r}",
                              "give each finger's disc centre and radius in metres")
        b = f["base"]
        if not (isinstance(b, list) and len(b) == 2 and all(
                isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c)
                for c in b)):
            raise ConfigError(src, f"{fld}.base", f"expected [x, y] metres, got {b!r}",
                              "give the disc centre as [x, y]")
        r = positive_length(src, f"{fld}.reach", f["reach"])
        fingers.append(CircularReach((float(b[0]), float(b[1])), r))
    max_radius = data.get("max_radius")
    if max_radius is not None:
        max_radius = positive_length(src, "max_radius", max_radius)
    try:
        hand = effective_hand(fingers, shape, max_radius, str(name))
    except ConfigError as exc:  # the effective arcs overlap: say so once, about this file
        raise ConfigError(src, "reach", f"the effective workspaces {exc.problem}",
                          exc.fix) from None
    except ValueError as exc:
        raise ConfigError(src, "reach", str(exc).split("; ")[0],
                          str(exc).split("; ")[-1]) from None
    return hand, max_radius
