"""General searches for a gait (thesis 5.3-5.5): breadth-first, depth-first, best-first."""

from __future__ import annotations

import numpy as np
import pytest

from graspgait_env import GraspGaitInputError
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import plan_from_states, validate_plan
from graspgait_env.planners.exact import optimal_gait
from graspgait_env.planners.search import (
    _Graph,
    best_first,
    best_first_metric,
    breadth_first,
    depth_first,
)

OBJECTS = ["circle", "pentagon", "ellipse", "hexagon", "square"]
PLANNERS = [breadth_first, depth_first, best_first]
MU = 0.7


def _model(name: str, n: int, mu: float = MU) -> GaitModel:
    return _MODELS.setdefault((name, n, mu), GaitModel(name, mu, n=n))


_MODELS: dict = {}


def _starts(model: GaitModel, count: int) -> list[GaitState]:
    """``count`` start grasps spread over ``start_states()``, each with a 360-degree gait."""
    key = (id(model), count)
    if key not in _STARTS:
        ss = model.start_states()
        picks: list[GaitState] = []
        for i in np.linspace(0, len(ss) - 1, 4 * count).astype(int):
            if len(picks) < count and optimal_gait(model, ss[i]).success:
                picks.append(ss[i])
        assert len(picks) == count
        _STARTS[key] = picks
    return _STARTS[key]


_STARTS: dict = {}


def _check_result(model: GaitModel, res, turn_deg: float) -> None:
    """A found plan validates, achieves the turn, and its statistics match it."""
    assert res.plan is not None, res.reason
    assert validate_plan(res.plan, model.shape, model.hand, turn_deg) is None
    assert res.reason == "" and not res.exhausted
    assert res.path_length == len(res.plan.steps) - 1  # one step per move, nothing merged
    assert res.regrasps == res.plan.regrasps
    assert res.rotation_deg == pytest.approx(res.plan.rotation_deg)
    assert res.rotation_deg == pytest.approx(model.turn_steps(turn_deg) * model.step_deg)
    assert abs(res.max_turn_deg) >= abs(turn_deg) - 1e-9
    assert 1 <= res.nodes_opened <= res.nodes_created
    assert res.wall_time_s > 0
    assert res.plan.stats == {"planner": res.planner, "nodes_opened": res.nodes_opened,
                              "regrasps": res.regrasps, "rotation_deg": res.rotation_deg}


# --------------------------------------------------------------------------- plans


@pytest.mark.parametrize("name", OBJECTS)
def test_breadth_first_plans_validate(name):
    # a coarse grid (10 deg) keeps the breadth-first state space small
    model = _model(name, 36)
    for s in _starts(model, 3):
        _check_result(model, breadth_first(model, s), 360.0)


@pytest.mark.parametrize("planner", [depth_first, best_first])
@pytest.mark.parametrize("name", OBJECTS)
def test_depth_and_best_first_plans_validate(name, planner):
    model = _model(name, 90)
    for s in _starts(model, 4):
        _check_result(model, planner(model, s), 360.0)


@pytest.mark.parametrize("planner", [depth_first, best_first])
def test_thesis_grid_pentagon(planner):
    # the thesis's own setting: 2-degree grid, pentagon of fig. 4.6, mu = 0.7
    model = _model("pentagon", 180)
    s = model.start_state({1: 50.0, 3: 270.0})
    _check_result(model, planner(model, s), 360.0)


@pytest.mark.parametrize("planner", PLANNERS)
def test_clockwise_turn(planner):
    model = _model("pentagon", 36)
    s = _starts(model, 2)[1]
    res = planner(model, s, -360.0)
    _check_result(model, res, -360.0)
    assert res.rotation_deg == pytest.approx(-360.0)


@pytest.mark.parametrize("planner", PLANNERS)
def test_zero_turn_is_the_start(planner):
    model = _model("pentagon", 36)
    s = _starts(model, 1)[0]
    res = planner(model, s, 0.0)
    assert res.plan is not None and res.path_length == 0 and res.nodes_opened == 0
    assert [st["op"] for st in res.plan.steps] == ["grasp"]


@pytest.mark.parametrize("name", OBJECTS)
def test_breadth_first_is_shortest_in_moves(name):
    model = _model(name, 36)
    for s in _starts(model, 3):
        b = breadth_first(model, s)
        d = depth_first(model, s)
        g = best_first(model, s)
        assert b.success and d.success and g.success
        assert b.path_length <= d.path_length
        assert b.path_length <= g.path_length


# --------------------------------------------------------------------------- DFS order


def test_depth_first_rotates_first_largest_toward_goal():
    # thesis fig. 4.6: (50, 270) by fingers 1 and 3 turns at most 40 deg CCW, 30 deg CW
    model = _model("pentagon", 180)
    s = model.start_state({1: 50.0, 3: 270.0})
    ccw = depth_first(model, s, 360.0)
    assert ccw.plan.steps[1] == {"op": "rotate", "delta": 40.0}
    coarse = _model("pentagon", 36)  # clockwise DFS paths are very long on the 2-degree grid
    s = coarse.start_state({1: 50.0, 3: 270.0})
    cw = depth_first(coarse, s, -360.0)
    assert cw.plan.steps[1] == {"op": "rotate", "delta": -30.0}


@pytest.mark.parametrize("name", OBJECTS)
def test_depth_first_regrasps_only_when_rotation_is_spent(name):
    """DFS opens with the largest forward rotation; its first regrasp comes where no
    counter-clockwise rotation is left (thesis 5.4)."""
    model = _model(name, 90)
    R = model.R
    for s in _starts(model, 3):
        steps = depth_first(model, s).plan.steps
        ccw = int(np.flatnonzero(model.action_mask(s)[:R]).max(initial=-1)) + 1
        if ccw:
            assert steps[1] == {"op": "rotate", "delta": ccw * model.step_deg}
        i = next(i for i, st in enumerate(steps) if st["op"] == "regrasp")
        k = model.turn_steps(sum(st["delta"] for st in steps[1:i]))
        assert not model.action_mask(GaitState(k, s.contacts))[:R].any()


# --------------------------------------------------------------------------- best-first


def test_metric_values():
    # M = alpha theta - beta eta - gamma r (thesis 5.5)
    assert best_first_metric(40.0, 1, 1) == 38.0
    assert best_first_metric(0.0, 0, 0) == 0.0
    assert best_first_metric(40.0, 2, 3, alpha=2.0, beta=0.5, gamma=0.0) == 79.0
    m = best_first_metric(np.array([0.0, 10.0]), np.array([1, 0]), np.array([0, 2]))
    np.testing.assert_allclose(m, [-1.0, 8.0])


def test_metric_ordering():
    # one 40-degree rotation beats two 20-degree rotations (gamma > 0) ...
    assert best_first_metric(40.0, 0, 1) > best_first_metric(40.0, 0, 2)
    # ... a rotation beats a regrasp at the same angle (beta > 0) ...
    assert best_first_metric(40.0, 0, 1) > best_first_metric(40.0, 1, 1)
    # ... and turning 2 degrees further outweighs one more rotation (alpha = gamma = 1)
    assert best_first_metric(42.0, 0, 2) > best_first_metric(40.0, 0, 1)
    # with gamma = 0 two small rotations tie with one large one
    assert best_first_metric(40.0, 0, 2, gamma=0.0) == best_first_metric(40.0, 0, 1, gamma=0.0)


def test_best_first_first_move_is_the_largest_rotation():
    # from the start, the child with the highest M is the largest rotation toward the goal
    model = _model("pentagon", 180)
    s = model.start_state({1: 50.0, 3: 270.0})
    res = best_first(model, s)
    assert res.plan.steps[1] == {"op": "rotate", "delta": 40.0}
    assert res.extra["alpha"] == res.extra["beta"] == res.extra["gamma"] == 1.0


def test_best_first_weights_change_the_search():
    model = _model("ellipse", 90)
    s = _starts(model, 3)[1]
    a = best_first(model, s)
    b = best_first(model, s, alpha=1.0, beta=5.0, gamma=1.0)
    _check_result(model, b, 360.0)
    assert b.extra["beta"] == 5.0
    assert (a.nodes_opened, a.plan.steps) != (b.nodes_opened, b.plan.steps)


def test_best_first_is_deterministic():
    model = _model("hexagon", 90)
    s = _starts(model, 2)[1]
    a, b = best_first(model, s), best_first(model, s)
    assert a.plan.steps == b.plan.steps and a.nodes_opened == b.nodes_opened


# --------------------------------------------------------------------------- limits


@pytest.mark.parametrize("planner", PLANNERS)
@pytest.mark.parametrize("limit", [0, 1, 5])
def test_node_limit(planner, limit):
    model = _model("ellipse", 90)
    s = _starts(model, 3)[1]
    res = planner(model, s, max_nodes=limit)
    assert res.plan is None and not res.exhausted
    assert res.nodes_opened <= limit
    assert res.reason.startswith("node limit")
    assert "max_nodes" in res.reason


def test_breadth_first_node_limit_on_thesis_grid():
    # thesis 5.3: breadth-first is hopeless at 2 degrees; the limit stops it cleanly
    model = _model("pentagon", 180)
    s = model.start_state({1: 50.0, 3: 270.0})
    res = breadth_first(model, s, max_nodes=2000)
    assert res.plan is None and res.nodes_opened == 2000 and not res.exhausted
    assert res.nodes_created > res.nodes_opened


def test_bad_arguments():
    model = _model("pentagon", 36)
    s = _starts(model, 1)[0]
    with pytest.raises(GraspGaitInputError, match="max_nodes"):
        breadth_first(model, s, max_nodes=-1)
    with pytest.raises(GraspGaitInputError, match="theta_window_deg"):
        best_first(model, s, 360.0, theta_window_deg=(0.0, 180.0))
    with pytest.raises(GraspGaitInputError, match="gamma"):
        best_first(model, s, gamma=float("nan"))
    with pytest.raises(ValueError, match="legal state"):
        depth_first(model, GaitState(0, (-1, -1, 0)))


def test_theta_window_is_rounded_as_the_workspaces_are():
    """The window's grid angles come from gait.workspace_grid, the one grid rounding:
    inwards, to 1e-9 of a step; a window holding no grid angle is refused by name."""
    model = _model("circle", 36)  # 10-degree grid
    s = _starts(model, 1)[0]
    res = breadth_first(model, s, 90.0, theta_window_deg=(-5.0, 95.0 + 1e-12))
    assert res.extra["theta_window_deg"] == [0.0, 90.0]
    with pytest.raises(GraspGaitInputError, match="theta_window_deg"):
        breadth_first(model, s, 0.0, theta_window_deg=(1.0, 9.0))


# --------------------------------------------------------------------------- no gait


@pytest.mark.parametrize("planner", PLANNERS)
def test_no_gait_is_exhausted_and_agrees_with_exact(planner):
    # thesis ellipse at mu = 0.8: this grasp turns 16 deg at most, whatever follows
    model = _model("ellipse", 180, 0.8)
    s = model.start_state({1: 10.0, 2: 194.0})
    exact = optimal_gait(model, s)
    assert exact.plan is None
    res = planner(model, s)
    assert res.plan is None and res.exhausted
    assert res.max_turn_deg == pytest.approx(exact.max_turn_deg) == pytest.approx(16.0)
    assert "at most 16 deg" in res.reason


def test_theta_window_bounds_the_search():
    model = _model("circle", 36)
    s = _starts(model, 1)[0]
    res = breadth_first(model, s, 90.0, theta_window_deg=(0.0, 90.0))
    _check_result(model, res, 90.0)
    assert res.extra["theta_window_deg"] == [0.0, 90.0]
    assert breadth_first(model, s).extra["theta_window_deg"] == [-360.0, 720.0]


# --------------------------------------------------------------------------- one move function


@pytest.mark.parametrize("name", ["pentagon", "ellipse"])
def test_vectorized_expansion_matches_model_successors(name):
    """The searches' decoding of ``action_mask`` equals GaitModel.successors, move for move."""
    model = _model(name, 36)
    rng = np.random.default_rng(1)
    start = _starts(model, 1)[0]
    states = []
    for s0 in _starts(model, 5):  # walk a little to reach states at other angles
        s = s0
        for _ in range(12):
            states.append(s)
            succ = model.successors(s)
            s = succ[rng.integers(len(succ))][1]
    for s in states:
        G = _Graph(model, start, 360.0, None)
        code = G.encode(s)
        assert G.decode(code) == s
        G.parent[:] = -1
        G.parent[code] = code
        codes, acts, is_reg = G.expand(code)
        got = [(int(a), G.decode(int(c))) for a, c in zip(acts, codes, strict=True)]
        want = [(a, t) for a, t in model.successors(s) if G.k_lo <= t.k <= G.k_hi]
        assert got == want
        assert is_reg.tolist() == [t.k == s.k for _, t in want]


# --------------------------------------------------------------------------- tie-break
def test_best_first_tie_break_oldest_and_newest():
    """The two readings of the unstated tie-break (thesis 5.5) are both searches of the
    same graph: both find a valid gait, they open different nodes, and the default is
    "oldest" (ties to the node created first)."""
    from graspgait_env.planners.registry import get_planner
    from graspgait_env.planners.search import best_first_newest

    model = _model("ellipse", 90)
    s = _starts(model, 2)[1]
    old, new = best_first(model, s), best_first(model, s, tie_break="newest")
    _check_result(model, old, 360.0)
    assert new.plan is not None and validate_plan(new.plan, model.shape, model.hand) is None
    assert old.extra["tie_break"] == "oldest" and new.extra["tie_break"] == "newest"
    assert (old.nodes_opened, old.plan.steps) != (new.nodes_opened, new.plan.steps)
    assert best_first(model, s, tie_break="oldest").plan.steps == old.plan.steps
    named = get_planner("best-first-newest")
    assert named is best_first_newest
    r = named(model, s)
    assert r.planner == r.plan.stats["planner"] == "best-first-newest"
    assert r.plan.steps == new.plan.steps and r.nodes_opened == new.nodes_opened
    with pytest.raises(GraspGaitInputError, match="tie_break"):
        best_first(model, s, tie_break="random")


# --------------------------------------------------------------------------- DFS, thesis form
def test_depth_first_thesis_has_no_visited_set():
    """Thesis 5.4: no visited set, so states are created again on every path reaching
    them (more nodes created than distinct states exist along the way); rotations toward
    the goal, the largest first, and regrasps only where rotation is spent."""
    from graspgait_env.planners.search import depth_first_thesis

    model = _model("pentagon", 180)
    s = model.start_state({1: 50.0, 3: 270.0})  # the thesis's pentagon example
    res = depth_first_thesis(model, s)
    _check_result_any(model, res)
    assert res.planner == "depth-first-thesis" and res.extra["visited_set"] is False
    assert res.plan.steps[1] == {"op": "rotate", "delta": 40.0}
    assert all(st["op"] == "regrasp" or st["delta"] > 0 for st in res.plan.steps[1:])
    ours = depth_first(model, s)
    assert res.nodes_created > ours.nodes_created  # repeats are created again
    capped = depth_first_thesis(model, s, max_nodes=50)
    assert capped.plan is None and not capped.exhausted and capped.nodes_opened == 50
    assert capped.reason.startswith("node limit")


def test_depth_first_thesis_exhausts_where_no_gait_exists():
    # thesis ellipse at mu = 0.8 on a 10-degree grid: this grasp turns 16 deg at most
    from graspgait_env.planners.search import depth_first_thesis

    model = _model("ellipse", 36, 0.8)
    for s in model.start_states()[:20]:
        exact = optimal_gait(model, s)
        res = depth_first_thesis(model, s, max_nodes=10**6)
        assert (res.plan is None) == (exact.plan is None)
        if res.plan is None:
            assert res.exhausted
            assert abs(res.max_turn_deg) <= abs(exact.max_turn_deg)


def _check_result_any(model: GaitModel, res) -> None:
    """As _check_result, for a planner whose stats carry its own name."""
    assert res.plan is not None, res.reason
    assert validate_plan(res.plan, model.shape, model.hand, 360.0) is None
    assert res.path_length == len(res.plan.steps) - 1
    assert res.regrasps == res.plan.regrasps
    assert 1 <= res.nodes_opened <= res.nodes_created


# --------------------------------------------------------------------------- batched BFS
def _fifo_breadth_first(model: GaitModel, start: GaitState, turn_deg: float,
                        max_nodes: int) -> tuple:
    """The reference: breadth-first search opened one node at a time from a FIFO queue
    with :meth:`_Graph.expand` (one ``action_mask`` call per node)."""
    from collections import deque

    G = _Graph(model, start, turn_deg, None)
    opened, queue = 0, deque([G.start_code])
    while G.goal < 0 and queue and opened < max_nodes:
        code = queue.popleft()
        opened += 1
        queue.extend(G.expand(code)[0].tolist())
    path = G.path() if G.goal >= 0 else None
    return opened, G.created, G.best, path


@pytest.mark.parametrize("name,turn,max_nodes", [
    ("circle", 360.0, 3000), ("ellipse", -90.0, 20_000), ("pentagon", 360.0, 6000),
    ("hexagon", 30.0, 50_000), ("square", 180.0, 9001)])
def test_breadth_first_batched_equals_fifo_queue(name, turn, max_nodes):
    """The level-by-level batched search opens the same nodes as a FIFO queue opened one
    by one: the same plan, nodes opened and created and largest turn, both when the goal
    is found and when the node limit stops it mid-level."""
    model = _model(name, 90)
    for s in model.start_states()[::97][:4]:
        res = breadth_first(model, s, turn, max_nodes=max_nodes)
        opened, created, best, path = _fifo_breadth_first(model, s, turn, max_nodes)
        assert res.nodes_opened == opened and res.nodes_created == created
        assert res.max_turn_deg == pytest.approx(np.sign(turn) * best * model.step_deg)
        if path is None:
            assert res.plan is None
        else:
            assert res.plan is not None
            ref = plan_from_states(model, path)
            ref.stats = res.plan.stats  # the counts, checked above
            assert res.plan.to_json() == ref.to_json()


def test_action_masks_at_equals_action_mask():
    """The batched legal-move rule is :meth:`GaitModel.action_mask` row for row, at
    angles all round the window (negative ones included)."""
    model = _model("hexagon", 180)
    rng = np.random.default_rng(3)
    rows, want = [], []
    for s in model.start_states()[::11]:
        k = int(rng.integers(-400, 400))
        f, g = s.held()
        pf, pg = (model.position(x, s.contacts[x], 0) for x in (f, g))
        cs = list(s.contacts)
        for x in (f, g):  # the same workspace positions at angle k
            cs[x] = (s.contacts[x] - k) % model.n
        rows.append((k, f, g, pf, pg))
        want.append(model.action_mask(GaitState(k, tuple(cs))))
    k, f, g, pf, pg = (np.array(c) for c in zip(*rows, strict=True))
    got = model.action_masks_at(k, f, g, pf, pg)
    assert got.shape == (len(rows), model.n_actions)
    assert got.any(axis=1).all()
    np.testing.assert_array_equal(got, np.stack(want))


def _dfs_thesis_counts(model: GaitModel, start: GaitState, turn_deg: float,
                       max_nodes: int) -> tuple:
    """The reference: the thesis's tree search with every node expanded afresh
    (:meth:`_Graph.children` at each opening, nothing kept per state)."""
    G = _Graph(model, start, turn_deg, None)
    R, sign, K = model.R, G.sign, G.K
    opened, created, best = 0, 1, 0
    path: list[int] = []
    frames: list[list[int]] = []
    goal = G.start_code if G.goal >= 0 else -1

    def open_node(code: int) -> int:
        nonlocal opened, created, best
        opened += 1
        path.append(code)
        codes, acts, kc = G.children(code)
        created += int(codes.size)
        is_reg = G.act_is_reg[acts]
        fwd = ~is_reg & ((acts < R) if sign > 0 else (acts >= R))
        along = kc * sign
        if fwd.any():
            best = max(best, int(along[fwd].max()))
            hit = fwd & (along >= sign * K)
            if hit.any():
                return int(codes[np.flatnonzero(hit)[np.argmin(along[hit])]])
        rot = codes[fwd][np.argsort(along[fwd], kind="stable")]
        frames.append(np.concatenate((codes[is_reg][::-1], rot)).tolist())
        return -1

    if goal < 0:
        goal = open_node(G.start_code)
    while goal < 0 and frames and opened < max_nodes:
        if not frames[-1]:
            frames.pop()
            path.pop()
            continue
        child = frames[-1].pop()
        if child not in path:
            goal = open_node(child)
    return opened, created, best, (path + [goal] if goal >= 0 else None)


@pytest.mark.parametrize("name", ["circle", "ellipse", "pentagon", "hexagon"])
def test_depth_first_thesis_equals_search_without_kept_openings(name):
    """What the tree search keeps per state changes nothing: the same nodes opened and
    created, largest turn and path as expanding every opening afresh, to the node limit
    and to the goal, both ways round."""
    from graspgait_env.planners.search import depth_first_thesis

    model = _model(name, 90)
    outcomes = set()
    for s in model.start_states()[::50][:4]:
        for turn in (360.0, -180.0):
            res = depth_first_thesis(model, s, turn, max_nodes=5000)
            opened, created, best, path = _dfs_thesis_counts(model, s, turn, 5000)
            assert (res.nodes_opened, res.nodes_created) == (opened, created)
            assert res.max_turn_deg == pytest.approx(np.sign(turn) * best * model.step_deg)
            assert (res.plan is None) == (path is None)
            if path is not None:
                ref = plan_from_states(model, [_Graph(model, s, turn, None).decode(c)
                                               for c in path])
                ref.stats = res.plan.stats
                assert res.plan.to_json() == ref.to_json()
            outcomes.add(res.plan is not None)
    if name == "hexagon":
        assert outcomes == {True, False}  # both outcomes are checked here
