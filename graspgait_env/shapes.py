"""Star-shaped planar objects (thesis 2.4, 3.2–3.4).

Every shape lives in the object frame ``f``: its origin is the object's centre of
rotation and the point about which the shape is star-shaped, so that the ray from the
origin at polar angle ``phi`` meets the contour exactly once (thesis 2.4). A contact is
named by that angle.

Conventions
-----------
- Lengths in metres, public angles in degrees (``phi_deg``), counter-clockwise positive.
- Every query is vectorized: ``phi_deg`` may be a scalar or any array; results have
  the same leading shape (points and normals add a trailing axis of 2).
- ``inward_normal`` is the unit normal pointing into the object. On a polygon vertex
  the normal is undefined: ``is_vertex`` is True there and the normal returned is the
  one of the edge counter-clockwise of the vertex (callers that care must mask vertices,
  as :func:`graspgait_env.grasp_map` does).

Examples
--------
>>> import numpy as np
>>> sq = Polygon([[0.05, 0.05], [-0.05, 0.05], [-0.05, -0.05], [0.05, -0.05]])
>>> np.round(sq.contour_point(0.0), 3).tolist()
[0.05, 0.0]
>>> bool(sq.is_vertex(45.0)), bool(sq.is_vertex(44.0))
(True, False)
>>> bool(np.isclose(sq.eccentricity, np.sqrt(2))), int(sq.smoothness)
(True, 4)
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Shape", "Polygon", "Ellipse", "Circle", "Stadium", "VERTEX_TOL_DEG"]

VERTEX_TOL_DEG = 1e-6  # (degrees) a contact this close to a vertex's polar angle is on it


def _as_rad(phi_deg: ArrayLike) -> NDArray[np.float64]:
    return np.deg2rad(np.asarray(phi_deg, dtype=np.float64))


def _unit(phi: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.stack([np.cos(phi), np.sin(phi)], axis=-1)


class Shape(ABC):
    """A star-shaped planar contour about the origin of the object frame ``f``.

    Subclasses give the radial function and the outward normal; everything else
    (contour points, inward normals, eccentricity) follows from them.
    """

    name: str = "shape"

    @abstractmethod
    def radius(self, phi_deg: ArrayLike) -> NDArray[np.float64]:
        """Distance (m) from the origin to the contour along the ray at ``phi_deg``."""

    @abstractmethod
    def _outward_normal_rad(self, phi: NDArray[np.float64]) -> NDArray[np.float64]:
        """Outward unit normal at polar angle ``phi`` (radians), shape ``phi.shape + (2,)``."""

    @property
    @abstractmethod
    def r_min(self) -> float:
        """Smallest radius of the contour (m)."""

    @property
    @abstractmethod
    def r_max(self) -> float:
        """Largest radius of the contour (m)."""

    @property
    @abstractmethod
    def smoothness(self) -> float:
        """Smoothness S (thesis 3.4): number of sides; ``math.inf`` for a smooth contour."""

    def is_vertex(self, phi_deg: ArrayLike) -> NDArray[np.bool_]:
        """True where ``phi_deg`` names a vertex (no defined normal). Smooth shapes: never."""
        return np.zeros(np.shape(phi_deg), dtype=bool)

    def contour_point(self, phi_deg: ArrayLike) -> NDArray[np.float64]:
        """Contour point (m, frame ``f``) at polar angle ``phi_deg``; trailing axis (x, y)."""
        phi = _as_rad(phi_deg)
        return self.radius(phi_deg)[..., None] * _unit(phi)

    def inward_normal(self, phi_deg: ArrayLike) -> NDArray[np.float64]:
        """Inward unit normal (frame ``f``) at polar angle ``phi_deg``; trailing axis (x, y)."""
        return -self._outward_normal_rad(_as_rad(phi_deg))

    @property
    def eccentricity(self) -> float:
        """Eccentricity E = r_max / r_min (thesis 3.3); 1 for a circle."""
        return self.r_max / self.r_min

    def describe(self) -> str:
        """One line with the shape's size, eccentricity and smoothness."""
        s = "inf" if math.isinf(self.smoothness) else str(int(self.smoothness))
        return (
            f"{self.name}: {type(self).__name__}, r_min={self.r_min:.4f} m, "
            f"r_max={self.r_max:.4f} m, E={self.eccentricity:.3f}, S={s}"
        )


class Ellipse(Shape):
    """Ellipse centred on the origin with semi-axes ``a`` (along x) and ``b`` (along y), m.

    Radial function ``r = a b / sqrt((b cos phi)^2 + (a sin phi)^2)``; the outward
    normal at (x, y) is along ``(x / a^2, y / b^2)``. E = max(a, b) / min(a, b).
    """

    def __init__(self, a: float, b: float, name: str = "ellipse") -> None:
        for field, v in (("a", a), ("b", b)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"Ellipse {field}={v!r}: must be a finite length > 0 (metres)")
        self.a = float(a)
        self.b = float(b)
        self.name = name

    def radius(self, phi_deg: ArrayLike) -> NDArray[np.float64]:
        phi = _as_rad(phi_deg)
        return self.a * self.b / np.hypot(self.b * np.cos(phi), self.a * np.sin(phi))

    def _outward_normal_rad(self, phi: NDArray[np.float64]) -> NDArray[np.float64]:
        # gradient of x^2/a^2 + y^2/b^2 at the contour point, up to a positive factor
        g = np.stack([np.cos(phi) / self.a**2, np.sin(phi) / self.b**2], axis=-1)
        return g / np.linalg.norm(g, axis=-1, keepdims=True)

    @property
    def r_min(self) -> float:
        return min(self.a, self.b)

    @property
    def r_max(self) -> float:
        return max(self.a, self.b)

    @property
    def smoothness(self) -> float:
        return math.inf

    def __repr__(self) -> str:
        return f"Ellipse(a={self.a}, b={self.b}, name={self.name!r})"


class Circle(Ellipse):
    """Circle of ``radius`` (m) centred on the origin: E = 1, S = inf."""

    def __init__(self, radius: float, name: str = "circle") -> None:
        if not (isinstance(radius, (int, float)) and math.isfinite(radius) and radius > 0):
            raise ValueError(f"Circle radius={radius!r}: must be a finite length > 0 (metres)")
        super().__init__(radius, radius, name=name)

    @property
    def radius_m(self) -> float:
        """The circle's radius (m)."""
        return self.a

    def __repr__(self) -> str:
        return f"Circle(radius={self.a}, name={self.name!r})"


class Stadium(Shape):
    """Stadium: flat sides joined by round ends (a hybrid shape, thesis 3.4).

    The set of points within ``radius`` of the segment from ``(-half_length, 0)`` to
    ``(half_length, 0)``. Its contour has no slope discontinuity, so S = inf (the
    thesis defines smoothness of hybrid shapes per section; the curvature jumps where
    the flats meet the arcs, but the normal is continuous and no contact is a vertex).
    E = (half_length + radius) / radius.
    """

    def __init__(self, half_length: float, radius: float, name: str = "stadium") -> None:
        if not (isinstance(radius, (int, float)) and math.isfinite(radius) and radius > 0):
            raise ValueError(f"Stadium radius={radius!r}: must be a finite length > 0 (metres)")
        if not (
            isinstance(half_length, (int, float))
            and math.isfinite(half_length)
            and half_length > 0
        ):
            raise ValueError(
                f"Stadium half_length={half_length!r}: must be a finite length > 0 (metres)"
            )
        self.half_length = float(half_length)
        self.rad = float(radius)
        self.name = name

    def _geometry(self, phi: NDArray[np.float64]):
        u = _unit(phi)
        c, s = u[..., 0], u[..., 1]
        L, R = self.half_length, self.rad
        with np.errstate(divide="ignore"):
            r_flat = R / np.abs(s)
        on_flat = np.abs(r_flat * c) <= L
        cx = np.where(c >= 0, L, -L)
        uc = c * cx
        r_cap = uc + np.sqrt(np.maximum(uc**2 - L**2 + R**2, 0.0))
        r = np.where(on_flat, r_flat, r_cap)
        return u, r, on_flat, cx

    def radius(self, phi_deg: ArrayLike) -> NDArray[np.float64]:
        return self._geometry(_as_rad(phi_deg))[1]

    def _outward_normal_rad(self, phi: NDArray[np.float64]) -> NDArray[np.float64]:
        u, r, on_flat, cx = self._geometry(phi)
        p = r[..., None] * u
        flat_n = np.stack([np.zeros_like(r), np.sign(p[..., 1])], axis=-1)
        cap = p - np.stack([cx, np.zeros_like(cx)], axis=-1)
        cap_n = cap / np.linalg.norm(cap, axis=-1, keepdims=True)
        return np.where(on_flat[..., None], flat_n, cap_n)

    @property
    def r_min(self) -> float:
        return self.rad

    @property
    def r_max(self) -> float:
        return self.half_length + self.rad

    @property
    def smoothness(self) -> float:
        return math.inf

    def __repr__(self) -> str:
        return f"Stadium(half_length={self.half_length}, radius={self.rad}, name={self.name!r})"


class Polygon(Shape):
    """Polygon star-shaped about the origin; vertices (m, frame ``f``) in either winding.

    Validation (each refusal names the problem and the fix): at least 3 distinct
    vertices, finite coordinates, no vertex on the origin, and every ray from the
    origin meets the contour exactly once, i.e. the vertices, taken in order, turn
    monotonically about the origin through exactly one full turn. That test also
    refuses self-intersecting polygons (they turn through two or more turns or turn
    back) and zero-area ones.

    Parameters
    ----------
    vertices
        ``(m, 2)`` array-like of vertex coordinates, clockwise or counter-clockwise;
        stored counter-clockwise.
    name
        Object name.
    """

    def __init__(self, vertices: ArrayLike | Sequence[Sequence[float]], name: str = "polygon"):
        v = np.asarray(vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2:
            raise ValueError(
                f"Polygon vertices: expected a list of [x, y] pairs, got shape {v.shape}"
            )
        if not np.all(np.isfinite(v)):
            raise ValueError("Polygon vertices: contain NaN or inf; give finite metres")
        # drop consecutive duplicates (including last == first)
        keep = np.ones(len(v), dtype=bool)
        for k in range(len(v)):
            if np.allclose(v[k], v[(k + 1) % len(v)], rtol=0, atol=1e-12) and keep.sum() > 1:
                keep[k] = False
        v = v[keep]
        if len(np.unique(np.round(v, 12), axis=0)) < 3:
            raise ValueError(
                f"Polygon vertices: {len(v)} distinct vertices; give at least 3 distinct points"
            )
        if np.any(np.hypot(v[:, 0], v[:, 1]) <= 1e-12):
            raise ValueError(
                "Polygon vertices: a vertex lies on the origin; the origin must be strictly "
                "inside the polygon (the centre of rotation)"
            )
        cross = v[:, 0] * np.roll(v[:, 1], -1) - v[:, 1] * np.roll(v[:, 0], -1)
        area2 = float(np.sum(cross))
        if abs(area2) <= 1e-15 * max(1.0, float(np.max(np.abs(v))) ** 2):
            raise ValueError("Polygon vertices: the polygon has zero area; give a proper outline")
        if area2 < 0:  # clockwise: reverse to counter-clockwise
            v = v[::-1].copy()
            cross = v[:, 0] * np.roll(v[:, 1], -1) - v[:, 1] * np.roll(v[:, 0], -1)
        ang = np.arctan2(v[:, 1], v[:, 0])
        step = np.angle(np.exp(1j * (np.roll(ang, -1) - ang)))  # wrapped to (-pi, pi]
        turns = float(np.sum(step)) / (2 * np.pi)
        if np.any(step <= 0) or np.any(cross <= 0) or abs(turns - 1.0) > 1e-9:
            raise ValueError(
                "Polygon vertices: not star-shaped about the origin (or self-intersecting): "
                "the vertices must go round the origin once, each ray from the origin meeting "
                "the outline exactly once; move the origin (the centre of rotation) inside the "
                "kernel or reorder the vertices"
            )
        self.vertices = v
        self.name = name
        # polar angle of each vertex, unwrapped counter-clockwise from vertex 0
        self._a0 = float(ang[0])
        # built with the same expression the queries use, so that a query exactly at a
        # vertex angle lands on the edge counter-clockwise of it
        self._cum = np.mod(ang - self._a0, 2 * np.pi)
        edges = np.roll(v, -1, axis=0) - v
        out = np.stack([edges[:, 1], -edges[:, 0]], axis=1)
        self._edge_normal = out / np.linalg.norm(out, axis=1, keepdims=True)  # outward
        self._edge_h = np.einsum("ij,ij->i", self._edge_normal, v)  # > 0: origin inside
        self._vertex_deg = np.rad2deg(ang)

    def _edge_index(self, phi: NDArray[np.float64]) -> NDArray[np.intp]:
        rel = np.mod(phi - self._a0, 2 * np.pi)
        return np.searchsorted(self._cum, rel, side="right") - 1

    def radius(self, phi_deg: ArrayLike) -> NDArray[np.float64]:
        phi = _as_rad(phi_deg)
        k = self._edge_index(phi)
        n = self._edge_normal[k]
        return self._edge_h[k] / (n[..., 0] * np.cos(phi) + n[..., 1] * np.sin(phi))

    def _outward_normal_rad(self, phi: NDArray[np.float64]) -> NDArray[np.float64]:
        return self._edge_normal[self._edge_index(phi)]

    def is_vertex(self, phi_deg: ArrayLike) -> NDArray[np.bool_]:
        d = np.asarray(phi_deg, dtype=np.float64)[..., None] - self._vertex_deg
        d = np.abs(np.mod(d + 180.0, 360.0) - 180.0)
        return np.any(d <= VERTEX_TOL_DEG, axis=-1)

    @property
    def vertex_angles_deg(self) -> NDArray[np.float64]:
        """Polar angle (degrees, in (-180, 180]) of each vertex, counter-clockwise order."""
        return self._vertex_deg.copy()

    @property
    def r_min(self) -> float:
        # distance from the origin to each edge segment
        a = self.vertices
        e = np.roll(a, -1, axis=0) - a
        t = np.clip(-np.einsum("ij,ij->i", a, e) / np.einsum("ij,ij->i", e, e), 0.0, 1.0)
        return float(np.min(np.linalg.norm(a + t[:, None] * e, axis=1)))

    @property
    def r_max(self) -> float:
        return float(np.max(np.linalg.norm(self.vertices, axis=1)))

    @property
    def smoothness(self) -> float:
        return float(len(self.vertices))

    def __repr__(self) -> str:
        return f"Polygon({self.vertices.tolist()}, name={self.name!r})"
