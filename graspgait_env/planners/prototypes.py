"""Prototype regions of a grasp map and the necessary conditions for prototype gaits.

Thesis 6.2 approximates the stable region of a grasp map by one of two simple shapes:

- a **band** along the positive diagonal with slope-1 edges (continuous maps, low
  eccentricity, fig. 6.3 (a)) — the home of the *forward* (staircase) gait, 6.3.1;
- an axis-aligned **box** (discontinuous maps, fig. 6.3 (b)) — the home of the
  *back-and-forth* (plus / combined) gait, 6.3.2.

Coordinates
-----------
``stable[x, y]`` with ``x`` the horizontal and ``y`` the vertical grasp-map coordinate
(thesis 4.2), both grid indices ``0 .. n-1`` of ``phi = 360 k / n`` degrees. A band is a
set of *diagonal offsets* ``d = (y - x) mod n``: the cells ``(i, (i + d) mod n)`` for
every ``i`` (it must run along the whole diagonal, fig. 6.3 (a), so it slides onto itself
when the object turns, fig. 6.4). Its **height** is ``(d_hi - d_lo)`` grid steps: the
vertical extent of a slope-1 band, i.e. its extent in offset terms, which is what the
thesis compares with ``w`` (6.3.1 condition 2); the perpendicular width is the height
divided by √2 and is reported as ``width_perp_deg``. Box sides are likewise measured
between the outermost stable grid contacts: a box of ``c`` cells spans ``(c - 1)`` grid
steps. Every size here is a distance between grid contacts, so "height >= w" means a
step of ``w`` fits inside the region.

The map is symmetric (``stable[x, y] == stable[y, x]``), so every band ``[d_lo, d_hi]``
comes with its mirror ``[n - d_hi, n - d_lo]`` below the diagonal, and every box with its
transpose; a grasp lies in a band if either of its two readings (which finger is ``x``)
does.

Workspace geometry
------------------
:class:`WorkspaceGrid` holds the finger workspaces on the grid (``ws_start``,
``ws_width`` exactly as :class:`graspgait_env.gait.GaitModel` computes them), the gap
``w`` in grid steps and the diagonal-offset range of every finger pair box: box
``(f_x, f_y)`` holds grasps with offsets ``y - x`` in ``[D - (W_x - 1), D + (W_y - 1)]``,
``D = (s_y - s_x) mod n``. Inner/outer follows :mod:`graspgait_env.workspace` (box
centre offset below or above 180°). For the thesis hand: inner boxes [30°, 210°], outer
[150°, 330°], ``w = 30°``.

Conditions (thesis 6.3)
-----------------------
Every check returns a :class:`Check` ``(ok, reason)`` whose reason names the numbers,
e.g. ``"band height 24 deg < w = 30 deg"``.

Forward gait (6.3.1), for a band ``[d_lo, d_hi]``:

1. the band intersects both the inner and the outer finger pair boxes (their offset
   ranges);
2. the band height is at least ``w``;
3. the (start) grasp is at least ``w`` from the band's forward edge. A grasp in an inner
   box moves forward (vertical step CCW, horizontal step CW) towards *larger* offsets,
   one in an outer box towards smaller offsets; reading the grasp in its inner box, with
   offset ``d_in`` (the outer reading is the mirror, ``n - d_in``), the condition is
   ``d_lo <= d_in <= d_hi - w`` for the band (or its mirror) that holds ``d_in``.

Back-and-forth gait (6.3.2), for a box: at least ``2w`` wide and ``2w`` tall, and
passing through both workspace box pairs — its offset range ``[y_lo - x_hi, y_hi -
x_lo]`` overlaps an inner and an outer box's offsets by at least ``w`` each (the finger
pair boxes slide along the diagonal as the object turns, so the box meets them one after
another; see :func:`box_placement_condition`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from graspgait_env.gait import GaitModel, workspace_grid
from graspgait_env.workspace import Hand

__all__ = [
    "Check",
    "WorkspaceGrid",
    "BandPrototype",
    "BoxPrototype",
    "band_offsets",
    "band_prototypes",
    "largest_band",
    "box_prototypes",
    "largest_box",
    "band_condition_1",
    "band_condition_2",
    "band_condition_3",
    "inner_offset",
    "forward_conditions",
    "box_size_condition",
    "box_placement_condition",
    "back_and_forth_conditions",
]


class Check(NamedTuple):
    """Outcome of one necessary condition: ``ok`` and a reason naming the numbers."""

    ok: bool
    reason: str

    def __bool__(self) -> bool:
        return self.ok


# --------------------------------------------------------------------------- workspaces
@dataclass(frozen=True)
class WorkspaceGrid:
    """Finger workspaces on the grid (frame ``F``) and the finger pair boxes' offsets.

    Build it with :meth:`from_model` or :meth:`from_hand`; fingers are 0-based.
    """

    n: int
    ws_start: tuple[int, ...]
    ws_width: tuple[int, ...]

    @classmethod
    def from_model(cls, model: GaitModel) -> WorkspaceGrid:
        """The grid of a :class:`~graspgait_env.gait.GaitModel`."""
        return cls(model.n, tuple(int(s) for s in model.ws_start),
                   tuple(int(w) for w in model.ws_width))

    @classmethod
    def from_hand(cls, hand: Hand | None = None, n: int = 180) -> WorkspaceGrid:
        """The grid of a hand (default the thesis hand) at ``n`` grid angles, rounded by
        :func:`graspgait_env.gait.workspace_grid` as :class:`~graspgait_env.gait.GaitModel`
        rounds it (thesis 4.1, 5.2)."""
        hand = hand or Hand.default()
        starts, widths = workspace_grid(hand.workspaces_deg, n)
        return cls(n, tuple(int(a) for a in starts), tuple(int(w) for w in widths))

    @property
    def step_deg(self) -> float:
        """Grid spacing (degrees)."""
        return 360.0 / self.n

    @property
    def n_fingers(self) -> int:
        """Number of fingers."""
        return len(self.ws_start)

    def succ(self, f: int) -> int:
        """The next finger counter-clockwise round the palm."""
        order = sorted(range(self.n_fingers), key=lambda g: self.ws_start[g] % self.n)
        return order[(order.index(f) + 1) % len(order)]

    def pred(self, f: int) -> int:
        """The previous finger (clockwise neighbour) round the palm."""
        order = sorted(range(self.n_fingers), key=lambda g: self.ws_start[g] % self.n)
        return order[(order.index(f) - 1) % len(order)]

    def gap_after(self, f: int) -> int:
        """Grid steps from finger ``f``'s last grid angle to its successor's first."""
        g = self.succ(f)
        return (self.ws_start[g] - (self.ws_start[f] + self.ws_width[f] - 1)) % self.n

    @property
    def w_steps(self) -> int:
        """The gap ``w`` between workspaces in grid steps (the smallest gap)."""
        return min(self.gap_after(f) for f in range(self.n_fingers))

    @property
    def w_deg(self) -> float:
        """``w`` in degrees, as realised on the grid."""
        return self.w_steps * self.step_deg

    def box_offsets(self, fx: int, fy: int) -> tuple[int, int]:
        """Offset range ``(lo, hi)`` (grid steps, ``0 < lo``) of the grasps ``y - x`` in box
        ``(fx, fy)``."""
        D = (self.ws_start[fy] - self.ws_start[fx]) % self.n
        return D - (self.ws_width[fx] - 1), D + (self.ws_width[fy] - 1)

    def box_kind(self, fx: int, fy: int) -> str:
        """``"inner"`` or ``"outer"`` (box centre offset below / above half a turn)."""
        cx = self.ws_start[fx] + (self.ws_width[fx] - 1) / 2
        cy = self.ws_start[fy] + (self.ws_width[fy] - 1) / 2
        return "inner" if (cy - cx) % self.n < self.n / 2 else "outer"

    def boxes(self, kind: str) -> list[tuple[int, int]]:
        """Ordered finger pairs ``(fx, fy)`` whose box is of ``kind``."""
        m = self.n_fingers
        return [(a, b) for a in range(m) for b in range(m)
                if a != b and self.box_kind(a, b) == kind]

    def deg(self, steps: float) -> float:
        """Grid steps to degrees."""
        return steps * self.step_deg


def _grid(geom: WorkspaceGrid | GaitModel | None, n: int) -> WorkspaceGrid:
    if geom is None:
        return WorkspaceGrid.from_hand(None, n)
    if isinstance(geom, WorkspaceGrid):
        return geom
    return WorkspaceGrid.from_model(geom)


def _meets(lo, hi, a, b, n: int):
    """Does ``[lo, hi]`` meet ``[a, b]`` modulo ``n`` (closed integer intervals)?

    Vectorized over ``lo, hi``: with ``m`` the largest shift such that ``lo + m n <= b``,
    they meet iff ``hi + m n >= a`` (or ``[lo, hi]`` covers a whole period).
    """
    lo, hi = np.asarray(lo), np.asarray(hi)
    out = ((hi - lo + 1) >= n) | (hi + ((b - lo) // n) * n >= a)
    return bool(out) if out.ndim == 0 else out


def _intersect(lo: int, hi: int, a: int, b: int, n: int) -> tuple[int, int]:
    """Part of ``[a, b]`` covered by ``[lo, hi]`` modulo ``n`` (first piece; lo > hi: none)."""
    m = (b - lo) // n
    return max(lo + m * n, a), min(hi + m * n, b)


def _overlap(lo, hi, a: int, b: int, n: int):
    """Length (grid steps; < 0: apart) of the overlap of ``[lo, hi]`` with ``[a, b]`` modulo
    ``n``, vectorized over ``lo, hi``."""
    lo, hi = np.asarray(lo), np.asarray(hi)
    m = (b - lo) // n
    ov = np.maximum(np.minimum(hi + m * n, b) - np.maximum(lo + m * n, a),
                    np.minimum(hi + (m - 1) * n, b) - np.maximum(lo + (m - 1) * n, a))
    ov = np.where(hi - lo + 1 >= n, b - a, ov)
    return int(ov) if ov.ndim == 0 else ov


# --------------------------------------------------------------------------- band
@dataclass(frozen=True)
class BandPrototype:
    """A band of diagonal offsets ``d_lo .. d_hi`` (grid steps, inclusive) that is stable
    along the whole diagonal: ``stable[i, (i + d) % n]`` for every ``i`` and every ``d``
    in the run. ``d_hi`` may exceed ``n`` for a run through offset 0."""

    d_lo: int
    d_hi: int
    n: int

    @property
    def height_steps(self) -> int:
        """Vertical extent (= extent in offset terms), grid steps."""
        return self.d_hi - self.d_lo

    @property
    def height_deg(self) -> float:
        """Vertical extent in degrees — the thesis's band height, compared with ``w``."""
        return self.height_steps * 360.0 / self.n

    @property
    def width_perp_deg(self) -> float:
        """Width perpendicular to the diagonal (degrees): ``height_deg / sqrt(2)``."""
        return self.height_deg / math.sqrt(2.0)

    @property
    def offsets_deg(self) -> tuple[float, float]:
        """The band's edges as offsets ``y - x`` in degrees."""
        s = 360.0 / self.n
        return self.d_lo * s, self.d_hi * s

    def contains(self, d: int) -> bool:
        """Is offset ``d`` (grid steps, any integer) in the band?"""
        return (d - self.d_lo) % self.n <= self.height_steps

    def mirror(self) -> BandPrototype:
        """The mirror band below the diagonal (offsets ``n - d``)."""
        lo = (self.n - self.d_hi) % self.n
        return BandPrototype(lo, lo + self.height_steps, self.n)

    def describe(self) -> str:
        """``band offsets [112, 248] deg, height 136 deg``."""
        a, b = self.offsets_deg
        return f"band offsets [{a:g}, {b:g}] deg, height {self.height_deg:g} deg"


def band_offsets(stable: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """``(n,)`` bool: offsets ``d`` with ``stable[i, (i + d) % n]`` for all ``i``.

    Vectorized: the map is sheared so that column ``d`` holds the diagonal at offset
    ``d``, then reduced with ``all`` over rows.
    """
    S = np.asarray(stable, dtype=bool)
    n = S.shape[0]
    i = np.arange(n)
    return S[i[:, None], (i[:, None] + i[None, :]) % n].all(axis=0)


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Maximal runs ``(lo, hi)`` (inclusive, ``hi`` may pass ``n``) of a circular mask."""
    n = len(mask)
    if mask.all():
        return [(0, n - 1)]
    if not mask.any():
        return []
    r = int(np.flatnonzero(~mask)[0])  # start scanning just after a False
    rolled = np.roll(mask, -r)
    padded = np.concatenate(([False], rolled, [False])).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    out = []
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        lo = (a + r) % n
        out.append((lo, lo + (b - a) - 1))
    return sorted(out)


def band_prototypes(stable: NDArray[np.bool_]) -> list[BandPrototype]:
    """Every maximal band (run of full-diagonal offsets), mirrors included, by offset."""
    S = np.asarray(stable, dtype=bool)
    n = S.shape[0]
    return [BandPrototype(lo, hi, n) for lo, hi in _runs(band_offsets(S))]


def largest_band(stable: NDArray[np.bool_]) -> BandPrototype | None:
    """The tallest band (ties: the lowest offset, i.e. the one above the diagonal first);
    ``None`` when no offset is stable along the whole diagonal."""
    bands = band_prototypes(stable)
    if not bands:
        return None
    return max(bands, key=lambda b: (b.height_steps, -b.d_lo))


# --------------------------------------------------------------------------- box
@dataclass(frozen=True)
class BoxPrototype:
    """An axis-aligned box of stable cells: ``x_lo..x_hi`` × ``y_lo..y_hi`` (grid indices,
    inclusive; ``0 <= x_lo, y_lo < n``; the ``hi`` ends may pass ``n``: the box wraps)."""

    x_lo: int
    x_hi: int
    y_lo: int
    y_hi: int
    n: int

    @property
    def width_steps(self) -> int:
        """Horizontal extent (grid steps)."""
        return self.x_hi - self.x_lo

    @property
    def height_steps(self) -> int:
        """Vertical extent (grid steps)."""
        return self.y_hi - self.y_lo

    @property
    def width_deg(self) -> float:
        """Horizontal extent ``w_x`` (degrees)."""
        return self.width_steps * 360.0 / self.n

    @property
    def height_deg(self) -> float:
        """Vertical extent ``w_y`` (degrees)."""
        return self.height_steps * 360.0 / self.n

    @property
    def cells(self) -> int:
        """Number of grid cells."""
        return (self.width_steps + 1) * (self.height_steps + 1)

    @property
    def offset_range(self) -> tuple[int, int]:
        """Diagonal offsets ``y - x`` (grid steps) that the box spans."""
        return self.y_lo - self.x_hi, self.y_hi - self.x_lo

    def contains(self, x: int, y: int) -> bool:
        """Is grid cell ``(x, y)`` (any integers, taken modulo ``n``) in the box?"""
        return ((x - self.x_lo) % self.n <= self.width_steps
                and (y - self.y_lo) % self.n <= self.height_steps)

    def transpose(self) -> BoxPrototype:
        """The mirror box (the map is symmetric)."""
        return BoxPrototype(self.y_lo, self.y_hi, self.x_lo, self.x_hi, self.n)

    def describe(self) -> str:
        """``box 112 x 112 deg at x [214, 326], y [34, 146] deg``."""
        s = 360.0 / self.n
        return (f"box {self.width_deg:g} x {self.height_deg:g} deg at x [{self.x_lo * s:g}, "
                f"{self.x_hi * s:g}], y [{self.y_lo * s:g}, {self.y_hi * s:g}] deg")


def _run_up(T: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Length of the run of True ending at each cell, going down axis 0."""
    idx = np.arange(T.shape[0])[:, None]
    last_false = np.maximum.accumulate(np.where(T, -1, idx), axis=0)
    return idx - last_false


def _left_extent(H: NDArray[np.int16]) -> NDArray[np.int32]:
    """Per cell: how many cells directly left of it (axis 1) have ``H >= H[cell]``.

    Binary lifting over a sparse table of running minima: ``log2(columns)`` vectorized
    gathers instead of a per-row stack (the histogram method, all rows at once).
    """
    R, C = H.shape
    levels = [H]  # levels[j][:, c] = min H[:, c - 2^j + 1 .. c]; -1 where off the edge
    t = 1
    while 2 * t <= C:
        prev = levels[-1]
        nxt = np.full_like(prev, -1)
        np.minimum(prev[:, t:], prev[:, :-t], out=nxt[:, t:])
        levels.append(nxt)
        t *= 2
    ext = np.zeros(H.shape, dtype=np.int32)
    cols = np.arange(C, dtype=np.int32)[None, :]
    rowoff = (np.arange(R, dtype=np.int32) * C)[:, None]
    for j in range(len(levels) - 1, -1, -1):
        pos = cols - ext - 1
        inside = pos >= 0
        np.maximum(pos, 0, out=pos)
        good = levels[j].ravel().take(pos + rowoff) >= H
        good &= inside
        ext += good.astype(np.int32) << j
    return ext


@lru_cache(maxsize=32)
def _maximal_boxes_cached(key: bytes, n: int) -> tuple[NDArray[np.int64], ...]:
    S = np.frombuffer(key, dtype=bool).reshape(n, n)
    T = np.tile(S, (2, 2))
    # bottom (largest-x) rows in the second tile: every box of <= n rows ends there
    H = np.minimum(_run_up(T), n)[n:].astype(np.int16)
    left = _left_extent(H)
    right = _left_extent(H[:, ::-1])[:, ::-1]
    width = np.minimum(left + right + 1, n)
    r = np.arange(n)[:, None] + n  # row index in T
    c = np.arange(2 * n)[None, :]
    keep = H > 0
    x_hi = np.broadcast_to(r, H.shape)[keep].astype(np.int64)
    h = H[keep].astype(np.int64)
    y_lo = np.broadcast_to(c, H.shape)[keep] - left[keep].astype(np.int64)
    wd = width[keep].astype(np.int64)
    x_lo = x_hi - h + 1
    # normalise the low corners into [0, n)
    sx = (x_lo % n) - x_lo
    sy = (y_lo % n) - y_lo
    out = (x_lo + sx, x_hi + sx, y_lo + sy, y_lo + sy + wd - 1)
    for a in out:
        a.flags.writeable = False
    return out


def _maximal_boxes(stable: NDArray[np.bool_]) -> tuple[NDArray[np.int64], ...]:
    """Candidate maximal boxes ``(x_lo, x_hi, y_lo, y_hi)`` arrays (one per cell of the
    second tile: the histogram method's rectangle of that cell's height), periodic."""
    S = np.ascontiguousarray(np.asarray(stable, dtype=bool))
    return _maximal_boxes_cached(S.tobytes(), S.shape[0])


def _pick(boxes: tuple[NDArray[np.int64], ...], sel: NDArray[np.bool_], n: int,
          squarest: bool) -> BoxPrototype | None:
    x_lo, x_hi, y_lo, y_hi = boxes
    if not sel.any():
        return None
    ex, ey = (x_hi - x_lo)[sel], (y_hi - y_lo)[sel]
    area = (ex + 1) * (ey + 1)
    side = np.minimum(ex, ey)
    # lexsort: last key is primary
    order = np.lexsort((-area, -side) if squarest else (-side, -area))
    i = np.flatnonzero(sel)[order[0]]
    return BoxPrototype(int(x_lo[i]), int(x_hi[i]), int(y_lo[i]), int(y_hi[i]), n)


def box_prototypes(stable: NDArray[np.bool_], min_steps: int = 0,
                   geom: WorkspaceGrid | GaitModel | None = None,
                   placed: bool = False) -> list[BoxPrototype]:
    """Distinct maximal boxes with both sides >= ``min_steps`` grid steps, squarest first.

    With ``placed`` only boxes that meet an inner and an outer finger pair box of
    ``geom`` (default: the thesis hand) are kept (6.3.2, fig. 6.11 (b)).
    """
    S = np.asarray(stable, dtype=bool)
    n = S.shape[0]
    x_lo, x_hi, y_lo, y_hi = _maximal_boxes(S)
    sel = ((x_hi - x_lo) >= min_steps) & ((y_hi - y_lo) >= min_steps)
    if not sel.any():
        return []
    uniq = np.unique(np.stack([x_lo[sel], x_hi[sel], y_lo[sel], y_hi[sel]], axis=1), axis=0)
    boxes = [BoxPrototype(*map(int, row), n) for row in uniq]
    if placed:
        g = _grid(geom, n)
        boxes = [b for b in boxes if box_placement_condition(b, g).ok]
    return sorted(boxes, key=lambda b: (-min(b.width_steps, b.height_steps), -b.cells,
                                        b.x_lo, b.y_lo))


def largest_box(stable: NDArray[np.bool_], squarest: bool = False) -> BoxPrototype | None:
    """The largest stable axis-aligned box (periodic: it may wrap).

    ``squarest=False``: the largest area (ties: the larger smaller side); ``True``: the
    largest smaller side (ties: the larger area) — the one the 2w × 2w condition asks
    about. ``None`` for a map with no stable cell. Maximal-rectangle by the histogram
    method on the 2 × 2 tiled map, vectorized over all rows.
    """
    S = np.asarray(stable, dtype=bool)
    boxes = _maximal_boxes(S)
    return _pick(boxes, np.ones(len(boxes[0]), dtype=bool), S.shape[0], squarest)


# --------------------------------------------------------------------------- conditions
def band_condition_1(band: BandPrototype, geom: WorkspaceGrid) -> Check:
    """6.3.1 condition 1: the band meets both the inner and the outer finger pair boxes."""
    n = geom.n
    bad = []
    for kind in ("inner", "outer"):
        for fx, fy in geom.boxes(kind):
            a, b = geom.box_offsets(fx, fy)
            if not _meets(band.d_lo, band.d_hi, a, b, n):
                bad.append(f"{kind} box ({fx + 1}, {fy + 1}) offsets [{geom.deg(a):g}, "
                           f"{geom.deg(b):g}] deg")
    if bad:
        return Check(False, f"{band.describe()} misses the " + "; ".join(bad))
    ia, ib = geom.box_offsets(*geom.boxes("inner")[0])
    oa, ob = geom.box_offsets(*geom.boxes("outer")[0])
    return Check(True, f"{band.describe()} meets the inner boxes' offsets [{geom.deg(ia):g}, "
                       f"{geom.deg(ib):g}] deg and the outer boxes' [{geom.deg(oa):g}, "
                       f"{geom.deg(ob):g}] deg")


def band_condition_2(band: BandPrototype, w_steps: int, n: int | None = None) -> Check:
    """6.3.1 condition 2: band height >= ``w`` (grid steps)."""
    s = 360.0 / (n or band.n)
    if band.height_steps >= w_steps:
        return Check(True, f"band height {band.height_deg:g} deg >= w = {w_steps * s:g} deg")
    return Check(False, f"band height {band.height_deg:g} deg < w = {w_steps * s:g} deg")


def inner_offset(contacts: dict[int, int] | tuple[int, ...], geom: WorkspaceGrid
                 ) -> tuple[int, int, int]:
    """Read a grasp in its inner finger pair box: ``(d_in, fx, fy)`` with ``fy`` the
    successor of ``fx`` and ``d_in = (c_fy - c_fx) mod n`` (grid steps).

    ``contacts``: ``{finger (0-based): contact index}`` or a per-finger tuple with -1 for
    the free finger (as :class:`~graspgait_env.gait.GaitState` holds them).
    """
    if not isinstance(contacts, dict):
        contacts = {f: c for f, c in enumerate(contacts) if c >= 0}
    f, g = sorted(contacts)
    fx, fy = (f, g) if geom.succ(f) == g else (g, f)
    return (contacts[fy] - contacts[fx]) % geom.n, fx, fy


def band_condition_3(band: BandPrototype, d_in: int, w_steps: int) -> Check:
    """6.3.1 condition 3: the grasp (inner-box offset ``d_in``) lies in ``band`` at least
    ``w`` from its forward edge (``band.d_hi``, towards which inner-box grasps step)."""
    s = 360.0 / band.n
    if not band.contains(d_in):
        return Check(False, f"grasp offset {d_in * s:g} deg is outside the {band.describe()}")
    u = band.d_lo + (d_in - band.d_lo) % band.n
    room = band.d_hi - u
    if room >= w_steps:
        return Check(True, f"grasp offset {d_in * s:g} deg is {room * s:g} deg >= w = "
                           f"{w_steps * s:g} deg from the band's forward edge "
                           f"{band.d_hi * s:g} deg")
    return Check(False, f"grasp offset {d_in * s:g} deg is only {room * s:g} deg from the band's "
                        f"forward edge {band.d_hi * s:g} deg (< w = {w_steps * s:g} deg)")


def forward_conditions(stable: NDArray[np.bool_], geom: WorkspaceGrid | GaitModel | None = None,
                       start: dict[int, int] | tuple[int, ...] | None = None
                       ) -> tuple[BandPrototype | None, list[Check]]:
    """The band for the forward gait and conditions 1–3 of thesis 6.3.1.

    Parameters
    ----------
    stable
        ``(n, n)`` grasp map.
    geom
        :class:`WorkspaceGrid` or a :class:`~graspgait_env.gait.GaitModel`; default the
        thesis hand on the map's grid.
    start
        The start grasp (contacts of the two holding fingers, 0-based finger → grid
        index, or a state's contact tuple). With it, the band is the one holding the
        grasp and condition 3 is checked; without it, the tallest band meeting
        conditions 1–2 (else the tallest band) and condition 3 is reported for the best
        grasp that band admits.

    Returns
    -------
    band, checks
        ``checks`` lists conditions 1, 2, 3 in order (all ``ok`` ⇒ the rules of 6.3.1
        generate a gait). ``band`` is ``None`` with a single failed check when the map
        has no band at all (or none holding the start grasp).
    """
    S = np.asarray(stable, dtype=bool)
    g = _grid(geom, S.shape[0])
    w = g.w_steps
    bands = band_prototypes(S)
    if not bands:
        return None, [Check(False, "no band: no diagonal offset is stable along the whole "
                                   "diagonal (the grasp map is not continuous, fig. 6.3 (a))")]
    if start is not None:
        d_in, fx, fy = inner_offset(start, g)
        held = [b for b in bands if b.contains(d_in)]
        if not held:
            tall = max(bands, key=lambda b: b.height_steps)
            return None, [Check(False, f"the start grasp (inner-box offset {g.deg(d_in):g} deg, "
                                       f"fingers {fx + 1}, {fy + 1}) lies in no band; the "
                                       f"tallest is the {tall.describe()}")]
        band = held[0]
        return band, [band_condition_1(band, g), band_condition_2(band, w),
                      band_condition_3(band, d_in, w)]
    good = [b for b in bands if band_condition_1(b, g).ok and band_condition_2(b, w).ok]
    band = max(good or bands, key=lambda b: (b.height_steps, -b.d_lo))
    c1, c2 = band_condition_1(band, g), band_condition_2(band, w)
    lo, hi = _start_offsets(band, g)
    if lo <= hi:
        c3 = Check(True, f"grasps with inner-box offsets [{g.deg(lo):g}, {g.deg(hi):g}] deg are "
                         f">= w = {g.w_deg:g} deg from the band's forward edge "
                         f"{g.deg(band.d_hi):g} deg")
    else:
        c3 = Check(False, f"no grasp of the {band.describe()} is >= w = {g.w_deg:g} deg from its "
                          "forward edge inside an inner box")
    return band, [c1, c2, c3]


def _start_offsets(band: BandPrototype, g: WorkspaceGrid) -> tuple[int, int]:
    """Inner-box offsets admitted by condition 3 that an inner box holds (lo > hi: none)."""
    a, b = g.box_offsets(*g.boxes("inner")[0])
    return _intersect(band.d_lo, band.d_hi - g.w_steps, a, b, g.n)


def box_size_condition(box: BoxPrototype, w_steps: int) -> Check:
    """6.3.2: the box is at least ``2w`` wide and ``2w`` tall."""
    s = 360.0 / box.n
    need = 2 * w_steps
    if box.width_steps >= need and box.height_steps >= need:
        return Check(True, f"box {box.width_deg:g} x {box.height_deg:g} deg >= 2w x 2w = "
                           f"{need * s:g} x {need * s:g} deg")
    return Check(False, f"box {box.width_deg:g} x {box.height_deg:g} deg is smaller than 2w x 2w "
                        f"= {need * s:g} x {need * s:g} deg")


def box_placement_condition(box: BoxPrototype, geom: WorkspaceGrid) -> Check:
    """6.3.2 (fig. 6.11 (b)): the box passes through both workspace box pairs.

    The finger pair boxes slide along the diagonal as the object turns, so the box meets
    a pair box when their diagonal-offset ranges overlap. "Passes through" is read as an
    overlap of at least ``w`` with an inner and with an outer box: a regrasp between the
    two is a step of at least ``w`` that must fit inside the box (condition 1 of 6.3.2).
    Mere touching is not enough — on synthetic box maps the exact planner finds a gait
    exactly when both overlaps reach ``w`` (``tests/planners/test_prototypes.py``).
    """
    lo, hi = box.offset_range
    n, w = geom.n, geom.w_steps
    rng = f"offsets [{geom.deg(lo):g}, {geom.deg(hi):g}] deg"
    short = []
    for kind in ("inner", "outer"):
        ov = max(_overlap(lo, hi, *geom.box_offsets(fx, fy), n) for fx, fy in geom.boxes(kind))
        if ov < w:
            short.append(f"the {kind} boxes by {geom.deg(max(ov, 0)):g} deg" if ov >= 0
                         else f"no {kind} box")
    if short:
        return Check(False, f"{box.describe()} ({rng}) overlaps {' and '.join(short)} "
                            f"(< w = {geom.w_deg:g} deg): it does not pass through both "
                            "workspace box pairs")
    return Check(True, f"{box.describe()} ({rng}) passes through inner and outer finger pair "
                       f"boxes (overlaps >= w = {geom.w_deg:g} deg)")


def back_and_forth_conditions(stable: NDArray[np.bool_],
                              geom: WorkspaceGrid | GaitModel | None = None,
                              start: dict[int, int] | tuple[int, ...] | None = None
                              ) -> tuple[BoxPrototype | None, list[Check]]:
    """The box for the back-and-forth gait and its conditions (thesis 6.3.2).

    The box is the squarest maximal box that is ``>= 2w × 2w`` and placed through an
    inner and an outer finger pair box (holding the start grasp in either reading when
    ``start`` is given); failing that, the squarest box (holding the start), whose failed
    conditions are then reported. Returns ``(box, [size check, placement check])``, or
    ``(None, [one failed check])`` when no box holds the start or the map has no stable
    cell at all.
    """
    S = np.asarray(stable, dtype=bool)
    n = S.shape[0]
    g = _grid(geom, n)
    w = g.w_steps
    boxes = _maximal_boxes(S)
    x_lo, x_hi, y_lo, y_hi = boxes
    sel = np.ones(len(x_lo), dtype=bool)
    if start is not None:
        cs = start if isinstance(start, dict) else {f: c for f, c in enumerate(start) if c >= 0}
        a, b = (cs[f] for f in sorted(cs))
        inx = lambda v, lo, hi: (v - lo) % n <= hi - lo  # noqa: E731
        sel = (inx(a, x_lo, x_hi) & inx(b, y_lo, y_hi)) | (inx(b, x_lo, x_hi) & inx(a, y_lo, y_hi))
        if not sel.any():
            return None, [Check(False, "the start grasp is not stable")]
    big = sel & ((x_hi - x_lo) >= 2 * w) & ((y_hi - y_lo) >= 2 * w)
    if big.any():
        lo, hi = y_lo - x_hi, y_hi - x_lo
        placed = big.copy()
        for kind in ("inner", "outer"):
            hit = np.zeros_like(big)
            for fx, fy in g.boxes(kind):
                hit |= _overlap(lo, hi, *g.box_offsets(fx, fy), n) >= w
            placed &= hit
        if placed.any():
            box = _pick(boxes, placed, n, squarest=True)
            if box is not None:  # always: ``placed`` selects at least one box
                return box, [box_size_condition(box, w), box_placement_condition(box, g)]
    box = _pick(boxes, sel, n, squarest=True)
    if box is None:  # no stable cell at all (e.g. a regular pentagon at mu = 0.3)
        return None, [Check(False, "no box: the grasp map has no stable grasp (thesis 6.2, "
                                   "fig. 6.3 (b))")]
    return box, [box_size_condition(box, w), box_placement_condition(box, g)]
