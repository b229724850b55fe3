"""Shapes (thesis 2.4, 3.3, 3.4) against hand-computed contour points, normals and radii."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.shapes import Circle, Ellipse, Polygon, Stadium

SQ = [[0.05, 0.05], [-0.05, 0.05], [-0.05, -0.05], [0.05, -0.05]]  # CCW, side 0.1 m
# a non-convex four-pointed star: tips at 0.1 m on the axes, notches at (±0.03, ±0.03)
STAR = [[0.1, 0.0], [0.03, 0.03], [0.0, 0.1], [-0.03, 0.03],
        [-0.1, 0.0], [-0.03, -0.03], [0.0, -0.1], [0.03, -0.03]]
T = math.tan
D = math.radians


def _ray_hits_segment(phi_deg, a, b):
    """Distance along the ray at phi_deg to the line through a, b (Cramer's rule)."""
    u = np.array([math.cos(D(phi_deg)), math.sin(D(phi_deg))])
    a, b = np.asarray(a), np.asarray(b)
    e = b - a
    # r u = a + t e  ->  [u, -e] [r, t]^T = a
    det = u[0] * -e[1] - u[1] * -e[0]
    r = (a[0] * -e[1] - a[1] * -e[0]) / det
    return r


# --------------------------------------------------------------------------- square


def test_square_contour_points_by_hand():
    sq = Polygon(SQ)
    phi = np.array([0.0, 30.0, 120.0, 200.0, 300.0])
    expected = np.array([
        [0.05, 0.0],
        [0.05, 0.05 * T(D(30))],           # right face x = 0.05
        [0.05 / T(D(120)), 0.05],          # top face y = 0.05: x = 0.05 cot(120°) < 0
        [-0.05, -0.05 * T(D(200))],        # left face x = -0.05: y = x tan(200°)
        [-0.05 / T(D(300)), -0.05],        # bottom face y = -0.05
    ])
    np.testing.assert_allclose(sq.contour_point(phi), expected, rtol=0, atol=1e-15)
    np.testing.assert_allclose(sq.radius(phi),
                               [0.05, 0.05 / math.cos(D(30)), 0.05 / math.sin(D(120)),
                                0.05 / abs(math.cos(D(200))), 0.05 / abs(math.sin(D(300)))],
                               rtol=1e-14)


def test_square_inward_normals_by_hand():
    sq = Polygon(SQ)
    got = sq.inward_normal([10.0, 100.0, 190.0, 280.0, -10.0])
    np.testing.assert_allclose(got, [[-1, 0], [0, -1], [1, 0], [0, 1], [-1, 0]], atol=1e-15)


def test_square_vertices_detected_exactly_and_not_half_a_degree_away():
    sq = Polygon(SQ)
    vert = np.array([45.0, 135.0, 225.0, 315.0, -45.0, 405.0])
    assert sq.is_vertex(vert).all()
    assert not sq.is_vertex(vert + 0.5).any()
    assert not sq.is_vertex(vert - 0.5).any()
    np.testing.assert_allclose(sq.radius(vert), 0.05 * math.sqrt(2), rtol=1e-14)
    np.testing.assert_allclose(np.sort(np.mod(sq.vertex_angles_deg, 360)), [45, 135, 225, 315])


def test_square_eccentricity_smoothness_radii():
    sq = Polygon(SQ)
    np.testing.assert_allclose(sq.r_min, 0.05, rtol=1e-14)
    np.testing.assert_allclose(sq.r_max, 0.05 * math.sqrt(2), rtol=1e-14)
    np.testing.assert_allclose(sq.eccentricity, math.sqrt(2), rtol=1e-14)
    assert sq.smoothness == 4


# --------------------------------------------------------------------------- smooth shapes


def test_circle_points_normals_and_measures():
    c = Circle(0.05)
    phi = np.array([0.0, 37.0, 90.0, 211.0])
    u = np.stack([np.cos(np.radians(phi)), np.sin(np.radians(phi))], -1)
    np.testing.assert_allclose(c.contour_point(phi), 0.05 * u, atol=1e-15)
    np.testing.assert_allclose(c.inward_normal(phi), -u, atol=1e-15)
    np.testing.assert_allclose(c.radius(phi), 0.05, rtol=1e-15)
    assert c.eccentricity == 1.0
    assert math.isinf(c.smoothness)
    assert not c.is_vertex(phi).any()


def test_ellipse_points_normals_by_hand():
    a, b = 0.09, 0.06
    e = Ellipse(a, b)
    # axes
    np.testing.assert_allclose(e.contour_point([0, 90, 180, 270]),
                               [[a, 0], [0, b], [-a, 0], [0, -b]], atol=1e-15)
    np.testing.assert_allclose(e.inward_normal([0, 90, 180, 270]),
                               [[-1, 0], [0, -1], [1, 0], [0, 1]], atol=1e-15)
    # 45°: x = y and x²/a² + y²/b² = 1  ->  x = a b / sqrt(a² + b²)
    x45 = a * b / math.sqrt(a * a + b * b)
    np.testing.assert_allclose(e.contour_point(45.0), [x45, x45], rtol=1e-14)
    np.testing.assert_allclose(e.radius(45.0), x45 * math.sqrt(2), rtol=1e-14)
    # normal along -(x/a², y/b²) = -(1/a², 1/b²) at 45°
    g = np.array([1 / a**2, 1 / b**2])
    np.testing.assert_allclose(e.inward_normal(45.0), -g / np.linalg.norm(g), rtol=1e-14)
    # 30°: r = 1 / sqrt(cos²/a² + sin²/b²)
    c30, s30 = math.cos(D(30)), math.sin(D(30))
    r30 = 1.0 / math.sqrt(c30**2 / a**2 + s30**2 / b**2)
    np.testing.assert_allclose(e.radius(30.0), r30, rtol=1e-14)
    assert e.r_min == b and e.r_max == a
    np.testing.assert_allclose(e.eccentricity, 1.5, rtol=1e-15)
    assert math.isinf(e.smoothness)


def test_stadium_flat_part_by_hand():
    L, R = 0.05, 0.04
    s = Stadium(L, R)
    np.testing.assert_allclose(s.contour_point([90.0, 60.0, 270.0, 250.0]),
                               [[0, R], [R / T(D(60)), R], [0, -R], [-R / T(D(250)), -R]],
                               atol=1e-15)
    np.testing.assert_allclose(s.radius(60.0), R / math.sin(D(60)), rtol=1e-14)
    np.testing.assert_allclose(s.inward_normal([90.0, 60.0, 120.0, 250.0, 290.0]),
                               [[0, -1], [0, -1], [0, -1], [0, 1], [0, 1]], atol=1e-15)
    assert not s.is_vertex([0.0, 38.66, 90.0]).any()


def test_stadium_caps_by_hand():
    L, R = 0.05, 0.04
    s = Stadium(L, R)
    np.testing.assert_allclose(s.contour_point([0.0, 180.0]), [[L + R, 0], [-(L + R), 0]],
                               atol=1e-15)
    np.testing.assert_allclose(s.inward_normal([0.0, 180.0]), [[-1, 0], [1, 0]], atol=1e-15)
    # 20° hits the right cap (flat/cap junction at atan(R/L) = 38.66°):
    # |r u - (L, 0)| = R  ->  r = L cos φ + sqrt(R² - L² sin² φ)
    r20 = L * math.cos(D(20)) + math.sqrt(R * R - (L * math.sin(D(20))) ** 2)
    p20 = r20 * np.array([math.cos(D(20)), math.sin(D(20))])
    np.testing.assert_allclose(s.radius(20.0), r20, rtol=1e-14)
    np.testing.assert_allclose(s.contour_point(20.0), p20, rtol=1e-14)
    np.testing.assert_allclose(s.inward_normal(20.0), -(p20 - [L, 0]) / R, rtol=1e-13)
    # 200° by symmetry on the left cap, centred at (-L, 0)
    p200 = r20 * np.array([math.cos(D(200)), math.sin(D(200))])
    np.testing.assert_allclose(s.contour_point(200.0), p200, rtol=1e-14)
    np.testing.assert_allclose(s.inward_normal(200.0), -(p200 - [-L, 0]) / R, rtol=1e-13)
    # measures
    assert s.r_min == R
    np.testing.assert_allclose(s.r_max, L + R)
    np.testing.assert_allclose(s.eccentricity, (L + R) / R)
    assert math.isinf(s.smoothness)


def test_stadium_is_continuous_at_flat_cap_junction():
    L, R = 0.05, 0.04
    s = Stadium(L, R)
    j = math.degrees(math.atan2(R, L))
    np.testing.assert_allclose(s.contour_point(j - 1e-7), s.contour_point(j + 1e-7), atol=1e-10)
    np.testing.assert_allclose(s.contour_point(j), [L, R], atol=1e-15)
    np.testing.assert_allclose(s.inward_normal(j + 1e-7), [0, -1], atol=1e-6)
    np.testing.assert_allclose(s.inward_normal(j - 1e-7), [0, -1], atol=1e-6)


# --------------------------------------------------------------------------- non-convex star


def test_star_points_normals_by_hand():
    st = Polygon(STAR)
    # 20° lies on the edge from the tip (0.1, 0) to the notch (0.03, 0.03)
    r20 = _ray_hits_segment(20.0, STAR[0], STAR[1])
    np.testing.assert_allclose(st.radius(20.0), r20, rtol=1e-13)
    np.testing.assert_allclose(st.contour_point(20.0),
                               r20 * np.array([math.cos(D(20)), math.sin(D(20))]), rtol=1e-13)
    # edge direction (-0.07, 0.03); outward normal (0.03, 0.07)/|.|, inward its negative
    nin = -np.array([0.03, 0.07]) / math.hypot(0.03, 0.07)
    np.testing.assert_allclose(st.inward_normal(20.0), nin, rtol=1e-13)
    # 70° lies on the edge from the notch (0.03, 0.03) to the tip (0, 0.1)
    r70 = _ray_hits_segment(70.0, STAR[1], STAR[2])
    np.testing.assert_allclose(st.radius(70.0), r70, rtol=1e-13)
    nin70 = -np.array([0.07, 0.03]) / math.hypot(0.07, 0.03)
    np.testing.assert_allclose(st.inward_normal(70.0), nin70, rtol=1e-13)
    # vertices: tips at 0, 90, 180, 270 deg (r = 0.1), notches at 45 + 90k (r = 0.03 √2)
    np.testing.assert_allclose(st.radius([0.0, 90.0, 45.0, 225.0]),
                               [0.1, 0.1, 0.03 * math.sqrt(2), 0.03 * math.sqrt(2)], rtol=1e-13)


def test_star_vertices_measures():
    st = Polygon(STAR)
    vert = 45.0 * np.arange(8)
    assert st.is_vertex(vert).all()
    assert not st.is_vertex(vert + 0.5).any()
    assert not st.is_vertex(vert - 0.5).any()
    assert st.smoothness == 8
    # r_min: the foot of the perpendicular from the origin to the line of each edge lies
    # beyond the segment (t = 0.007 / 0.0058 > 1), so the nearest contour point is the
    # notch vertex, 0.03 √2 (not the line distance 0.003 / |(-0.07, 0.03)| = 0.0394).
    np.testing.assert_allclose(st.r_min, 0.03 * math.sqrt(2), rtol=1e-14)
    np.testing.assert_allclose(st.r_max, 0.1, rtol=1e-14)
    np.testing.assert_allclose(st.eccentricity, 0.1 / (0.03 * math.sqrt(2)), rtol=1e-14)


# --------------------------------------------------------------------------- general properties

SHAPES = {
    "square": lambda: Polygon(SQ),
    "star": lambda: Polygon(STAR),
    "circle": lambda: Circle(0.05),
    "ellipse": lambda: Ellipse(0.09, 0.06),
    "stadium": lambda: Stadium(0.05, 0.04),
}
# 0.7° spacing: never on a vertex of SQ or STAR (multiples of 45°)
PHI = np.arange(0.35, 360.0, 0.7)


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_normals_unit_inward_and_perpendicular_to_contour(name):
    s = SHAPES[name]()
    p = s.contour_point(PHI)
    n = s.inward_normal(PHI)
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, rtol=1e-14)
    # star-shaped about the origin: the inward normal points back towards the origin side
    assert np.all(np.einsum("ij,ij->i", n, p) < 0)
    # the tangent (central finite difference) is perpendicular to the normal
    h = 1e-6
    tangent = s.contour_point(PHI + h) - s.contour_point(PHI - h)
    tangent /= np.linalg.norm(tangent, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.einsum("ij,ij->i", tangent, n), 0.0, atol=1e-6)
    # radius and contour_point agree
    np.testing.assert_allclose(np.linalg.norm(p, axis=-1), s.radius(PHI), rtol=1e-14)
    # the contour point lies on the ray at phi
    np.testing.assert_allclose(np.degrees(np.arctan2(p[:, 1], p[:, 0])) % 360, PHI % 360,
                               atol=1e-9)


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_vectorized_shapes(name):
    s = SHAPES[name]()
    grid = PHI[:12].reshape(3, 4)
    assert s.radius(grid).shape == (3, 4)
    assert s.contour_point(grid).shape == (3, 4, 2)
    assert s.inward_normal(grid).shape == (3, 4, 2)
    assert s.is_vertex(grid).shape == (3, 4)
    np.testing.assert_array_equal(s.contour_point(grid)[1, 2], s.contour_point(grid[1, 2]))
    assert s.radius(17.0).shape == ()
    assert s.contour_point(17.0).shape == (2,)


@pytest.mark.parametrize("verts", [SQ, STAR], ids=["square", "star"])
def test_both_windings_identical(verts):
    ccw = Polygon(verts)
    cw = Polygon(verts[::-1])
    np.testing.assert_array_equal(cw.radius(PHI), ccw.radius(PHI))
    np.testing.assert_array_equal(cw.contour_point(PHI), ccw.contour_point(PHI))
    np.testing.assert_array_equal(cw.inward_normal(PHI), ccw.inward_normal(PHI))
    all_phi = np.concatenate([PHI, 45.0 * np.arange(8)])
    np.testing.assert_array_equal(cw.is_vertex(all_phi), ccw.is_vertex(all_phi))
    assert (cw.r_min, cw.r_max, cw.smoothness) == (ccw.r_min, ccw.r_max, ccw.smoothness)
    # stored counter-clockwise: positive signed area
    v = cw.vertices
    assert np.sum(v[:, 0] * np.roll(v[:, 1], -1) - v[:, 1] * np.roll(v[:, 0], -1)) > 0


def test_closing_vertex_repeated_is_dropped():
    closed = Polygon([*SQ, SQ[0]])
    assert closed.smoothness == 4
    np.testing.assert_array_equal(closed.radius(PHI), Polygon(SQ).radius(PHI))


# --------------------------------------------------------------------------- degenerate input

BAD_POLYGONS = {
    "two vertices": [[0.1, 0.0], [0.0, 0.1]],
    "two distinct": [[0.1, 0.0], [0.0, 0.1], [0.1, 0.0]],
    "all the same": [[0.1, 0.1]] * 4,
    "collinear": [[0.1, 0.0], [0.2, 0.0], [0.3, 0.0]],
    "collinear through origin": [[-0.1, 0.0], [0.1, 0.0], [0.2, 0.0]],
    "nan": [[0.1, 0.0], [0.0, float("nan")], [-0.1, -0.1]],
    "inf": [[0.1, 0.0], [0.0, float("inf")], [-0.1, -0.1]],
    "vertex on origin": [[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]],
    "origin on an edge": [[0.1, 0.0], [-0.1, 0.0], [0.0, -0.1]],
    "origin outside": [[0.1, 0.1], [0.2, 0.1], [0.2, 0.2], [0.1, 0.2]],
    "pentagram": [[math.cos(D(90 + 144 * k)) * 0.1, math.sin(D(90 + 144 * k)) * 0.1]
                  for k in range(5)],
    "origin not in kernel (notch)": [[0.1, -0.1], [0.1, 0.1], [-0.1, 0.1], [-0.1, 0.05],
                                     [0.05, 0.05], [0.05, 0.02], [-0.1, 0.02], [-0.1, -0.1]],
    "three coordinates": [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [-0.1, -0.1, 0.0]],
    "flat list": [0.1, 0.0, 0.0, 0.1, -0.1, -0.1],
}


@pytest.mark.parametrize("name", sorted(BAD_POLYGONS))
def test_degenerate_polygons_refused(name):
    with pytest.raises(ValueError, match="vertices"):
        Polygon(BAD_POLYGONS[name])


@pytest.mark.parametrize(
    "make",
    [
        lambda: Circle(0.0),
        lambda: Circle(-0.05),
        lambda: Circle(float("nan")),
        lambda: Circle(float("inf")),
        lambda: Ellipse(0.09, 0.0),
        lambda: Ellipse(-0.09, 0.06),
        lambda: Ellipse(0.09, float("nan")),
        lambda: Stadium(0.0, 0.04),
        lambda: Stadium(0.05, -0.04),
        lambda: Stadium(float("inf"), 0.04),
    ],
    ids=["circle0", "circle-", "circle-nan", "circle-inf", "ellipse-b0", "ellipse-a-",
         "ellipse-nan", "stadium-L0", "stadium-R-", "stadium-inf"],
)
def test_degenerate_smooth_shapes_refused(make):
    with pytest.raises(ValueError):
        make()


def _bundled_polygons():
    from graspgait_env.objects import bundled_objects, load_object

    return [n for n in bundled_objects() if isinstance(load_object(n), Polygon)]


@pytest.mark.parametrize("name", ["square-literal", "star-literal", *_bundled_polygons()])
def test_normal_on_vertex_is_that_of_the_ccw_edge(name):
    """Module docstring: on a vertex, ``inward_normal`` returns the normal of the edge
    counter-clockwise of the vertex. Checked at every vertex, at the angle the polygon
    itself reports (``vertex_angles_deg``), against the normal 0.5° counter-clockwise."""
    from graspgait_env.objects import load_object

    poly = {"square-literal": lambda: Polygon(SQ),
            "star-literal": lambda: Polygon(STAR)}.get(name, lambda: load_object(name))()
    va = poly.vertex_angles_deg
    assert poly.is_vertex(va).all()
    np.testing.assert_allclose(poly.inward_normal(va), poly.inward_normal(va + 0.5),
                               atol=1e-12)


def test_docstring_examples():
    """The module's examples run as written."""
    import doctest
    import importlib

    mod = importlib.import_module("graspgait_env.shapes")

    res = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert res.failed == 0
