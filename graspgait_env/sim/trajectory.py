"""The trajectory planner (thesis 7.4.2): finger paths, grip schedules, contact normals.

Each gait step becomes a short list of :class:`Trajectory` objects, all three fingers
on one clock (the sequences themselves: :mod:`~graspgait_env.sim.moves`):

- **rotation** (:func:`rotation`): the fingers on the object travel arcs about the
  (estimated) object centre at their present radius, through the commanded angle; a
  free finger stays where it is;
- **transition** (a regrasp): the new finger travels an arc at ``max_r``
  (:func:`free_arc`), then a line inward toward the object centre until contact
  (:func:`approach`: fast to ``standoff`` outside the expected surface, then slowly
  with contact detection armed); the three fingers servo to the same
  points while the grip transfers linearly from the old pair to the new
  (:func:`transfer`); the old finger retreats along a line outward to ``max_r``
  (:func:`retreat`).

Via points are ``res`` apart along the longest finger path (the thesis's ``len_tra``
pieces). The thesis's PD moved at a constant speed between via points; here the speed
follows a trapezoidal profile with acceleration ``max_accel`` (constant acceleration
between via points), so that free-motion servo forces stay under the contact threshold.

Grip magnitudes are given per finger pair, in the order of :data:`PAIRS`; the thesis's
per-finger columns of internal force magnitudes (7.4.2) are the same numbers.
Trajectory types per finger are the thesis's: ``FREE`` (0, no force, not touching),
``TRANSITION`` (1, applying transition forces), ``CONTACT`` (2, making contact) and
``HOLD`` (3, applying grip forces that are not transition forces).

Everything here is pure NumPy; frames: F (the palm, = MuJoCo world), metres, degrees
in the public arguments.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspgait_env.sim.frames import rotation_matrices

__all__ = [
    "Trajectory",
    "PAIRS",
    "pair_index",
    "FREE",
    "TRANSITION",
    "CONTACT",
    "HOLD",
    "time_law",
    "rotation",
    "free_arc",
    "approach",
    "transfer",
    "retreat",
    "hold",
    "translate",
    "workspace_sweep_deg",
]

FREE, TRANSITION, CONTACT, HOLD = 0, 1, 2, 3
PAIRS: tuple[tuple[int, int], ...] = ((0, 1), (0, 2), (1, 2))  # finger pairs, 0-based


def pair_index(i: int, j: int) -> int:
    """Index in :data:`PAIRS` of the pair of 0-based fingers ``i`` and ``j``."""
    return PAIRS.index((min(i, j), max(i, j)))


@dataclass
class Trajectory:
    """One trajectory: via points of all three fingers on a common clock.

    Attributes
    ----------
    name
        ``rotate``, ``arc``, ``approach``, ``transfer``, ``retreat``, ``hold``, ...
    t
        ``(n,)`` via-point times (s), ``t[0] = 0``.
    v
        ``(n,)`` path speed at the via points (m/s along the longest path), for the
        constant-acceleration interpolation between them.
    s
        ``(n,)`` arc length of the longest path at the via points (m).
    x
        ``(n, 3, 3)`` desired tip positions (m, frame F).
    grip
        ``(n, 3)`` internal force magnitude of each pair of :data:`PAIRS` (N).
    kind
        ``(3,)`` trajectory type per finger (FREE, TRANSITION, CONTACT, HOLD).
    normals
        ``(n, 3, 2)`` inward unit normals (frame F) of the fingers on the object,
        zero for the others.
    """

    name: str
    t: NDArray[np.float64]
    v: NDArray[np.float64]
    s: NDArray[np.float64]
    x: NDArray[np.float64]
    grip: NDArray[np.float64]
    kind: NDArray[np.int64]
    normals: NDArray[np.float64]
    info: dict = field(default_factory=dict)

    @property
    def duration(self) -> float:
        """Duration (s)."""
        return float(self.t[-1])

    @property
    def end(self) -> NDArray[np.float64]:
        """``(3, 3)`` desired positions at the end."""
        return self.x[-1].copy()

    def sample(self, dt: float) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                          NDArray[np.float64], NDArray[np.float64]]:
        """Desired positions, velocities, grips and normals at servo ticks ``k dt``.

        Between via points the path speed changes at constant acceleration (the
        trapezoidal profile), the position moving along the straight line between
        them. Returns arrays of shapes ``(m, 3, 3)``, ``(m, 3, 3)``, ``(m, 3)`` and
        ``(m, 3, 2)`` with ``m = floor(duration / dt) + 1`` (at least 2: the last tick
        holds the end point, at rest).
        """
        T = self.duration
        m = max(2, int(math.floor(T / dt + 1e-9)) + 1)
        tau = np.minimum(np.arange(m) * dt, T)
        tau[-1] = T
        n = len(self.t)
        if n < 2 or T <= 0.0:
            x = np.broadcast_to(self.x[-1], (m, 3, 3)).copy()
            return (x, np.zeros_like(x), np.broadcast_to(self.grip[-1], (m, 3)).copy(),
                    np.broadcast_to(self.normals[-1], (m, 3, 2)).copy())
        k = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, n - 2)
        h = tau - self.t[k]
        dtk = self.t[k + 1] - self.t[k]
        ds = self.s[k + 1] - self.s[k]
        v0, v1 = self.v[k], self.v[k + 1]
        acc = np.where(dtk > 0, (v1 - v0) / np.where(dtk > 0, dtk, 1.0), 0.0)
        sh = v0 * h + 0.5 * acc * h * h  # path distance since via point k
        vh = v0 + acc * h
        with np.errstate(invalid="ignore", divide="ignore"):
            frac = np.where(ds > 0, sh / np.where(ds > 0, ds, 1.0), h / np.where(dtk > 0, dtk, 1.0))
            rate = np.where(ds > 0, vh / np.where(ds > 0, ds, 1.0), 0.0)
        frac = np.clip(frac, 0.0, 1.0)
        dx = self.x[k + 1] - self.x[k]
        xd = self.x[k] + frac[:, None, None] * dx
        vd = rate[:, None, None] * dx
        gf = np.clip(h / np.where(dtk > 0, dtk, 1.0), 0.0, 1.0)[:, None]
        grip = self.grip[k] + gf * (self.grip[k + 1] - self.grip[k])
        normals = self.normals[k]
        vd[-1] = 0.0
        return xd, vd, grip, normals


def time_law(s: ArrayLike, vmax: ArrayLike, accel: float, decel: float | None = None
             ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Time-optimal speed profile along a path with speed limits and acceleration limits.

    Parameters
    ----------
    s
        ``(n,)`` arc length at the via points (non-decreasing, ``s[0] = 0``).
    vmax
        ``(n,)`` speed limit at each via point (m/s, > 0).
    accel
        Acceleration limit (m/s^2).
    decel
        Deceleration limit (m/s^2); default ``accel``.

    Returns
    -------
    t, v
        Via-point times (s) and speeds (m/s); at rest at both ends.

    Examples
    --------
    A 0.1 m path at up to 1 m/s with 2 m/s^2 never reaches 1 m/s (triangular profile,
    ``t = 2 sqrt(d / a)``):

    >>> t, v = time_law(np.linspace(0, 0.1, 41), np.ones(41), 2.0)
    >>> round(float(t[-1]), 4), round(float(v.max()), 3)
    (0.4472, 0.447)
    """
    s = np.asarray(s, dtype=np.float64)
    v = np.asarray(vmax, dtype=np.float64).copy()
    n = len(s)
    if n == 1:
        return np.zeros(1), np.zeros(1)
    ds = np.diff(s)
    v[0] = 0.0
    v[-1] = 0.0
    for k in range(n - 1):  # forward: reachable from rest
        v[k + 1] = min(v[k + 1], math.sqrt(v[k] ** 2 + 2 * accel * ds[k]))
    dec = accel if decel is None else decel
    for k in range(n - 2, -1, -1):  # backward: can stop at the end
        v[k] = min(v[k], math.sqrt(v[k + 1] ** 2 + 2 * dec * ds[k]))
    vs = v[:-1] + v[1:]
    dt = np.where(vs > 0, 2.0 * ds / np.where(vs > 0, vs, 1.0), 0.0)
    return np.concatenate([[0.0], np.cumsum(dt)]), v


def _build(name: str, paths: NDArray[np.float64], speed: NDArray[np.float64] | float,
           accel: float, grip: ArrayLike, kind: ArrayLike, normals: NDArray[np.float64],
           info: dict | None = None, decel: float | None = None) -> Trajectory:
    """Trajectory from sampled paths ``(n, 3, 3)`` (common parameter), speed limits."""
    seg = np.linalg.norm(np.diff(paths, axis=0), axis=2).max(axis=1) if len(paths) > 1 \
        else np.zeros(0)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    vmax = np.broadcast_to(np.asarray(speed, dtype=np.float64), s.shape)
    t, v = time_law(s, vmax, accel, decel)
    grip = np.asarray(grip, dtype=np.float64)
    if grip.ndim == 1:
        grip = np.broadcast_to(grip, (len(s), 3)).copy()
    if normals.ndim == 2:
        normals = np.broadcast_to(normals, (len(s), 3, 2)).copy()
    return Trajectory(name, t, v, s, paths, grip, np.asarray(kind, dtype=np.int64), normals,
                      info or {})


def _n_points(length: float, res: float) -> int:
    return max(2, int(math.ceil(length / res)) + 1)


def rotation(x0: NDArray[np.float64], center: ArrayLike, delta_deg: float,
             moving: ArrayLike, grip: ArrayLike, normals: NDArray[np.float64], *,
             res: float, speed_deg: float, accel: float, max_speed: float | None = None,
             kind: ArrayLike | None = None,
             rolling: Callable[[NDArray[np.float64]], tuple[NDArray[np.float64],
                                                            NDArray[np.float64]]] | None = None
             ) -> Trajectory:
    """An object rotation: the ``moving`` fingers travel arcs about ``center`` at their
    present radius through ``delta_deg`` (CCW positive); the others stay (7.4.2).

    ``normals`` (3, 2) are rotated along. The angular speed is limited to
    ``speed_deg`` deg/s, and the fastest tip to ``max_speed`` m/s if given;
    ``accel`` limits the tip acceleration.

    ``rolling``: for ball tips that roll on the object (thesis 7.2), a function of the
    object angles ``a_deg`` ``(n,)`` (0 .. ``delta_deg``) returning ``(shift, normals)``,
    each ``(n, k, 2)`` for the ``k`` moving fingers in ascending order, in the frame of
    the object at the start of the rotation: how far each ball centre has moved on the
    object since the start (m), and the inward normals at the rolled contacts. Each
    moving finger then follows ``center + R(a) (rel + shift)`` instead of the rigid arc.
    """
    x0 = np.asarray(x0, dtype=np.float64)
    c = np.asarray(center, dtype=np.float64)[:2]
    mv = np.zeros(3, dtype=bool)
    mv[list(moving)] = True
    rel = x0[:, :2] - c
    rmax = float(np.max(np.linalg.norm(rel[mv], axis=1))) if mv.any() else 0.0
    d = math.radians(delta_deg)
    length = abs(d) * max(rmax, 1e-9)
    n = _n_points(length, res)
    a = np.linspace(0.0, d, n)
    R = rotation_matrices(a)  # (n, 2, 2)
    paths = np.broadcast_to(x0, (n, 3, 3)).copy()
    nr = np.broadcast_to(np.asarray(normals, dtype=np.float64), (3, 2))
    if rolling is None:
        paths[:, mv, :2] = c + np.einsum("nij,fj->nfi", R, rel[mv])
        nrm = np.einsum("nij,fj->nfi", R, nr)
    else:
        shift, n_roll = rolling(np.degrees(a))
        paths[:, mv, :2] = c + np.einsum("nij,nfj->nfi", R, rel[mv][None] + shift)
        nr_n = np.broadcast_to(nr, (n, 3, 2)).copy()
        nr_n[:, mv] = n_roll
        nrm = np.einsum("nij,nfj->nfi", R, nr_n)
    vlim = math.radians(speed_deg) * max(rmax, 1e-9)
    if max_speed is not None:
        vlim = min(vlim, max_speed)
    kind = np.where(mv, HOLD, FREE) if kind is None else kind
    return _build("rotate", paths, vlim, accel, grip, kind, nrm,
                  {"delta_deg": float(delta_deg), "center": c.copy()})


def workspace_sweep_deg(a_from: float, a_to: float,
                        workspace: tuple[float, float] | None = None) -> float:
    """Signed angle (deg) from ``a_from`` to ``a_to`` that stays inside ``workspace``
    (an F arc ``(lo, hi)``) when both ends are inside it, else the shortest way.

    >>> workspace_sweep_deg(80.0, 10.0, (0.0, 90.0)), workspace_sweep_deg(350.0, 10.0)
    (-70.0, 20.0)
    """
    short = (a_to - a_from + 180.0) % 360.0 - 180.0
    if workspace is None:
        return short
    lo, hi = workspace
    u0 = (a_from - lo) % 360.0
    u1 = (a_to - lo) % 360.0
    w = hi - lo
    tol = 1e-6
    if u0 <= w + tol and u1 <= w + tol:
        return u1 - u0
    return short


def free_arc(x0: NDArray[np.float64], fingers: ArrayLike, center: ArrayLike,
             targets_deg: ArrayLike, radius: float, grip: ArrayLike,
             normals: NDArray[np.float64], *, res: float, speed: float, accel: float,
             workspaces: ArrayLike | None = None, kind: ArrayLike | None = None
             ) -> Trajectory:
    """Free ``fingers`` travel arcs about ``center`` to polar angles ``targets_deg``
    (frame F), their radius changing linearly to ``radius`` (``max_r``) on the way, so
    that they keep clear of the object (7.4.1-7.4.2). Each arc stays inside its finger's
    workspace (``workspaces[k] = (lo, hi)``) when given. The other fingers hold."""
    x0 = np.asarray(x0, dtype=np.float64)
    fingers = [int(f) for f in np.atleast_1d(fingers)]
    targets = np.atleast_1d(np.asarray(targets_deg, dtype=np.float64))
    c = np.asarray(center, dtype=np.float64)[:2]
    rel = x0[fingers, :2] - c
    r0 = np.hypot(rel[:, 0], rel[:, 1])
    a0 = np.degrees(np.arctan2(rel[:, 1], rel[:, 0]))
    ws = [None] * len(fingers) if workspaces is None else list(workspaces)
    sweep = np.array([workspace_sweep_deg(a, b, w) for a, b, w in zip(a0, targets, ws,
                                                                       strict=True)])
    length = float(np.max(np.abs(np.radians(sweep)) * np.maximum(r0, radius)
                          + np.abs(radius - r0)))
    n = _n_points(length, res)
    u = np.linspace(0.0, 1.0, n)[:, None]
    ang = np.radians(a0 + u * sweep)
    r = r0 + u * (radius - r0)
    paths = np.broadcast_to(x0, (n, 3, 3)).copy()
    paths[:, fingers, 0] = c[0] + r * np.cos(ang)
    paths[:, fingers, 1] = c[1] + r * np.sin(ang)
    if kind is None:
        kind = np.full(3, HOLD)
        kind[fingers] = FREE
    return _build("arc", paths, speed, accel, grip, kind, np.asarray(normals, float),
                  {"fingers": fingers, "sweep_deg": sweep})


def approach(x0: NDArray[np.float64], fingers: ArrayLike, targets: NDArray[np.float64],
             grip: ArrayLike, normals: NDArray[np.float64], *, res: float, speed: float,
             approach_speed: float, standoff: float, overshoot: float, accel: float,
             approach_accel: float, hold: ArrayLike = ()) -> list[Trajectory]:
    """The ``fingers`` move along straight lines toward their ``targets`` ((k, 3) ball
    centres at contact) and on, ``overshoot`` beyond them, so that the servo force rises
    at contact (7.3).

    Two trajectories along the same lines: ``approach_fast`` (type FREE, ``speed``,
    ``accel``, but braking at ``approach_accel``, so that the finger stops without
    a servo transient that the contact detector would take for contact) to
    ``standoff`` before the targets, then ``approach`` (type CONTACT,
    ``approach_speed``, ``approach_accel``: contact detection armed) to the end; contact
    detection ends the second early (the servo loop). The fast part is skipped for a
    finger already within ``standoff``. The ``hold`` fingers keep their grip (HOLD).
    """
    x0 = np.asarray(x0, dtype=np.float64)
    fingers = list(fingers)
    targets = np.asarray(targets, dtype=np.float64).reshape(len(fingers), 3)
    d = targets - x0[fingers]
    dist = np.linalg.norm(d, axis=1)
    u = d / np.maximum(dist, 1e-12)[:, None]
    mid = targets - np.minimum(standoff, dist)[:, None] * u
    ends = targets + overshoot * u
    out = []
    hold = list(hold)
    nr = np.asarray(normals, float)
    if float(np.max(np.linalg.norm(mid - x0[fingers], axis=1))) > 1e-6:
        n = _n_points(float(np.max(np.linalg.norm(mid - x0[fingers], axis=1))), res)
        w = np.linspace(0.0, 1.0, n)[:, None, None]
        paths = np.broadcast_to(x0, (n, 3, 3)).copy()
        paths[:, fingers, :] = x0[fingers] + w * (mid - x0[fingers])
        kind = np.full(3, FREE)
        kind[hold] = HOLD
        out.append(_build("approach_fast", paths, speed, accel, grip, kind, nr,
                          {"fingers": fingers}, decel=approach_accel))
        x0 = paths[-1]
    L = float(np.max(np.linalg.norm(ends - x0[fingers], axis=1)))
    n = _n_points(L, res)
    w = np.linspace(0.0, 1.0, n)[:, None, None]
    paths = np.broadcast_to(x0, (n, 3, 3)).copy()
    paths[:, fingers, :] = x0[fingers] + w * (ends - x0[fingers])
    kind = np.full(3, FREE)
    kind[hold] = HOLD
    kind[fingers] = CONTACT
    out.append(_build("approach", paths, approach_speed, approach_accel, grip, kind, nr,
                      {"fingers": fingers, "targets": targets}))
    return out


def transfer(x0: NDArray[np.float64], grip_from: ArrayLike, grip_to: ArrayLike,
             normals: NDArray[np.float64], duration: float, *, steps: int = 20,
             kind: ArrayLike | None = None) -> Trajectory:
    """Three fingers servo to fixed points while each pair's grip changes linearly from
    ``grip_from`` to ``grip_to`` (3 pair magnitudes each) over ``duration`` (7.4.2)."""
    x0 = np.asarray(x0, dtype=np.float64)
    n = max(2, steps)
    t = np.linspace(0.0, duration, n)
    g0 = np.asarray(grip_from, float)
    g1 = np.asarray(grip_to, float)
    grip = g0 + np.linspace(0, 1, n)[:, None] * (g1 - g0)
    kind = np.full(3, TRANSITION) if kind is None else kind
    nr = np.broadcast_to(np.asarray(normals, float), (n, 3, 2)).copy()
    return Trajectory("transfer", t, np.zeros(n), np.zeros(n),
                      np.broadcast_to(x0, (n, 3, 3)).copy(), grip,
                      np.asarray(kind, dtype=np.int64), nr)


def hold(x0: NDArray[np.float64], grip: ArrayLike, normals: NDArray[np.float64],
         duration: float, kind: ArrayLike, name: str = "hold") -> Trajectory:
    """All fingers servo to fixed points for ``duration`` with constant grips."""
    tr = transfer(x0, grip, grip, normals, duration, steps=2, kind=kind)
    tr.name = name
    return tr


def retreat(x0: NDArray[np.float64], fingers: int | ArrayLike, center: ArrayLike,
            radius: float, grip: ArrayLike, normals: NDArray[np.float64], *, res: float,
            speed: float, accel: float, kind: ArrayLike | None = None) -> Trajectory:
    """The ``fingers`` leave the object along lines outward from ``center`` through
    their present points until their radius is ``radius`` (``max_r``) (7.4.2)."""
    x0 = np.asarray(x0, dtype=np.float64)
    fingers = [int(f) for f in np.atleast_1d(fingers)]
    c = np.asarray(center, dtype=np.float64)[:2]
    rel = x0[fingers, :2] - c
    r0 = np.hypot(rel[:, 0], rel[:, 1])
    u = rel / np.maximum(r0, 1e-12)[:, None]
    length = np.maximum(radius - r0, 0.0)
    n = _n_points(float(length.max()), res)
    w = np.linspace(0.0, 1.0, n)[:, None, None]
    paths = np.broadcast_to(x0, (n, 3, 3)).copy()
    paths[:, fingers, :2] = x0[fingers, :2] + w * (length[:, None] * u)
    if kind is None:
        kind = np.full(3, HOLD)
        kind[fingers] = FREE
    nr = np.array(normals, dtype=float)
    nr[fingers] = 0.0
    return _build("retreat", paths, speed, accel, grip, kind, nr, {"fingers": fingers})


def translate(x0: NDArray[np.float64], moving: ArrayLike, offset: ArrayLike, grip: ArrayLike,
              normals: NDArray[np.float64], *, res: float, speed: float, accel: float,
              kind: ArrayLike | None = None) -> Trajectory:
    """The ``moving`` fingers (and the object they hold) translate by ``offset`` (x, y):
    the recentering move of thesis 7.5 (errors over 1/4 in)."""
    x0 = np.asarray(x0, dtype=np.float64)
    off = np.asarray(offset, dtype=np.float64)[:2]
    mv = np.zeros(3, dtype=bool)
    mv[list(moving)] = True
    n = _n_points(float(np.hypot(*off)), res)
    paths = np.broadcast_to(x0, (n, 3, 3)).copy()
    paths[:, mv, :2] += np.linspace(0, 1, n)[:, None, None] * off
    kind = np.where(mv, HOLD, FREE) if kind is None else kind
    return _build("recenter", paths, speed, accel, grip, kind, np.asarray(normals, float),
                  {"offset": off})
