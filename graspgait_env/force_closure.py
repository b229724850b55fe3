"""Force closure of two point contacts with Coulomb friction (thesis 2.3, 3.2).

Two independent tests, vectorized over any number of contact pairs:

- :func:`force_closure_wrench` — the thesis's formulation (section 3.2). The four
  contact wrenches (two normal, two tangential) form the columns of the 3 × 4 matrix
  ``W``; the grasp is force-closure when ``W`` has rank 3 and its one homogeneous
  solution ``c_h`` (the internal force) can be scaled by some ``lambda`` so that both
  normal intensities are positive and both tangential intensities lie strictly inside
  their friction limits: ``lambda c_h1 > 0``, ``lambda c_h2 > 0``,
  ``|c_h3| < mu c_h1``, ``|c_h4| < mu c_h2`` (after choosing the sign of ``lambda``).
  The thesis prints one-sided friction constraints (``c3 <= mu c1``); the Coulomb cone
  is two-sided, so we test ``|c3| < mu c1`` — a choice, tested in
  ``tests/test_force_closure.py``. Strict inequalities: a grasp exactly on the cone
  boundary is not force-closure.
- :func:`force_closure_nguyen` — Nguyen's geometric test: the line joining the
  contacts lies strictly inside both friction cones (half-angle ``atan(mu)``), with
  the fingers either squeezing (``d = p2 - p1`` inside the cone at ``p1`` and ``-d``
  inside the cone at ``p2``) or pushing apart (the reverse: two fingers in a notch of
  a non-convex object pressing its walls outward). Both are force-closure; the wrench
  test finds both, and so must this one. On a convex object only squeezing occurs.

Both are mathematically the same set (squeezing and pushing-apart grasps alike);
numerically they can differ only within rounding of the cone boundary, which
:func:`cone_margin_deg` measures.

Conventions: points and inward unit normals in any common frame (metres), trailing
axis (x, y). ``mu`` is the Coulomb coefficient (dimensionless, > 0).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["force_closure_nguyen", "force_closure_wrench", "cone_margin_deg", "check_mu"]


def check_mu(mu: float) -> float:
    """Validate the friction coefficient: a finite number > 0."""
    if isinstance(mu, bool) or not isinstance(mu, (int, float, np.floating)):
        raise ValueError(f"mu={mu!r}: must be a number; give the Coulomb coefficient, e.g. 0.7")
    if not math.isfinite(mu) or mu <= 0:
        raise ValueError(f"mu={mu!r}: must be finite and > 0; give e.g. mu=0.7")
    return float(mu)


def _pair_geometry(p1, n1, p2, n2):
    p1, n1, p2, n2 = (np.asarray(a, dtype=np.float64) for a in (p1, n1, p2, n2))
    d = p2 - p1
    dist = np.hypot(d[..., 0], d[..., 1])
    c1 = np.einsum("...i,...i->...", d, n1)  # |d| cos(angle between d and n1)
    c2 = -np.einsum("...i,...i->...", d, n2)  # |d| cos(angle between -d and n2)
    return dist, c1, c2


def force_closure_nguyen(
    p1: ArrayLike, n1: ArrayLike, p2: ArrayLike, n2: ArrayLike, mu: float
) -> NDArray[np.bool_]:
    """Nguyen's test: the line p1→p2 lies strictly inside both friction cones.

    Parameters
    ----------
    p1, p2
        Contact points, shape ``(..., 2)`` (m).
    n1, n2
        Inward unit normals at the contacts, shape ``(..., 2)``.
    mu
        Coulomb friction coefficient (> 0).

    Returns
    -------
    ndarray of bool, shape ``(...)``
        False for coincident contacts.
    """
    cos_a = math.cos(math.atan(check_mu(mu)))
    dist, c1, c2 = _pair_geometry(p1, n1, p2, n2)
    lim = cos_a * dist
    squeeze = (c1 > lim) & (c2 > lim)
    expand = (-c1 > lim) & (-c2 > lim)
    return (squeeze | expand) & (dist > 0)


def cone_margin_deg(
    p1: ArrayLike, n1: ArrayLike, p2: ArrayLike, n2: ArrayLike, mu: float
) -> NDArray[np.float64]:
    """Signed distance (degrees) of the grasp from the friction-cone boundary.

    ``atan(mu) - max(angle(d, n1), angle(-d, n2))`` with ``d = p2 - p1`` for a
    squeezing grasp, the same with ``-d`` for fingers pushing apart; the larger of the
    two. Positive inside both cones (force-closure), negative outside, zero on the
    boundary.
    """
    alpha = math.atan(check_mu(mu))
    dist, c1, c2 = _pair_geometry(p1, n1, p2, n2)
    with np.errstate(invalid="ignore", divide="ignore"):
        a1 = np.arccos(np.clip(c1 / dist, -1.0, 1.0))
        a2 = np.arccos(np.clip(c2 / dist, -1.0, 1.0))
    squeeze = np.maximum(a1, a2)
    expand = np.maximum(np.pi - a1, np.pi - a2)
    return np.rad2deg(alpha - np.minimum(squeeze, expand))


def force_closure_wrench(
    p1: ArrayLike, n1: ArrayLike, p2: ArrayLike, n2: ArrayLike, mu: float, rank_tol: float = 1e-12
) -> NDArray[np.bool_]:
    """The thesis's wrench-matrix test (section 3.2), vectorized.

    ``W = [w_1n, w_2n, w_1t, w_2t]`` with planar wrenches ``w = (f_x, f_y, p × f)``
    and tangents ``t = n`` rotated +90°. For a 3 × 4 matrix the homogeneous solution
    is given by signed 3 × 3 minors (``c_h[k] = (-1)^k det W_without_column_k``); it
    is zero exactly when ``rank W < 3``.

    Parameters
    ----------
    p1, n1, p2, n2, mu
        As for :func:`force_closure_nguyen`.
    rank_tol
        Rank-3 threshold on ``|c_h|`` relative to the wrench scale.
    """
    mu = check_mu(mu)
    p1, n1, p2, n2 = (np.asarray(a, dtype=np.float64) for a in (p1, n1, p2, n2))
    t1 = np.stack([-n1[..., 1], n1[..., 0]], axis=-1)
    t2 = np.stack([-n2[..., 1], n2[..., 0]], axis=-1)

    def wrench(p, f):
        return np.stack([f[..., 0], f[..., 1], p[..., 0] * f[..., 1] - p[..., 1] * f[..., 0]], -1)

    W = np.stack([wrench(p1, n1), wrench(p2, n2), wrench(p1, t1), wrench(p2, t2)], axis=-1)
    cols = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]
    ch = np.stack(
        [(-1) ** k * np.linalg.det(W[..., :, cols[k]]) for k in range(4)], axis=-1
    )  # W @ ch == 0 (generalised cross product)
    scale = np.max(np.abs(W), axis=(-2, -1)) ** 3 + 1e-300
    rank3 = np.linalg.norm(ch, axis=-1) > rank_tol * scale
    sign = np.where(ch[..., 0] >= 0, 1.0, -1.0)  # choose lambda so that c_h1 >= 0
    c = ch * sign[..., None]
    return (
        rank3
        & (c[..., 0] > 0)
        & (c[..., 1] > 0)
        & (np.abs(c[..., 2]) < mu * c[..., 0])
        & (np.abs(c[..., 3]) < mu * c[..., 1])
    )
