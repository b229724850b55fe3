"""Grasp maps (thesis 2.3, 3.2–3.4): the thesis's qualitative findings and the map's contract."""

from __future__ import annotations

import math

import numpy as np
import pytest

from graspgait_env.grasp_map import grasp_map, grasp_map_loop, grid_angles_deg
from graspgait_env.objects import bundled_objects, load_object
from graspgait_env.shapes import Circle, Ellipse, Polygon

N = 180
MUS = (0.1, 0.3, 0.5, 0.7, 0.9)


def _run(stable, i, j, di, dj):
    """Steps k >= 1 for which stable[i + k di, j + k dj] stays True (indices mod n)."""
    n = len(stable)
    k = 0
    while k < n and stable[(i + (k + 1) * di) % n, (j + (k + 1) * dj) % n]:
        k += 1
    return k


# ----------------------------------------------------------------- circle (fig. 3.1-3.3)


def test_circle_band_along_plus_one_diagonal():
    """Circle, mu = 0.3: stable[i, j] depends only on (j - i) mod n; the stable offsets form
    one contiguous band centred on n/2 (antipodal grasps), so the region is continuous along
    the +1 diagonal (fig. 3.3).

    By hand: contacts Δ apart on a circle see the chord at |180° - Δ|/2 off each normal, so
    the grasp is stable iff |Δ - 180°| < 2 atan(mu) = 33.40°, i.e. for the 2° grid offsets
    k = (j - i) mod n in 74..106 (Δ = 148°..212°).
    """
    st = grasp_map(Circle(0.0762), 0.3).stable
    assert np.array_equal(st, np.roll(st, 1, axis=(0, 1)))  # shift both indices by 1
    i, j = np.indices(st.shape)
    k = (j - i) % N
    band = np.zeros(N, dtype=bool)
    band[74:107] = True
    np.testing.assert_array_equal(st, band[k])
    # hand-computed band edges: Δ = 148° is inside, 146° outside
    two_alpha = 2 * math.degrees(math.atan(0.3))
    assert abs(2 * 74 - 180) < two_alpha < abs(2 * 73 - 180)
    # moving along +1 never leaves the region; moving the fingers towards each other does
    assert _run(st, 0, 90, 1, 1) == N
    assert _run(st, 0, 90, 1, -1) == 8


# ----------------------------------------------------------------- ellipse (fig. 3.5-3.8)


@pytest.mark.parametrize("ecc", [3.0, 100.0])
def test_eccentric_ellipse_stable_region_along_minus_one(ecc):
    """Ellipse of eccentricity E (semi-axes E b along x, b along y), mu = 0.3.

    Criterion: start at the grasp across the minor axis (contacts at 90° and 270°, cells
    i = 45, j = 135). Count how many grid steps the grasp stays stable when the fingers move
    towards each other, (i + k, j - k) (the -1 direction), and when both increase in angle,
    (i + k, j + k) (the +1 direction); do the same in the opposite sense (k < 0). The thesis
    (fig. 3.6) says the main region runs along -1: the -1 runs must be longer than the +1
    runs, both ways, and the region is discontinuous (the +1 run ends well before a turn).
    For the circle it is the other way round (test above: +1 run = n, -1 run = 8).
    """
    b = 0.04
    st = grasp_map(Ellipse(ecc * b, b), 0.3).stable
    i, j = 45, 135
    assert st[i, j]
    minus = (_run(st, i, j, 1, -1), _run(st, i, j, -1, 1))
    plus = (_run(st, i, j, 1, 1), _run(st, i, j, -1, -1))
    assert min(minus) > 2 * max(plus), (minus, plus)
    assert max(plus) < N // 4  # discontinuous along +1
    # the same for the bundled long ellipse (E = 3)
    if ecc == 3.0:
        st3 = grasp_map(load_object("long_ellipse"), 0.3).stable
        assert _run(st3, i, j, 1, -1) > 2 * _run(st3, i, j, 1, 1)


def test_eccentricity_transition_plus_to_minus_one():
    """Fig. 3.8: as E grows the predominant direction goes from +1 to -1 (monotonically for
    the minor-axis grasp's -1 run)."""
    runs = []
    for ecc in (1.0, 1.5, 2.0, 3.0, 10.0):
        st = grasp_map(Ellipse(0.04 * ecc, 0.04), 0.3).stable
        runs.append((_run(st, 45, 135, 1, -1), _run(st, 45, 135, 1, 1)))
    minus = [r[0] for r in runs]
    assert minus == sorted(minus)
    assert runs[0][1] == N and runs[-1][1] < runs[-1][0]


# ----------------------------------------------------------------- polygons (fig. 3.10-3.12)


def _regular_polygon(m, r=0.08, start_deg=90.0):
    a = np.radians(start_deg + 360.0 * np.arange(m) / m)
    return Polygon(np.stack([r * np.cos(a), r * np.sin(a)], 1))


def test_regular_pentagon_no_stable_grasp_at_mu_03():
    """Non-adjacent faces of a regular pentagon have normals 144° apart, so the chord
    between them is at least 18° off one normal: force closure needs mu > tan 18° = 0.325."""
    for pent in (load_object("pentagon"), _regular_polygon(5)):
        assert not grasp_map(pent, 0.3).stable.any()
        assert not grasp_map(pent, 0.32).stable.any()
        assert grasp_map(pent, 0.34).stable.any()


@pytest.mark.parametrize("mu", [0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0])
def test_square_always_has_stable_grasps(mu):
    st = grasp_map(load_object("square"), mu).stable
    assert st.any()
    assert st[0, 90] and st[45, 135]  # opposite faces straight across (0°/180°, 90°/270°)


def test_polygon_region_elongates_along_minus_one_locally():
    """Thesis 3.4, fig. 3.12: two fingers on parallel faces of the square stay stable as
    they move towards/away from each other within the faces (the -1 direction)."""
    st = grasp_map(load_object("square"), 0.5).stable
    # 0°/180° on the right/left faces: (i + k, j - k) mirrors across the y axis
    assert _run(st, 0, 90, 1, -1) >= 10 and _run(st, 0, 90, -1, 1) >= 10


# --------------------------------------------------------------------------- map contract


@pytest.mark.parametrize("name", bundled_objects())
def test_shrinks_as_mu_falls_symmetric_diagonal(name):
    shape = load_object(name)
    prev = None
    for mu in sorted(MUS + (0.05, 0.2, 1.5), reverse=True):
        st = grasp_map(shape, mu).stable
        assert st.shape == (N, N) and st.dtype == bool
        np.testing.assert_array_equal(st, st.T)
        assert not np.diagonal(st).any()
        if prev is not None:
            assert not (st & ~prev).any(), (name, mu)  # subset of the larger-mu map
        prev = st


@pytest.mark.parametrize("name", bundled_objects())
def test_vertex_contacts_never_stable(name):
    shape = load_object(name)
    phi = grid_angles_deg(N)
    gm = grasp_map(shape, 0.9)
    vert = shape.is_vertex(phi)
    np.testing.assert_array_equal(gm.usable, ~vert)
    assert not gm.stable[vert].any() and not gm.stable[:, vert].any()


def test_vertex_on_grid_never_stable():
    """A square rotated so that its vertices sit on grid angles 0°, 90°, 180°, 270°: those
    contacts are unusable; without the rule the grasp 0°/180° (vertex to vertex along the
    diagonal, chord 45° off each adjacent face's normal) would be stable at mu = 1.1."""
    d = 0.08
    diamond = Polygon([[d, 0], [0, d], [-d, 0], [0, -d]])
    gm = grasp_map(diamond, 1.1)
    vert_idx = [0, 45, 90, 135]
    assert not gm.usable[vert_idx].any()
    assert gm.usable.sum() == N - 4
    assert not gm.stable[vert_idx].any() and not gm.stable[:, vert_idx].any()
    assert gm.stable[1, 89]  # just off the vertices, across the diagonal: stable at mu = 1.1


def _grid_on_vertices(shape: Polygon) -> tuple[int, np.ndarray]:
    """The coarsest grid n (180, 360 or 720) with a contact within 1e-3° of a vertex of
    ``shape``, and the mask of those contacts; fails when none has one, so a test built
    on it always checks some vertex contact (the square's vertices, at 45° + k 90°, miss
    the 2° grid and sit on the 1° one)."""
    for n in (180, 360, 720):
        phi = grid_angles_deg(n)
        dist = np.abs((phi[:, None] - shape.vertex_angles_deg + 180.0) % 360.0 - 180.0).min(1)
        near = dist < 1e-3
        if near.any():
            return n, near
    raise AssertionError(f"{shape.name}: no grid up to n = 720 has a contact on a vertex")


@pytest.mark.parametrize("name", [n for n in bundled_objects()
                                  if isinstance(load_object(n), Polygon)])
def test_bundled_nominal_vertex_contacts_never_stable(name):
    """The bundled polygons have vertices at nominal angles that are on a grid (the
    pentagon at 18°, 90°, 162°, ... on the 2° grid; the square at 45°, 135°, ... on the
    1° grid). Their YAML coordinates carry 6 decimals, which moves the vertex angles by up
    to ~4e-4°. A grid contact within 1e-3° of a vertex is a vertex contact for any
    practical purpose and must never be part of a stable grasp (a contact exactly on a
    vertex has no defined normal). Each case checks at least one such contact, on the
    coarsest grid that has one, and that some grasp of the map is stable at all."""
    shape = load_object(name)
    n, near = _grid_on_vertices(shape)
    for mu in MUS:
        st = grasp_map(shape, mu, n).stable
        assert not st[near].any(), (name, mu, n, int(st[near].sum()))
        assert not st[:, near].any()
    assert grasp_map(shape, max(MUS), n).stable.any()  # the rule, not an empty map


@pytest.mark.parametrize("name", bundled_objects())
def test_vectorized_equals_loop_and_wrench(name):
    shape = load_object(name)
    for mu in (0.3, 0.7):
        a = grasp_map(shape, mu)
        b = grasp_map_loop(shape, mu)
        c = grasp_map(shape, mu, method="wrench")
        np.testing.assert_array_equal(a.stable, b.stable)
        np.testing.assert_array_equal(a.stable, c.stable)
        np.testing.assert_array_equal(a.usable, b.usable)
        np.testing.assert_array_equal(a.phi_deg, grid_angles_deg(N))


def test_small_grid_by_hand():
    """n = 12 (30° grid), circle, mu = 0.3: stable iff |Δ - 180°| < 2 atan(0.3) = 33.4°,
    i.e. Δ in {150°, 180°, 210°}: offsets k = 5, 6, 7."""
    gm = grasp_map(Circle(0.05), mu=0.3, n=12)
    assert gm.n == 12 and gm.step_deg == 30.0
    np.testing.assert_allclose(gm.phi_deg, 30.0 * np.arange(12))
    i, j = np.indices((12, 12))
    k = (j - i) % 12
    np.testing.assert_array_equal(gm.stable, (k >= 5) & (k <= 7))
    np.testing.assert_allclose(gm.fraction_stable(), 12 * 3 / 144)


def test_docstring_examples():
    """The module's examples (grasp_map's docstring) run as written."""
    import doctest
    import importlib

    mod = importlib.import_module("graspgait_env.grasp_map")

    res = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert res.failed == 0


def test_accepts_name_and_path():
    from graspgait_env.objects import OBJECT_DIR

    a = grasp_map("square", 0.5).stable
    b = grasp_map(OBJECT_DIR / "square.yaml", 0.5).stable
    c = grasp_map(load_object("square"), 0.5).stable
    assert np.array_equal(a, b) and np.array_equal(a, c)
    assert grasp_map("square", 0.5).shape_name == "square"


# --------------------------------------------------------------------------- views


def test_window_and_extended_are_wrapping_views():
    gm = grasp_map(load_object("ellipse"), 0.5)
    st = gm.stable
    ext = gm.extended()
    assert ext.shape == (2 * N, 2 * N)
    assert np.shares_memory(ext, st)
    for blk in ((0, 0), (0, 1), (1, 0), (1, 1)):
        np.testing.assert_array_equal(ext[blk[0] * N:(blk[0] + 1) * N,
                                          blk[1] * N:(blk[1] + 1) * N], st)
    for i0, j0, size in ((0, 0, 10), (170, 175, 20), (-5, 3, 12), (400, -200, 7), (179, 179, N)):
        w = gm.window(i0, j0, size)
        assert w.shape == (size, size)
        assert np.shares_memory(w, st)
        rows = np.arange(i0, i0 + size) % N
        cols = np.arange(j0, j0 + size) % N
        np.testing.assert_array_equal(w, st[np.ix_(rows, cols)])
    # read-only: a view cannot corrupt the map
    with pytest.raises(ValueError):
        gm.window(0, 0, 3)[0, 0] = True
    with pytest.raises(ValueError):
        st[0, 1] = True
    for size in (0, -1, N + 1):
        with pytest.raises(ValueError):
            gm.window(0, 0, size)


def test_array_protocol():
    gm = grasp_map(load_object("square"), 0.5)
    np.testing.assert_array_equal(np.asarray(gm), gm.stable)


# --------------------------------------------------------------------------- reach limit


def test_max_radius_marks_far_contacts_unusable():
    """Thesis 4.2, fig. 4.3: ellipse a = 0.09, b = 0.06, cap 0.075 m. Contacts with
    r(phi) > 0.075 lie within asin-bounded arcs around 0° and 180°: r = 0.075 where
    cos² phi = (1/r² - 1/b²) / (1/a² - 1/b²)."""
    a, b, cap = 0.09, 0.06, 0.075
    e = Ellipse(a, b)
    full = grasp_map(e, 0.5)
    gm = grasp_map(e, 0.5, max_radius=cap)
    phi = grid_angles_deg(N)
    c2 = (1 / cap**2 - 1 / b**2) / (1 / a**2 - 1 / b**2)
    edge = math.degrees(math.acos(math.sqrt(c2)))  # 51.3°: beyond reach within ±edge of 0/180
    far = (np.abs((phi + 180) % 360 - 180) < edge) | (np.abs(phi - 180) < edge)
    np.testing.assert_array_equal(gm.usable, ~far)
    assert not gm.stable[far].any() and not gm.stable[:, far].any()
    ok = ~far
    np.testing.assert_array_equal(gm.stable[np.ix_(ok, ok)], full.stable[np.ix_(ok, ok)])
    assert full.stable[far].any()  # the cap really removed something
    # a cap above r_max changes nothing
    np.testing.assert_array_equal(grasp_map(e, 0.5, max_radius=0.1).stable, full.stable)


@pytest.mark.parametrize("bad", [0.0, -0.05, float("nan"), float("inf")])
def test_bad_max_radius_refused(bad):
    with pytest.raises(ValueError, match="max_radius"):
        grasp_map(Circle(0.05), 0.5, max_radius=bad)


# --------------------------------------------------------------------------- bad arguments


@pytest.mark.parametrize("mu", [0, -0.1, float("nan"), float("inf"), "0.5", None, True])
def test_bad_mu_refused(mu):
    with pytest.raises(ValueError, match="mu"):
        grasp_map(Circle(0.05), mu)


@pytest.mark.parametrize("n", [0, 3, -180, 2.5, 180.0, "180", True, None])
def test_bad_n_refused(n):
    with pytest.raises(ValueError, match="n="):
        grasp_map(Circle(0.05), 0.5, n=n)


def test_bad_method_refused():
    with pytest.raises(ValueError, match="method"):
        grasp_map(Circle(0.05), 0.5, method="magic")


def test_numpy_scalar_arguments_accepted():
    a = grasp_map(Circle(0.05), np.float64(0.5), n=np.int64(36)).stable
    b = grasp_map(Circle(0.05), 0.5, n=36).stable
    np.testing.assert_array_equal(a, b)
