"""The object localizer (thesis 7.4.5): the planar object pose from finger-tip positions.

Pure NumPy; no MuJoCo. The controller (thesis 7.3) runs it between trajectories, when the
fingers are on the object. Its inputs are the *expected* object pose, the measured
finger-tip positions and the object's shape; its output is a new pose estimate, which the
executor uses to recentre the object (error over 1/4 in, thesis 7.5), to aim the next
finger placement, and to fold the orientation error into the next rotation.

Frames and units
----------------
``F`` is the fixed workspace frame; the object frame ``f`` sits at pose
``(x, y, theta_deg)`` relative to ``F`` (metres, metres, degrees, counter-clockwise
positive). A point ``p_F`` lies at ``p_f = R(-theta) (p_F - (x, y))`` in ``f``. The
thesis's expected, trial and actual frames ``E``, ``T``, ``A`` are three such poses.

The error (thesis 7.4.5)
------------------------
For a trial pose ``T`` each finger is put in polar coordinates ``(R_t, phi)`` in ``T``
and compared with the object's radius ``R_a(phi)`` at the same polar angle::

    E(x, y, theta) = sum_i (R_t,i - R_a(phi_i))^2            (m^2)

*Ball tips.* The fingers end in balls of radius ``rho`` (thesis 7.2: 0.307 in = 7.8 mm).
The thesis models them as points; a point model puts every tip ``rho`` outside the
contour and biases the pose whenever the fingers are not symmetric about the centre.
We measure the tip *centre* against the object *grown by the tip radius* (the Minkowski
sum of the object and a disc of radius ``rho``: the locus of the centre of a ball
touching the object, :class:`GrownContour`). ``R_t`` is the distance of the tip centre
from the trial object centre and ``R_a`` the grown contour's radius along the same ray.
This is exact for any ``rho`` up to the table's 1e-6 m (no search for the contact point,
and a polygon's vertices grow into arcs of radius ``rho``, so ``E`` has no kinks there);
``tip_radius = 0`` gives the thesis's point fingers, ``R_a = r(phi)``. The grown set of a
star-shaped object is star-shaped about the same origin, so the ray meets it once.

The search (thesis 7.4.5)
-------------------------
Each iteration evaluates ``E`` on a grid of trial poses around the current estimate
(``(2n+1)^3`` offsets of ``step_xy`` in x, y and ``step_deg`` in theta, all in one NumPy
expression), takes the grid minimum ``(x_min, y_min, theta_min)`` and blends it with the
current estimate coordinate by coordinate::

    X_new = W_x X_old + (1 - W_x) X_min,   W_i = 1 / (1 + d^2E/di^2),  i = x, y, theta

the thesis's curvature weighting, "similar to the Levenberg-Marquardt approach": a
sharply curved (well observed) coordinate moves most of the way to the minimum, a flat
(poorly observed) one stays near the old value. The curvatures are central second
differences on the grid's own axis neighbours. Where the thesis is silent we chose:

- *Units of the curvature.* ``d^2E/dx^2`` is dimensionless in any length unit, but
  ``d^2E/dtheta^2`` is not: read literally (m^2 per rad^2, or in^2 per deg^2) it is
  ~1e-3 and theta would never move. We measure theta as arc length at the object's mean
  radius ``angle_scale`` (``s = angle_scale * theta``), so all three coordinates are
  lengths, ``W_theta`` is ~0.5 on an eccentric object and 1 on a circle, whose
  orientation is unobservable.
- *Iterating.* The thesis runs one blend per controller cycle (about 1 Hz), a filter
  "less noisy but slightly lagged". Here one call iterates to the fixed point: the grid
  is recentred on each new estimate and halved when its centre is best (coarse to fine),
  until the spacing is below ``min_step_xy`` / ``min_step_deg`` or the Gauss-Newton step
  (below) is under ten of them. The weights shape the path, not the answer: the fixed
  point is a minimum of ``E`` (plus the prior) near the expected pose.
  ``max_iterations=1, gauss_newton=False`` is the thesis's literal single step.
- *Safeguards.* The blend is taken only when it lowers ``E`` (a per-coordinate blend can
  climb out of a diagonal valley of ``E``; the grid minimum is taken then), and ``W`` is
  capped at ``max_weight`` (where ``E`` is flat or concave along a coordinate the formula
  gives ``W = 1`` and that coordinate would freeze).
- *Gauss-Newton.* Each iteration also tries the Levenberg-Marquardt pose built from the
  residuals' Jacobian at the grid centre, clipped to the initial local space; it is taken
  when it beats the whole grid and the blend. It is the full-matrix form of the thesis's
  per-coordinate weighting and walks the narrow valleys of ``E`` (weakly observed
  rotations) in a few steps where a grid crawls. ``gauss_newton=False`` turns it off.
- *A weak prior.* ``prior_weight * |T - E|^2`` (x, y in metres, theta as arc length) is
  added to the searched cost, never to the reported error. It breaks ties in directions
  the fingers do not observe -- a circle's orientation, the curve of poses that fit two
  contacts -- in favour of the expected pose.

Observability
-------------
Each finger measures one number, so three fingers give three equations for three
unknowns. They fix the pose when the residuals' Jacobian is well conditioned; the result
reports its singular values (``singular_values``, dimensionless, theta as arc length) so
the caller can tell. Cases worth knowing:

- *Circle:* the orientation is never observed (the expected angle is kept;
  ``singular_values[2] == 0``). Two fingers fix the centre up to its mirror image across
  the line through them (the centre is ``R + rho`` from both); for a near-antipodal pair
  the two lie close together and the search takes the one nearer the expected pose.
- *Two fingers:* two equations; on a non-circular object the poses that fit form a curve
  through the true pose. Both contacts fit but the position along the curve is a guess
  (near the expected pose).
- *Three fingers exactly 120 deg apart* observe rotation badly on the thesis objects: at
  three equally spaced angles the second harmonic of ``r(phi)`` (an ellipse, the eccentric
  hexagon) and the fifth (a pentagon) alias onto the first, which is a translation, so a
  small rotation looks like a shift. Fingers a little off that symmetry (e.g. a
  near-antipodal grasp and a third finger between) observe it well.
- *Polygons* with the three fingers on three edges have, besides the true pose, a second
  pose that fits exactly (edge lines through the tips: the rotation solves
  ``A cos(theta) + B sin(theta) = C``, two roots). A local search finds the one in
  its basin; from a start between them the answer can be the wrong one.

Recentring (thesis 7.4.5, 7.5): if the estimated position is more than
``allowable_error`` (1/4 in) from the expected one, ``LocalizerResult.recenter`` is set
and the next trajectory should move the object back; otherwise the error is only
tracked. ``orientation_error_deg`` is to be taken off the next rotation (7.5: "any
orientation error was corrected during each rotation phase").

Examples
--------
>>> from graspgait_env.shapes import Circle
>>> disc = Circle(0.05)
>>> tips = np.array([[0.051, 0.0], [-0.049, 0.0], [0.001, 0.05]])  # point tips, 1 mm off
>>> res = localize(disc, tips, (0.0, 0.0, 0.0), LocalizerConfig(tip_radius=0.0))
>>> [round(v, 6) + 0.0 for v in res.pose], res.recenter, res.converged
([0.001, 0.0, 0.0], False, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspgait_env.shapes import Polygon, Shape
from graspgait_env.sim.frames import INCH, wrap_deg

__all__ = [
    "LocalizerConfig",
    "LocalizerResult",
    "GrownContour",
    "ObjectLocalizer",
    "localize",
    "tips_in_object_frame",
    "finger_radius_errors",
    "pose_error",
    "curvature_weights",
    "wrap_deg",
]

# --------------------------------------------------------------------------- config


@dataclass(frozen=True)
class LocalizerConfig:
    """Parameters of the object localizer (thesis 7.4.5), SI units.

    The thesis gives the allowable error (1/4 in, 7.5) and the tip size (0.307 in, 7.2);
    it gives no search grid, so the grid is ours: wide enough to take a pose error of the
    allowable size in a couple of iterations, fine enough to end at 0.01 mm / 0.01 deg.
    """

    tip_radius: float = 0.307 * INCH
    """(m) finger-tip ball radius; 0.307 in = 7.8 mm (thesis 7.2). 0: point fingers."""
    allowable_error: float = 0.25 * INCH
    """(m) position error above which the object is recentred (thesis 7.5: 1/4 in)."""
    step_xy: float = 0.002
    """(m) initial grid spacing of the trial poses in x and y."""
    step_deg: float = 2.0
    """(degrees) initial grid spacing of the trial poses in theta."""
    grid_half_width: int = 2
    """Trial poses each side of the centre per coordinate: ``(2n+1)^3`` per iteration."""
    min_step_xy: float = 1e-5
    """(m) the search ends once the x, y spacing is below this (0.01 mm) and ..."""
    min_step_deg: float = 0.01
    """(degrees) ... the theta spacing below this; or once a Gauss-Newton step is below
    ten of each."""
    max_iterations: int = 60
    """Most grid evaluations in one call; ``converged`` is False when they run out."""
    curvature_weighting: bool = True
    """Blend with W_i = 1/(1 + d^2E/di^2) (thesis); False: jump to the grid minimum."""
    max_weight: float = 0.9
    """Cap on W_i, so that a coordinate along which E is flat or concave still moves."""
    gauss_newton: bool = True
    """Also try the Levenberg-Marquardt pose each iteration (see the module docstring)."""
    gn_damping: float = 1e-4
    """(dimensionless) Levenberg-Marquardt damping added to J^T J: bounds the step along
    directions the fingers barely observe (J^T J eigenvalue << damping)."""
    angle_scale: float | None = None
    """(m) radius at which theta is measured as arc length (W_theta, the prior, the
    singular values); None: the object's mean radius (r_min + r_max) / 2."""
    prior_weight: float = 1e-6
    """(dimensionless) weight of |trial - expected|^2 in the searched cost. Tiny: breaks
    ties in unobserved directions only. Larger values also pull weakly observed
    directions (J^T J eigenvalue below the weight) toward the expected pose, a
    regularizer against noise that biases exact data: at 1e-2, up to 0.2 mm and 0.5 deg
    on the thesis objects from 6 mm / 5 deg off."""
    contour_resolution_deg: float = 0.1
    """(degrees) sampling of the grown contour table (:class:`GrownContour`)."""

    def __post_init__(self) -> None:
        def number(name: str, lo: float, strict: bool) -> None:
            v = getattr(self, name)
            ok = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
            if not ok or (v <= lo if strict else v < lo):
                rel = ">" if strict else ">="
                raise ValueError(
                    f"LocalizerConfig.{name}={v!r}: must be a finite number {rel} {lo}"
                )

        for name in ("tip_radius", "prior_weight", "gn_damping", "max_weight"):
            number(name, 0.0, strict=False)
        for name in ("allowable_error", "step_xy", "step_deg", "min_step_xy", "min_step_deg",
                     "contour_resolution_deg"):
            number(name, 0.0, strict=True)
        if self.angle_scale is not None:
            number("angle_scale", 0.0, strict=True)
        if self.max_weight >= 1.0:
            raise ValueError(
                f"LocalizerConfig.max_weight={self.max_weight!r}: must be < 1 (1 would "
                "freeze a coordinate); the default is 0.9"
            )
        for name in ("grid_half_width", "max_iterations"):
            v = getattr(self, name)
            if not isinstance(v, (int, np.integer)) or isinstance(v, bool) or v < 1:
                raise ValueError(f"LocalizerConfig.{name}={v!r}: must be an integer >= 1")


@dataclass(frozen=True)
class LocalizerResult:
    """Output of the object localizer.

    ``pose`` is ``(x, y, theta_deg)`` of frame ``f`` in ``F`` (m, m, degrees); theta is
    continuous with the expected angle (not wrapped), so a gait's accumulated rotation
    survives. ``error`` is the thesis's E at ``pose`` (m^2, without the prior);
    ``rms_error`` is ``sqrt(E / m)`` (m) and ``residuals`` the per-finger ``R_t - R_a``
    (m; positive: the finger is outside the object).
    """

    pose: tuple[float, float, float]
    error: float
    rms_error: float
    residuals: NDArray[np.float64]
    iterations: int
    converged: bool
    weights: tuple[float, float, float]
    """Last curvature weights (W_x, W_y, W_theta), capped at ``max_weight``."""
    singular_values: tuple[float, float, float]
    """Singular values of the residual Jacobian d(R_t - R_a)/d(x, y, s) at the estimate,
    largest first (dimensionless; s = angle_scale * theta). Near 0: a pose direction the
    fingers do not observe (a circle's rotation, the curve of poses two fingers allow)."""
    expected_pose: tuple[float, float, float]
    position_error: tuple[float, float]
    """(m) estimated minus expected position, frame F."""
    orientation_error_deg: float
    """(degrees, wrapped) estimated minus expected angle: take it off the next rotation."""
    recenter: bool
    """|position_error| > allowable_error: the next trajectory should recentre the object."""


# --------------------------------------------------------------------------- geometry


class GrownContour:
    """Radial function of the object grown by the tip radius: where a ball tip's centre is.

    The grown set is the Minkowski sum of the object and a disc of radius ``tip_radius``:
    the centre of a ball of that radius touching the object lies on its boundary. It is
    star-shaped about the object's origin (a Minkowski sum of two sets star-shaped about
    the origin is), so each ray meets the boundary once. Its radial function is
    tabulated once: along each ray the farthest point within ``tip_radius`` of a dense
    sampling of the contour (plus a polygon's vertices, which grow into arcs); between
    samples it is interpolated linearly. ``tip_radius = 0`` queries the shape itself.

    Accuracy at the default 0.1 deg: within 1e-6 m of the exact grown boundary (5e-7 m
    on the thesis objects: the discs about samples 0.1 deg apart, and the linear
    interpolation across the arcs of radius ``rho`` about a polygon's vertices); exact on
    a circle. Building the table takes ~10 ms.

    Parameters
    ----------
    shape
        The object's contour (frame f).
    tip_radius
        Ball radius (m), >= 0.
    resolution_deg
        Spacing of the table (degrees).

    Examples
    --------
    >>> from graspgait_env.shapes import Circle
    >>> g = GrownContour(Circle(0.05), 0.01)
    >>> np.round(g.radius_deg([0.0, 123.0]), 9).tolist()
    [0.06, 0.06]
    """

    def __init__(self, shape: Shape, tip_radius: float, resolution_deg: float = 0.1) -> None:
        self.shape = shape
        self.tip_radius = float(tip_radius)
        n = max(int(math.ceil(360.0 / float(resolution_deg))), 8)
        self._n = n
        self._inv_step = n / (2.0 * math.pi)
        if self.tip_radius == 0.0:
            self._table = None
            return
        rho = self.tip_radius
        alpha = np.linspace(-math.pi, math.pi, n + 1)[:-1]          # the rays, (n,)
        ux, uy = np.cos(alpha), np.sin(alpha)
        p = np.asarray(shape.contour_point(np.rad2deg(alpha)), dtype=np.float64)
        best = np.full(n, -np.inf)

        def grow(px: NDArray, py: NDArray) -> None:
            # farthest intersection of each ray with the disc of radius rho about (px, py)
            a = ux * px + uy * py
            perp2 = px * px + py * py - a * a
            t = a + np.sqrt(np.maximum(rho * rho - perp2, 0.0))
            np.maximum(best, np.where(perp2 <= rho * rho, t, -np.inf), out=best)

        # a contour sample within rho of a ray lies within asin(rho / |p|) of it
        r_min = float(shape.r_min)
        half = math.asin(min(1.0, rho / r_min)) if r_min > 0 else math.pi
        w = min(int(math.ceil(half * self._inv_step)) + 1, n // 2)
        idx = np.arange(n)
        for o in range(-w, w + 1):
            j = (idx + o) % n
            grow(p[j, 0], p[j, 1])
        if isinstance(shape, Polygon):  # exact vertices: their arcs, not sampled chords
            for vx, vy in shape.vertices:
                grow(np.full(n, vx), np.full(n, vy))
        # star-shaped: the boundary is at least the contour pushed out along the ray
        base = np.asarray(shape.radius(np.rad2deg(alpha)), dtype=np.float64)
        best = np.maximum(best, base)
        self._table = np.r_[best, best[0]]  # periodic: phi = +pi maps to index n

    def radius(self, phi: NDArray[np.float64]) -> NDArray[np.float64]:
        """Grown radius (m) along polar angles ``phi`` in radians, in [-pi, pi]."""
        if self._table is None:
            return self.shape.radius(np.rad2deg(phi))
        t = (np.asarray(phi) + math.pi) * self._inv_step
        i = np.minimum(t.astype(np.intp), self._n - 1)
        lo = self._table[i]
        return lo + (t - i) * (self._table[i + 1] - lo)

    def radius_deg(self, phi_deg: ArrayLike) -> NDArray[np.float64]:
        """Grown radius (m) along polar angles in degrees (any range)."""
        phi = np.deg2rad(wrap_deg(phi_deg))
        return self.radius(phi)


@lru_cache(maxsize=32)
def _grown_cached(shape: Shape, tip_radius: float, resolution_deg: float) -> GrownContour:
    return GrownContour(shape, tip_radius, resolution_deg)


def _grown(shape: Shape, tip_radius: float, resolution_deg: float) -> GrownContour:
    """The grown contour, tabulated once per (shape, tip radius, resolution)."""
    try:
        return _grown_cached(shape, tip_radius, resolution_deg)
    except TypeError:  # an unhashable shape: no cache
        return GrownContour(shape, tip_radius, resolution_deg)


def _as_tips(tips_F: ArrayLike) -> NDArray[np.float64]:
    tips = np.asarray(tips_F, dtype=np.float64)
    if tips.ndim != 2 or tips.shape[1] != 2:
        raise ValueError(
            f"tips_F: expected an (m, 2) array of finger-tip positions (m, frame F), "
            f"got shape {tips.shape}"
        )
    if len(tips) < 2:
        raise ValueError(
            f"tips_F: {len(tips)} finger(s); the localizer needs at least 2 fingers in "
            "contact (3 to observe the whole pose)"
        )
    if not np.all(np.isfinite(tips)):
        raise ValueError("tips_F: contains NaN or inf; give measured positions in metres")
    return tips


def _as_poses(poses: ArrayLike) -> NDArray[np.float64]:
    p = np.asarray(poses, dtype=np.float64)
    if p.shape[-1:] != (3,):
        raise ValueError(f"pose: expected (x, y, theta_deg) on the last axis, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("pose: contains NaN or inf")
    return p


def tips_in_object_frame(tips_F: ArrayLike, poses: ArrayLike) -> NDArray[np.float64]:
    """Finger tips (m, frame F) in the object frame at each pose.

    Parameters
    ----------
    tips_F
        ``(m, 2)`` tip positions (m, frame F).
    poses
        ``(..., 3)`` object poses ``(x, y, theta_deg)``.

    Returns
    -------
    ``(..., m, 2)`` positions (m, frame f).

    Examples
    --------
    >>> tips_in_object_frame([[1.0, 1.0]], [1.0, 0.0, 90.0]).round(12).tolist()
    [[1.0, 0.0]]
    """
    tips = np.asarray(tips_F, dtype=np.float64).reshape(-1, 2)
    p = _as_poses(poses)
    th = np.deg2rad(p[..., 2:3])
    c, s = np.cos(th), np.sin(th)
    dx = tips[:, 0] - p[..., 0:1]
    dy = tips[:, 1] - p[..., 1:2]
    return np.stack([c * dx + s * dy, c * dy - s * dx], axis=-1)


def finger_radius_errors(
    shape: Shape, tips_F: ArrayLike, poses: ArrayLike, tip_radius: float = 0.0,
    resolution_deg: float = 0.1,
) -> NDArray[np.float64]:
    """Per-finger radius error ``R_t - R_a`` (m) at each trial pose (thesis 7.4.5).

    ``R_t`` is the distance from the trial object centre to the finger (tip centre),
    ``R_a`` the radius of the object grown by ``tip_radius`` (:class:`GrownContour`)
    along the same ray in the trial frame. Positive: the finger is outside the object.

    Parameters
    ----------
    shape
        The object's contour, frame f.
    tips_F
        ``(m, 2)`` finger-tip centres (m, frame F).
    poses
        ``(..., 3)`` trial poses ``(x, y, theta_deg)``.
    tip_radius
        Ball-tip radius (m); 0 for point fingers.
    resolution_deg
        Table spacing of the grown contour (unused for point fingers).

    Returns
    -------
    ``(..., m)`` errors (m).

    Examples
    --------
    >>> from graspgait_env.shapes import Circle
    >>> finger_radius_errors(Circle(0.05), [[0.06, 0.0]], [0.0, 0.0, 0.0]).round(6).tolist()
    [0.01]
    """
    q = tips_in_object_frame(tips_F, poses)
    grown = _grown(shape, float(tip_radius), float(resolution_deg))
    return np.hypot(q[..., 0], q[..., 1]) - grown.radius(np.arctan2(q[..., 1], q[..., 0]))


def pose_error(
    shape: Shape, tips_F: ArrayLike, poses: ArrayLike, tip_radius: float = 0.0,
    resolution_deg: float = 0.1,
) -> NDArray[np.float64]:
    """The thesis's error ``E = sum_i (R_t - R_a)^2`` (m^2) at each trial pose ``(..., 3)``.

    Zero at the true pose for exact measurements; see :func:`finger_radius_errors`.
    """
    e = finger_radius_errors(shape, tips_F, poses, tip_radius, resolution_deg)
    return np.sum(e * e, axis=-1)


def curvature_weights(
    e_center: ArrayLike, e_plus: ArrayLike, e_minus: ArrayLike, step: ArrayLike
) -> NDArray[np.float64]:
    """Thesis weights ``W_i = 1 / (1 + d^2E/di^2)`` from a central second difference.

    ``d^2E/di^2 ~ (E(+h) - 2 E(0) + E(-h)) / h^2`` with ``h = step``. A negative estimate
    (E concave there) counts as zero curvature: W = 1, keep the old value. The
    coordinates must be lengths (theta as arc length) for the formula to be unit-free.

    Examples
    --------
    >>> float(curvature_weights(0.0, 1.5, 1.5, 1.0))   # E = 1.5 i^2: d2E = 3, W = 1/4
    0.25
    """
    e0 = np.asarray(e_center, dtype=np.float64)
    h = np.asarray(step, dtype=np.float64)
    d2 = (np.asarray(e_plus) - 2.0 * e0 + np.asarray(e_minus)) / (h * h)
    return 1.0 / (1.0 + np.maximum(d2, 0.0))


# --------------------------------------------------------------------------- localizer


def _grid(n: int) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """Integer offsets (K, 3), centre first; and the indices (3, 2) of the +/- axis neighbours."""
    r = np.arange(-n, n + 1, dtype=np.float64)
    g = np.stack(np.meshgrid(r, r, r, indexing="ij"), axis=-1).reshape(-1, 3)
    centre = int(np.flatnonzero(np.all(g == 0, axis=1))[0])
    g = g[np.r_[centre, np.delete(np.arange(len(g)), centre)]]
    nb = np.empty((3, 2), dtype=np.intp)
    for a in range(3):
        for j, sgn in enumerate((1.0, -1.0)):
            e = np.zeros(3)
            e[a] = sgn
            nb[a, j] = int(np.flatnonzero(np.all(g == e, axis=1))[0])
    return g, nb


def _solve3(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Solve the 3 x 3 system ``a x = b`` by Cramer's rule (LAPACK costs more at this
    size); None when ``a`` is singular."""
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = a.tolist()
    b0, b1, b2 = b.tolist()
    c00 = a11 * a22 - a12 * a21
    c01 = a12 * a20 - a10 * a22
    c02 = a10 * a21 - a11 * a20
    det = a00 * c00 + a01 * c01 + a02 * c02
    if not math.isfinite(det) or abs(det) < 1e-300:
        return None
    x0 = b0 * c00 + a01 * (a12 * b2 - b1 * a22) + a02 * (b1 * a21 - a11 * b2)
    x1 = a00 * (b1 * a22 - a12 * b2) + b0 * c01 + a02 * (a10 * b2 - b1 * a20)
    x2 = a00 * (a11 * b2 - b1 * a21) + a01 * (b1 * a20 - a10 * b2) + b0 * c02
    return np.array([x0, x1, x2]) / det


_JAC_STEP = 1e-7  # (m) forward-difference step of the Jacobian: far above rounding of r


class ObjectLocalizer:
    """The object localizer of thesis 7.4.5 for one object shape.

    Build once per object (it tabulates the grown contour, ~10 ms); :meth:`localize`
    then costs two vectorized evaluations of ``E`` per iteration, 3-5 iterations from a
    pose error of the allowable size: ~0.3-0.5 ms. See the module docstring for the
    algorithm and the choices made where the thesis is silent.

    Parameters
    ----------
    shape
        The object's contour in frame f.
    config
        Search parameters; default :class:`LocalizerConfig`.
    """

    def __init__(self, shape: Shape, config: LocalizerConfig | None = None) -> None:
        if not isinstance(shape, Shape):
            raise TypeError(f"shape: expected a graspgait_env Shape, got {type(shape).__name__}")
        if config is not None and not isinstance(config, LocalizerConfig):
            raise TypeError(f"config: expected a LocalizerConfig, got {type(config).__name__}")
        self.shape = shape
        self.config = cfg = config if config is not None else LocalizerConfig()
        self.angle_scale = (
            float(cfg.angle_scale)
            if cfg.angle_scale is not None
            else 0.5 * (float(shape.r_min) + float(shape.r_max))
        )
        """(m) radius at which theta is measured as arc length (W_theta, prior)."""
        self.grown = _grown(shape, float(cfg.tip_radius), float(cfg.contour_resolution_deg))
        """The object grown by the tip radius: where the tip centres lie."""
        self._offsets, self._neighbours = _grid(int(cfg.grid_half_width))

    def residuals(self, tips_F: ArrayLike, poses: ArrayLike) -> NDArray[np.float64]:
        """Per-finger ``R_t - R_a`` (m), shape ``(..., m)``, at trial poses ``(..., 3)``
        (``(x, y, theta_deg)``): :func:`finger_radius_errors` with this localizer's tips."""
        q = tips_in_object_frame(_as_tips(tips_F), poses)
        return np.hypot(q[..., 0], q[..., 1]) - self.grown.radius(
            np.arctan2(q[..., 1], q[..., 0])
        )

    def _trial_residuals(self, tips: NDArray, u: NDArray) -> NDArray[np.float64]:
        """Residuals (K, m) at trial poses u (K, 3) = (x m, y m, arc length m)."""
        th = u[:, 2:3] / self.angle_scale
        c, s = np.cos(th), np.sin(th)
        dx = tips[:, 0] - u[:, 0:1]
        dy = tips[:, 1] - u[:, 1:2]
        qx = c * dx + s * dy
        qy = c * dy - s * dx
        return np.hypot(qx, qy) - self.grown.radius(np.arctan2(qy, qx))

    def localize(self, tips_F: ArrayLike, expected_pose: ArrayLike) -> LocalizerResult:
        """Estimate the object pose from the finger tips in contact (thesis 7.4.5).

        Parameters
        ----------
        tips_F
            ``(m, 2)`` centres of the finger tips in contact (m, frame F), ``m >= 2``
            (three observe the whole pose; see the module docstring for two).
        expected_pose
            ``(x, y, theta_deg)``: where the gait plan says the object is (frame E).

        Returns
        -------
        LocalizerResult
        """
        cfg = self.config
        tips = _as_tips(tips_F)
        exp = _as_poses(expected_pose).reshape(3)
        # Search coordinates u = (x, y, s): metres, theta as arc length s = scale * theta,
        # so that E's curvature (thesis W_i) and the prior are unit-consistent.
        scale = self.angle_scale
        u_exp = np.array([exp[0], exp[1], scale * math.radians(exp[2])])
        h = np.array([cfg.step_xy, cfg.step_xy, scale * math.radians(cfg.step_deg)])
        h_min = np.array([cfg.min_step_xy, cfg.min_step_xy,
                          scale * math.radians(cfg.min_step_deg)])
        lam = cfg.prior_weight
        offsets, nb = self._offsets, self._neighbours
        n_grid = len(offsets)
        trust = float(cfg.grid_half_width) * h      # the initial local space bounds a step
        damp = (lam + cfg.gn_damping) * np.eye(3)
        probes = _JAC_STEP * np.eye(3)
        trial = np.empty((n_grid + 3, 3))

        u = u_exp.copy()
        w = np.ones(3)
        jtj = np.zeros((3, 3))
        converged = False
        it = 0
        while it < cfg.max_iterations:
            it += 1
            # the local space around u, plus three poses a hair away along each axis
            # (forward-difference Jacobian for Gauss-Newton): one evaluation of E
            np.multiply(offsets, h, out=trial[:n_grid])
            trial[n_grid:] = probes
            trial += u
            r_all = self._trial_residuals(tips, trial)
            r = r_all[:n_grid]
            e = np.einsum("km,km->k", r, r)                         # thesis E per trial pose
            d = trial[:n_grid] - u_exp
            cost = e + lam * np.einsum("kj,kj->k", d, d)
            k = int(np.argmin(cost))                                # ties -> centre (k = 0)
            if cfg.curvature_weighting:                             # thesis W_i
                w = np.minimum(curvature_weights(e[0], e[nb[:, 0]], e[nb[:, 1]], h),
                               cfg.max_weight)
            else:
                w = np.zeros(3)
            jac = ((r_all[n_grid:] - r[0]) / _JAC_STEP).T           # (m, 3), dimensionless
            jtj = jac.T @ jac

            cands = []
            delta = None
            if cfg.gauss_newton:  # Levenberg-Marquardt step, clipped to the local space
                delta = _solve3(jtj + damp, -(jac.T @ r[0] + lam * (u - u_exp)))
                if delta is not None:
                    if bool(np.all(np.abs(delta) < 10 * h_min)):   # stationary point: done
                        u = u + delta
                        converged = True
                        break
                    delta *= min(1.0, float(np.min(trust / np.maximum(np.abs(delta), 1e-300))))
                    cands.append(u + delta)
            if k != 0:
                cands.append(w * u + (1.0 - w) * trial[k])          # thesis 7.4.5 blending
            if cands:
                c = np.array(cands)
                r2 = self._trial_residuals(tips, c)
                d2 = c - u_exp
                cost2 = np.einsum("km,km->k", r2, r2) + lam * np.einsum("kj,kj->k", d2, d2)

            # Next centre: the Gauss-Newton pose when it beats the grid and the blend;
            # else the thesis's blended pose when it lowers the cost; else the grid
            # minimum (a blend can climb out of a diagonal valley); else refine.
            best_other = min(cost[k], cost2[-1]) if k != 0 else cost[0]
            if delta is not None and cost2[0] < best_other:
                u = c[0]
                h = np.clip(2.0 * np.abs(delta), 0.5 * h_min, h)    # quadratic regime
            elif k != 0:
                u = c[-1] if cost2[-1] < cost[0] else trial[k].copy()
            else:                                                   # centre best: refine
                if np.all(h < h_min):
                    converged = True
                    break
                h = np.maximum(0.5 * h, 0.5 * h_min)

        sv = np.sqrt(np.clip(np.linalg.eigvalsh(jtj)[::-1], 0.0, None))  # at the last centre
        theta_deg = math.degrees(u[2] / scale)
        pose = (float(u[0]), float(u[1]), theta_deg)
        res = self.residuals(tips, pose)
        err = float(np.dot(res, res))
        dpos = (pose[0] - float(exp[0]), pose[1] - float(exp[1]))
        return LocalizerResult(
            pose=pose,
            error=err,
            rms_error=math.sqrt(err / len(tips)),
            residuals=res,
            iterations=it,
            converged=converged,
            weights=(float(w[0]), float(w[1]), float(w[2])),
            singular_values=(float(sv[0]), float(sv[1]), float(sv[2])),
            expected_pose=(float(exp[0]), float(exp[1]), float(exp[2])),
            position_error=dpos,
            orientation_error_deg=float(wrap_deg(theta_deg - exp[2])),
            recenter=bool(math.hypot(*dpos) > cfg.allowable_error),
        )


@lru_cache(maxsize=32)
def _localizer(shape: Shape, config: LocalizerConfig) -> ObjectLocalizer:
    return ObjectLocalizer(shape, config)


def localize(
    shape: Shape,
    tips_F: ArrayLike,
    expected_pose: ArrayLike,
    config: LocalizerConfig | None = None,
) -> LocalizerResult:
    """Estimate the object pose from finger-tip positions (thesis 7.4.5).

    One-shot form of :class:`ObjectLocalizer` (kept for the last few shapes and configs,
    so repeated calls do not tabulate the grown contour again). ``tips_F`` is ``(m, 2)``
    tip centres (m, frame F) of the fingers in contact; ``expected_pose`` is
    ``(x, y, theta_deg)``. See the module docstring.
    """
    cfg = config if config is not None else LocalizerConfig()
    try:
        loc = _localizer(shape, cfg)
    except TypeError:  # an unhashable shape: no cache
        loc = ObjectLocalizer(shape, cfg)
    return loc.localize(tips_F, expected_pose)
