"""Grasp maps (thesis 2.3 "The Grasp Map", 3.2).

``stable[i, j]`` is True when fingers at ``phi_i`` and ``phi_j`` (object frame ``f``)
make a force-closure two-point grasp with Coulomb friction ``mu``, where
``phi_k = 360 k / n`` degrees (default ``n = 180``: 2°, as in the thesis). The map is
symmetric and its diagonal is False. A contact exactly on a polygon vertex has no
defined normal and is never part of a stable grasp. Contacts beyond a reach limit
(``max_radius``, thesis 4.2 and fig. 4.3) are marked unusable: their rows and columns
are False.

The *extended grasp map* (thesis fig. 3.3) repeats the map every 360° in both axes.
:meth:`GraspMap.extended` and :meth:`GraspMap.window` return read-only **views** of
one 2 × 2 tiling whose top-left block *is* ``stable``, so no copy is made per call.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from graspgait_env.contact_model import POINT_CONTACTS, ContactModel, rolling_contacts_deg
from graspgait_env.force_closure import check_mu, force_closure_wrench
from graspgait_env.shapes import Shape

__all__ = ["GraspMap", "grasp_map", "grasp_map_loop", "grid_angles_deg", "check_n"]


# (grid points) the largest grid: a map peaks at about 45 bytes per cell while it is
# computed, 2.2 GB and 7.5 s measured at n = 7200 (a 0.05-degree grid) on a 2-core,
# 24 GiB machine; n = 20000 took 16 GiB before finishing.
MAX_N = 7200


def check_n(n: int) -> int:
    """Validate the number of contacts on the grid: an integer in ``[4, MAX_N]``."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 4:
        raise ValueError(f"n={n!r}: must be an integer >= 4 (grid points on the contour), e.g. 180")
    if n > MAX_N:
        raise ValueError(f"n={n!r}: at most {MAX_N} grid points (a {360 / MAX_N:g}-degree grid; "
                         f"a map needs about 45 bytes per cell, 2.2 GB at n={MAX_N}); "
                         "give e.g. 180")
    return int(n)


def grid_angles_deg(n: int) -> NDArray[np.float64]:
    """Contact angles of the grid, ``phi_k = 360 k / n`` degrees, k = 0..n-1."""
    return 360.0 * np.arange(check_n(n)) / n


@dataclass(frozen=True, eq=False)
class GraspMap:
    """A boolean grasp map with its angles.

    Attributes
    ----------
    stable
        ``(n, n)`` bool, ``stable[i, j]`` for contacts at ``phi_deg[i]``, ``phi_deg[j]``.
        Read-only.
    phi_deg
        ``(n,)`` contact angles (degrees, object frame).
    mu
        Friction coefficient the map was computed for.
    shape_name
        Name of the object.
    usable
        ``(n,)`` bool: contacts that are within reach and not on a vertex.
    """

    stable: NDArray[np.bool_]
    phi_deg: NDArray[np.float64]
    mu: float
    shape_name: str
    usable: NDArray[np.bool_]
    _tiled: NDArray[np.bool_] = field(repr=False)

    @property
    def n(self) -> int:
        """Number of contacts on the grid."""
        return len(self.phi_deg)

    @property
    def step_deg(self) -> float:
        """Grid spacing (degrees)."""
        return 360.0 / self.n

    def __array__(self, dtype=None, copy=None):
        return self.stable if dtype is None else self.stable.astype(dtype)

    def window(self, i0: int, j0: int, size: int) -> NDArray[np.bool_]:
        """View of the extended map: rows ``i0..i0+size-1``, columns ``j0..j0+size-1``.

        Indices wrap modulo ``n`` (so ``i0`` may be negative or beyond ``n``);
        ``size <= n``. The result shares memory with :attr:`stable`.
        """
        if not 0 < size <= self.n:
            raise ValueError(f"size={size}: must be in 1..n={self.n}")
        i0 %= self.n
        j0 %= self.n
        return self._tiled[i0 : i0 + size, j0 : j0 + size]

    def extended(self) -> NDArray[np.bool_]:
        """The extended grasp map over [0°, 720°)² (thesis fig. 3.3), a read-only view."""
        return self._tiled

    def fraction_stable(self) -> float:
        """Fraction of the map's cells that are stable."""
        return float(self.stable.mean())


def _make(stable: NDArray[np.bool_], phi: NDArray[np.float64], mu: float, name: str,
          usable: NDArray[np.bool_]) -> GraspMap:
    tiled = np.tile(stable, (2, 2))
    tiled.flags.writeable = False
    n = len(phi)
    view = tiled[:n, :n]
    usable = usable.copy()
    usable.flags.writeable = False
    phi = phi.copy()
    phi.flags.writeable = False
    return GraspMap(view, phi, mu, name, usable, tiled)


def _usable(shape: Shape, phi: NDArray[np.float64], max_radius: float | None,
            vertex_clearance_deg: float = 0.0) -> NDArray[np.bool_]:
    usable = ~shape.is_vertex(phi)
    if vertex_clearance_deg:
        if not (math.isfinite(vertex_clearance_deg) and 0 < vertex_clearance_deg < 90):
            raise ValueError(f"vertex_clearance_deg={vertex_clearance_deg!r}: must be in "
                             "[0, 90) degrees")
        va = getattr(shape, "vertex_angles_deg", None)
        if va is not None:
            d = np.abs(np.mod(phi[:, None] - va[None, :] + 180.0, 360.0) - 180.0)
            usable &= d.min(axis=1) > vertex_clearance_deg
    if max_radius is not None:
        if not (math.isfinite(max_radius) and max_radius > 0):
            raise ValueError(f"max_radius={max_radius!r}: must be a finite length > 0 (m)")
        usable &= shape.radius(phi) <= max_radius
    return usable


def _nguyen(P: NDArray[np.float64], N: NDArray[np.float64], mu: float,
            contact_model: ContactModel) -> NDArray[np.bool_]:
    """Force closure of every pair of contacts at points ``P`` with inward normals ``N``."""
    # thesis 3.2 via Nguyen: d_ij = p_j - p_i must lie inside both friction cones,
    # d_ij . n_i > cos(atan mu) |d_ij| and -d_ij . n_j > cos(atan mu) |d_ij|.
    # With M = N P^T (M_ij = n_i . p_j) and h_i = n_i . p_i, d_ij . n_i = M_ij - h_i
    # and -d_ij . n_j = M_ji - h_j; |d_ij|^2 comes from the Gram matrix. Two small
    # matrix products instead of an (n, n, 2) tensor: no division, no arccos.
    cos_a = math.cos(math.atan(mu))
    M = N @ P.T
    h = np.diagonal(M)
    G = P @ P.T
    sq = np.diagonal(G)
    lim = np.sqrt(np.maximum(sq[:, None] + sq[None, :] - 2.0 * G, 0.0))
    if not contact_model.is_point:
        # the hand's contacts (graspgait_env.contact_model): each cone narrowed by the
        # margin that carries the rotation's load, atan(tau / (G d)) for chord d
        half = math.atan(mu) - np.radians(contact_model.margin_deg(lim))
        with np.errstate(invalid="ignore"):  # no cone left: never stable
            lim = np.where(half > 0, np.cos(np.clip(half, 0.0, None)), np.inf) * lim
    else:
        lim *= cos_a
    A = M - h[:, None]
    # squeezing (both dot products positive) or pushing apart in a notch (both negative)
    return ((A > lim) & (A.T > lim)) | ((A < -lim) & (A.T < -lim))


def grasp_map(
    shape: Shape,
    mu: float,
    n: int = 180,
    *,
    max_radius: float | None = None,
    method: str = "nguyen",
    vertex_clearance_deg: float = 0.0,
    contact_model: ContactModel = POINT_CONTACTS,
) -> GraspMap:
    """Compute the grasp map of ``shape`` at friction ``mu`` on an ``n``-point grid.

    Parameters
    ----------
    shape
        A star-shaped object (see :mod:`graspgait_env.shapes`); a name or YAML path is
        loaded with :func:`graspgait_env.load_object`.
    mu
        Coulomb friction coefficient (> 0).
    n
        Contacts on the contour, ``phi_k = 360 k / n`` degrees (default 180: 2°).
    max_radius
        Reach limit (m, thesis 4.2, fig. 4.3): contacts whose radius exceeds it are
        unusable and never part of a stable grasp. ``None``: no limit.
    method
        ``"nguyen"`` (geometric, default, fastest) or ``"wrench"`` (thesis 3.2).
    vertex_clearance_deg
        Contacts within this polar angle (degrees) of a polygon vertex are unusable
        (default 0: only contacts exactly on a vertex). A physical ball tip rolls along
        the contour as the object turns and can roll off a corner the point-contact model
        of the thesis never sees; a clearance keeps planned grasps away from corners.
    contact_model
        What the fingertips are (:mod:`graspgait_env.contact_model`): the default
        :data:`~graspgait_env.contact_model.POINT_CONTACTS` is the thesis's model, bit
        for bit. A ball-tip model keeps each chord ``margin_deg(chord)`` inside both
        cones (the load of a rotation), wherever the balls roll to while the object
        turns the gait's way by up to its ``max_rotation_deg`` (checked at the half and
        the whole), and leaves out contacts nearer a vertex than its
        ``vertex_clearance_m``; ``method="nguyen"`` only.

    Returns
    -------
    GraspMap
        ``.stable`` is the ``(n, n)`` boolean map; ``.phi_deg`` its angles.

    Examples
    --------
    >>> from graspgait_env.shapes import Circle
    >>> gm = grasp_map(Circle(0.05), mu=0.3, n=12)
    >>> bool(gm.stable[0, 6]), bool(gm.stable[0, 5]), bool(gm.stable[0, 4])
    (True, True, False)

    Contacts 150° apart see the chord 15° off each normal, inside the 16.7° cone of
    mu = 0.3; 120° apart, 30° off: outside. The diagonal is never stable:

    >>> bool(gm.stable[3, 3])
    False
    """
    if not isinstance(shape, Shape):
        from graspgait_env.objects import load_object

        shape = load_object(shape)
    mu = check_mu(mu)
    phi = grid_angles_deg(n)
    P = shape.contour_point(phi)
    N = shape.inward_normal(phi)
    if method == "nguyen":
        stable = _nguyen(P, N, mu, contact_model)
        if not contact_model.is_point and contact_model.max_rotation_deg != 0:
            # the balls roll while the object turns the gait's way (contact_model): the
            # grasp must hold wherever its contacts roll to in up to the largest rotation
            rho, top = contact_model.tip_radius_m, contact_model.max_rotation_deg
            for turn in (top / 2, top):
                phr = rolling_contacts_deg(shape, phi, turn, rho)
                stable &= _nguyen(shape.contour_point(phr), shape.inward_normal(phr), mu,
                                  contact_model)
    elif method == "wrench":
        if not contact_model.is_point:
            raise ValueError(f"method='wrench': draws point-contact maps only; use "
                             f"method='nguyen' for contact_model={contact_model.name!r}")
        I, J = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        stable = force_closure_wrench(P[I], N[I], P[J], N[J], mu)
    else:
        raise ValueError(f"method={method!r}: use 'nguyen' or 'wrench'")
    usable = _usable(shape, phi, max_radius, vertex_clearance_deg)
    if contact_model.vertex_clearance_m > 0:
        va = getattr(shape, "vertex_angles_deg", None)
        if va is not None:  # a rolling ball must not reach a corner (contact_model)
            dv = np.linalg.norm(P[:, None, :] - shape.contour_point(va)[None], axis=2)
            usable &= dv.min(axis=1) >= contact_model.vertex_clearance_m
    stable &= usable[:, None] & usable[None, :]
    np.fill_diagonal(stable, False)
    return _make(stable, phi, mu, shape.name, usable)


def grasp_map_loop(shape: Shape, mu: float, n: int = 180) -> GraspMap:
    """Reference implementation: one Python-level force-closure test per pair.

    Kept as the yardstick for ``graspgait perf`` (the vectorized map must be >= 10×
    faster) and as an independent check in the tests. Same result as :func:`grasp_map`.
    """
    mu = check_mu(mu)
    phi = grid_angles_deg(n)
    P = shape.contour_point(phi).tolist()
    N = shape.inward_normal(phi).tolist()
    usable = _usable(shape, phi, None)
    cos_a = math.cos(math.atan(mu))
    stable = np.zeros((n, n), dtype=bool)
    for i in range(n):
        if not usable[i]:
            continue
        (xi, yi), (nxi, nyi) = P[i], N[i]
        for j in range(n):
            if j == i or not usable[j]:
                continue
            dx, dy = P[j][0] - xi, P[j][1] - yi
            lim = cos_a * math.hypot(dx, dy)
            c1 = dx * nxi + dy * nyi
            c2 = -(dx * N[j][0] + dy * N[j][1])
            stable[i, j] = (c1 > lim and c2 > lim) or (c1 < -lim and c2 < -lim)
    return _make(stable, phi, mu, shape.name, usable)
