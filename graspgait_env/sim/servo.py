"""The inner servo loop of the thesis controller (7.3, 7.4.3, 7.4.4, 7.4.6).

Four units, each tested on its own:

- :class:`PDServo` (7.4.6): ``F_s = kp (x_d - x_m) + kv (v_d - v_m)`` with ``v_m`` a
  low-pass-filtered finite difference of the measured positions (the only sensors are
  the encoders);
- :func:`internal_forces` (7.4.3): each gripping pair squeezes along the line between
  the measured fingertips, equal and opposite, so no net force on the object;
- :class:`GripCheck` (7.4.4): raises a pair's grip by ``grip_force / settle`` in a
  cycle where a finger's total commanded force has less than the nominal grip along its
  grip direction, or lies outside the (estimated) friction cone; no increase where the
  finger's total force exceeds the saturation (1 lb), or (friction check) where the grip
  direction itself lies outside the estimated cone;
- :class:`ContactDetector` (7.3): contact once the commanded servo force exceeds a
  threshold (1 oz) for ``cycles`` consecutive servo cycles (3).

Data layout: these run once per servo cycle, thousands of times per simulated second,
on three fingers. NumPy's per-call overhead (~1 µs) on 3x3 arrays would cost more than
the arithmetic, so the units take and return flat Python lists of floats: positions and
forces as 9 numbers ``[x1, y1, z1, x2, ..., z3]`` (fingers 1..3, frame F), pair values
as 3 numbers in the order of :data:`~graspgait_env.sim.trajectory.PAIRS` ((1,2), (1,3),
(2,3)), normals as 6 numbers ``[nx1, ny1, ..., ny3]``. Any sequence works as input
(``ndarray.ravel().tolist()`` is cheap).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from graspgait_env.sim.trajectory import HOLD, PAIRS

__all__ = ["PDServo", "internal_forces", "GripCheck", "ContactDetector"]


class PDServo:
    """PD servo with a low-pass-filtered velocity estimate (thesis 7.4.6).

    Parameters
    ----------
    kp, kv
        Gains per axis (x, y, z): N/m and N s/m.
    alpha
        Low-pass coefficient per cycle, ``v <- v + alpha (dx/dt - v)`` (thesis: 1/10
        at 3500 Hz).
    dt
        Servo period (s).

    Examples
    --------
    >>> s = PDServo([100, 100, 100], [1, 1, 1], alpha=1.0, dt=0.01)
    >>> s.reset([0.0] * 9)
    >>> f = s.cycle([0.001] + [0.0] * 8, [0.002] + [0.0] * 8, [0.0] * 9)
    >>> round(f[0], 6), round(s.v[0], 6)   # 100 * 0.001 + 1 * (0 - 0.1)
    (0.0, 0.1)
    """

    def __init__(self, kp: Sequence[float], kv: Sequence[float], alpha: float,
                 dt: float) -> None:
        if len(kp) != 3 or len(kv) != 3:
            raise ValueError("kp, kv: give one gain per axis (x, y, z)")
        if not 0.0 < alpha <= 1.0:
            raise ValueError(f"alpha={alpha!r}: the filter coefficient must be in (0, 1]")
        if not dt > 0:
            raise ValueError(f"dt={dt!r}: the servo period must be > 0")
        self.kp = [float(k) for k in kp] * 3
        self.kv = [float(k) for k in kv] * 3
        self.alpha = float(alpha)
        self.dt = float(dt)
        self.x_prev = [0.0] * 9
        self.v = [0.0] * 9

    def reset(self, x_m: Sequence[float], v: Sequence[float] | None = None) -> None:
        """Start from measured positions ``x_m`` (9) and a velocity estimate (default 0)."""
        self.x_prev = [float(a) for a in x_m]
        self.v = [0.0] * 9 if v is None else [float(a) for a in v]

    def cycle(self, x_m: Sequence[float], x_d: Sequence[float], v_d: Sequence[float]
              ) -> list[float]:
        """One servo cycle: update the velocity estimate from the new measurement
        ``x_m`` and return the servo force ``kp (x_d - x_m) + kv (v_d - v_m)`` (9)."""
        a = self.alpha
        inv = 1.0 / self.dt
        xp, v, kp, kv = self.x_prev, self.v, self.kp, self.kv
        f = [0.0] * 9
        for k in range(9):
            xk = x_m[k]
            vk = v[k] + a * ((xk - xp[k]) * inv - v[k])
            v[k] = vk
            f[k] = kp[k] * (x_d[k] - xk) + kv[k] * (v_d[k] - vk)
        self.x_prev = list(x_m)
        return f


def internal_forces(x_m: Sequence[float], grip: Sequence[float]
                    ) -> tuple[list[float], list[tuple[float, float] | None]]:
    """Internal (grip) forces of thesis 7.4.3.

    Parameters
    ----------
    x_m
        Measured tip positions (9).
    grip
        Grip magnitude of each pair (3, order of ``PAIRS``); pairs at 0 apply none.

    Returns
    -------
    forces, u
        Forces (9, horizontal) and, per pair, the unit vector ``u`` from its first
        finger toward its second (None for a pair without grip). The first finger is
        pushed along ``u``, the second along ``-u``: equal and opposite.

    Examples
    --------
    >>> x = [0.1, 0, 0, -0.1, 0, 0, 0, 0.3, 0]
    >>> f, u = internal_forces(x, [2.0, 0.0, 0.0])
    >>> [round(a, 6) for a in f], u
    ([-2.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0], [(-1.0, 0.0), None, None])
    """
    f = [0.0] * 9
    us: list[tuple[float, float] | None] = [None, None, None]
    for p in range(3):
        g = grip[p]
        if g <= 0.0:
            continue
        i, j = PAIRS[p]
        dx = x_m[3 * j] - x_m[3 * i]
        dy = x_m[3 * j + 1] - x_m[3 * i + 1]
        d = math.hypot(dx, dy)
        if d < 1e-12:
            continue
        ux, uy = dx / d, dy / d
        us[p] = (ux, uy)
        f[3 * i] += g * ux
        f[3 * i + 1] += g * uy
        f[3 * j] -= g * ux
        f[3 * j + 1] -= g * uy
    return f, us


class GripCheck:
    """The grip force and friction cone check of thesis 7.4.4.

    Parameters
    ----------
    nominal
        Nominal grip force (N): the least total force a gripping finger must push
        along its grip direction.
    settle
        Servo cycles to apply a nominal grip: the increment per cycle is
        ``nominal / settle`` (thesis: 40).
    saturation
        No grip is added for a finger whose total force exceeds this (N; thesis: 1 lb),
        nor to a pair whose grip already exceeds it.
    cone_mu
        Friction coefficient of the estimated cone (half-angle ``atan(cone_mu)``).

    Examples
    --------
    Two fingers squeeze along x with 1 N each, but finger 1's servo pulls it back 0.5 N:
    its total along the grip direction is 0.5 N < 1 N, so the pair's grip rises.

    >>> chk = GripCheck(nominal=1.0, settle=40, saturation=4.448, cone_mu=0.7)
    >>> total = [0.5, 0, 0, -1.0, 0, 0, 0, 0, 0]
    >>> chk(total, [(1.0, 0.0), None, None], [1.0, 0, 0], [1, 0, -1, 0, 0, 0], [3, 3, 0])
    [0.025, 0.0, 0.0]
    """

    def __init__(self, nominal: float, settle: int, saturation: float, cone_mu: float) -> None:
        if not nominal > 0 or not int(settle) >= 1:
            raise ValueError("nominal must be > 0 and settle >= 1")
        self.nominal = float(nominal)
        self.increment = float(nominal) / int(settle)
        self.saturation = float(saturation)
        self.cos_cone = math.cos(math.atan(float(cone_mu)))

    def _violates(self, total, k: int, ux: float, uy: float, normals) -> bool:
        """Finger ``k`` pushing along ``(ux, uy)`` (its grip direction) violates the
        grip check or the friction check, and may be helped by more grip."""
        fx, fy = total[3 * k], total[3 * k + 1]
        mag = math.hypot(fx, fy)
        if mag >= self.saturation:
            return False  # saturated: no additional force (7.4.4)
        if fx * ux + fy * uy < self.nominal:
            return True  # grip check
        nx, ny = normals[2 * k], normals[2 * k + 1]
        if nx == 0.0 and ny == 0.0:
            return False
        c = self.cos_cone
        # outside the estimated cone, while the grip direction itself is inside it
        return (fx * nx + fy * ny) <= c * mag and (ux * nx + uy * ny) > c

    def __call__(self, total: Sequence[float], u: Sequence[tuple[float, float] | None],
                 grip: Sequence[float], normals: Sequence[float], kind: Sequence[int]
                 ) -> list[float]:
        """Grip increments (3, per pair) for this servo cycle.

        Parameters
        ----------
        total
            Total commanded finger forces (9): servo + internal.
        u
            Pair directions from :func:`internal_forces` (None: pair without grip).
        grip
            Present pair grips (3).
        normals
            Inward unit normals (6, frame F) at the contacts; zeros: no cone check.
        kind
            Trajectory type per finger (3); only ``HOLD`` fingers are checked, not
            those in transition or making contact (7.4.2).
        """
        inc = [0.0, 0.0, 0.0]
        for p in range(3):
            up = u[p]
            if up is None or grip[p] >= self.saturation:
                continue
            i, j = PAIRS[p]
            ux, uy = up
            if (kind[i] == HOLD and self._violates(total, i, ux, uy, normals)) or (
                    kind[j] == HOLD and self._violates(total, j, -ux, -uy, normals)):
                inc[p] = self.increment
        return inc


class ContactDetector:
    """Contact detection of thesis 7.3: the servo force of a finger moving toward the
    object exceeds ``threshold`` (N) for ``cycles`` consecutive servo cycles.

    With approach ``directions`` given, the servo force's component along them is
    tested: at contact the object holds the finger back and the servo pushes it on
    along its path, while the transients of a finger that has just stopped or started
    (it lags or overshoots its desired point) push along or against the path for a few
    cycles. Without them, the magnitude (the thesis's test).

    Examples
    --------
    >>> det = ContactDetector(0.278, 3)
    >>> f = [0.5, 0, 0, 0.1, 0, 0, 0.5, 0, 0]
    >>> [det.update(f, [True, True, False]) for _ in range(3)][-1]
    [True, False, False]
    >>> det.reset()
    >>> d = [(-1.0, 0.0), (1.0, 0.0), (1.0, 0.0)]   # finger 1 moves in -x: f pulls back
    >>> [det.update(f, [True, True, False], d) for _ in range(3)][-1]
    [False, False, False]
    """

    def __init__(self, threshold: float, cycles: int) -> None:
        if not threshold > 0 or not int(cycles) >= 1:
            raise ValueError("threshold must be > 0 and cycles >= 1")
        self.threshold = float(threshold)
        self.threshold2 = float(threshold) ** 2
        self.cycles = int(cycles)
        self.count = [0, 0, 0]

    def reset(self) -> None:
        """Forget the counts."""
        self.count = [0, 0, 0]

    def update(self, servo_force: Sequence[float], armed: Sequence[bool],
               directions: Sequence[tuple[float, float] | None] | None = None
               ) -> list[bool]:
        """Count one cycle; return, per finger, whether contact is now assumed.

        Only ``armed`` fingers (trajectory type CONTACT) count; the horizontal servo
        force is tested (the vertical axis only holds the tips at mid-height), along
        the finger's unit approach direction when ``directions`` gives one.
        """
        out = [False, False, False]
        for k in range(3):
            if armed[k]:
                fx, fy = servo_force[3 * k], servo_force[3 * k + 1]
                d = directions[k] if directions is not None else None
                if d is None:
                    over = fx * fx + fy * fy > self.threshold2
                else:
                    over = fx * d[0] + fy * d[1] > self.threshold
                self.count[k] = self.count[k] + 1 if over else 0
                out[k] = self.count[k] >= self.cycles
            else:
                self.count[k] = 0
        return out
