"""The planners as policies with stable-baselines3's ``predict`` signature.

One evaluation loop runs planners and learned agents alike::

    policy = PlannerPolicy(env, optimal_gait)          # or a PPO / MaskablePPO model
    obs, info = env.reset(seed=0)
    action, state = policy.predict(obs, state=None, episode_start=None, deterministic=True)

A planner is any function ``planner(model, start_state, turn_deg) -> PlannerResult``
(:mod:`graspgait_env.planners.result`; ``.plan`` a :class:`graspgait_env.plan.Plan` or ``None``):
:func:`graspgait_env.planners.exact.optimal_gait`, and with the same signature the search planners
(``graspgait_env.planners.search``) and the rule-based ones (``graspgait_env.planners.rule_based``).

How it works
------------
1. The gait state is read from the observation (:func:`state_from_observation`: the
   GraspGait observation encodes the object angle and contacts exactly); the gait model
   and the requested turn come from the environment (``env.unwrapped.model``, or
   ``get_attr`` on a vector env), re-read at every episode start, since
   ``GraspGaitRandom-v0`` changes the object at reset.
2. At the start of an episode (``episode_start`` true, the first call, or a state that
   is not the one the plan expects next) the planner is run from the present state and
   the plan's steps are turned into states, then into actions with
   :meth:`GaitModel.encode` (long rotations split into moves of at most ``R`` steps).
   Planners start at θ = 0; to replan from a state at angle ``k != 0`` the planner gets
   a model whose hand is turned by ``-k`` grid steps (:func:`rebased_model`), in which
   that state is at θ = 0, and the plan is shifted back.
3. While the observed state is the one the plan expects, the next action is played.
4. Without a plan (no gait exists, or the planner gives up) the policy plays the
   fallback: the longest legal rotation towards the goal, else the first legal move,
   else action 0 (the episode is over then). It does not rerun the planner until the
   next episode starts or the state leaves the fallback's own prediction.

Batched observations (``(n_envs, obs_dim)``) return ``(n_envs,)`` actions, one plan per
environment index; a single observation returns a 0-d action array, as SB3 does.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from gymnasium.vector import VectorEnv
from numpy.typing import NDArray

from graspgait_env.envs.map_env import state_from_observation
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.plan import Plan
from graspgait_env.planners.result import PlannerResult
from graspgait_env.workspace import Hand

__all__ = ["PlannerPolicy", "Planner", "plan_states", "plan_actions", "rebased_model",
           "planner_start"]

Planner = Callable[[GaitModel, GaitState, float], PlannerResult]


def plan_states(model: GaitModel, plan: Plan, k0: int = 0) -> list[GaitState]:
    """The gait states a plan passes through, the first at object angle ``k0``.

    Raises
    ------
    ValueError
        A contact or rotation off the model's grid, or an unknown step.
    """
    states: list[GaitState] = []
    k = k0
    for st in plan.steps:
        op = st.get("op")
        if op in ("grasp", "regrasp"):
            cs = [-1, -1, -1]
            for f, phi in st["contacts"].items():
                cs[int(f) - 1] = model.contact_index(float(phi))
            states.append(GaitState(k, tuple(cs)))
        elif op == "rotate":
            x = float(st["delta"]) / model.step_deg
            d = round(x)
            if abs(x - d) > 1e-6:
                raise ValueError(f"rotate {st['delta']} deg: not a multiple of the "
                                 f"{model.step_deg:g}-degree grid")
            k += d
            states.append(GaitState(k, states[-1].contacts))
        else:
            raise ValueError(f"plan step {st!r}: unknown op")
    return states


def plan_actions(model: GaitModel, states: list[GaitState]) -> list[tuple[GaitState, int]]:
    """``(state, action)`` pairs taking ``states[0]`` through every later state.

    Rotations longer than the longest single move ``R`` are split; zero rotations are
    dropped. Raises ``ValueError`` when two consecutive states are not one move apart.
    """
    out: list[tuple[GaitState, int]] = []
    for s, t in zip(states, states[1:], strict=False):
        if t == s:
            continue
        if t.contacts == s.contacts:
            k = s.k
            while k != t.k:
                d = max(-model.R, min(model.R, t.k - k))
                a = GaitState(k, s.contacts)
                b = GaitState(k + d, s.contacts)
                out.append((a, model.encode(a, b)))
                k += d
        else:
            out.append((s, model.encode(s, t)))
    return out


def rebased_model(model: GaitModel, k: int) -> GaitModel:
    """The model with the hand turned by ``-k`` grid steps: state ``(k, c)`` becomes ``(0, c)``.

    A contact's workspace position depends on ``c + k - s_f`` only, so shifting every
    workspace start ``s_f`` by ``-k`` moves the object angle to 0 and keeps the object,
    its grasp map and every legal move. The new model's states are the old ones with
    ``k`` subtracted.
    """
    if k % model.n == 0:
        return model
    shift = k * model.step_deg
    ws = tuple(((lo - shift) % 360.0, (lo - shift) % 360.0 + (hi - lo))
               for lo, hi in model.hand.workspaces_deg)
    m = GaitModel(model.shape, model.mu, Hand(ws, f"{model.hand.name} turned {-shift:g} deg"),
                  model.n, max_radius=model.max_radius, contact_model=model.contact_model)
    ok = (m.ws_width.tolist() == model.ws_width.tolist()
          and all((int(m.ws_start[f]) - int(model.ws_start[f]) + k) % model.n == 0
                  for f in range(3)))
    if not ok:
        raise ValueError(f"cannot turn the hand by {-shift:g} deg on the {model.step_deg:g}"
                         "-degree grid")
    return m


def planner_start(model: GaitModel, planner: Callable[..., PlannerResult],
                  turn_deg: float = 360.0) -> GaitState | None:
    """The start grasp a planner picks itself (``start=None``), or ``None`` without a plan.

    For planners whose start is optional (the rule-based ones): reset the env there,
    ``env.reset(options={"start": planner_start(model, forward_gait)})``, to evaluate
    the planner from the grasp its rules choose rather than from a random one.
    """
    res = planner(model, None, turn_deg)
    if res.plan is None:
        return None
    return plan_states(model, res.plan)[0]


@dataclass
class _Track:
    """What the policy knows about one environment index."""

    model: GaitModel | None = None
    queue: list[tuple[GaitState, int]] = field(default_factory=list)
    expected: GaitState | None = None  # the state the next observation should show
    result: PlannerResult | None = None
    fallback: bool = False
    replans: int = 0


class PlannerPolicy:
    """A planner behind SB3's ``predict(observation, state, episode_start, deterministic)``.

    Parameters
    ----------
    env
        The GraspGait environment the observations come from: a Gymnasium env (wrapped
        or not), a Gymnasium vector env or an SB3 ``VecEnv`` of GraspGait envs. Only its
        gait model(s) and ``turn_deg`` are read, never its state.
    planner
        ``planner(model, start_state, turn_deg) -> PlannerResult``.
    name
        Label (default the planner function's name).

    Attributes
    ----------
    results
        The latest :class:`PlannerResult` per environment index (``None`` before any).
    """

    def __init__(self, env: Any, planner: Planner, name: str | None = None) -> None:
        if not callable(planner):
            raise TypeError(f"planner={planner!r}: must be callable "
                            "planner(model, start_state, turn_deg) -> PlannerResult")
        self.env = env
        self.planner = planner
        self.name = name or getattr(planner, "__name__", "planner")
        self._tracks: dict[int, _Track] = {}
        self._turn_deg: float | None = None

    # ------------------------------------------------------------------ env access
    def _get_attr(self, name: str, index: int) -> Any:
        env = self.env
        if isinstance(env, VectorEnv):  # Gymnasium vector env: one value per env
            return env.get_attr(name)[index]
        if hasattr(env, "num_envs") and hasattr(env, "env_method"):  # SB3 VecEnv
            return env.get_attr(name, indices=[index])[0]
        if index != 0:
            raise ValueError("a batch of observations needs a vector env; got a single env")
        return getattr(env.unwrapped, name)

    def _turn(self) -> float:
        if self._turn_deg is None:
            self._turn_deg = float(self._get_attr("turn_deg", 0))
        return self._turn_deg

    @property
    def results(self) -> dict[int, PlannerResult | None]:
        """The latest planner result of each environment index."""
        return {i: t.result for i, t in self._tracks.items()}

    # ------------------------------------------------------------------ planning
    def _replan(self, tr: _Track, s: GaitState) -> None:
        model = tr.model
        assert model is not None
        turn = self._turn()
        K = model.turn_steps(turn)
        tr.replans += 1
        tr.queue = []
        tr.fallback = True
        try:
            base = rebased_model(model, s.k)
        except ValueError:
            tr.result = None
            return
        res = self.planner(base, GaitState(0, s.contacts), (K - s.k) * model.step_deg)
        tr.result = res
        if res.plan is None:
            return
        try:
            states = plan_states(model, res.plan, k0=s.k)
            if states[0] != s:
                return
            tr.queue = plan_actions(model, states)
        except (ValueError, KeyError):
            tr.queue = []
            return
        tr.fallback = False

    def _fallback_action(self, model: GaitModel, s: GaitState) -> int:
        mask = model.action_mask(s)
        legal = np.flatnonzero(mask)
        if legal.size == 0:
            return 0
        R = model.R
        sign = 1 if model.turn_steps(self._turn()) >= 0 else -1
        fwd = legal[legal < R] if sign > 0 else legal[(legal >= R) & (legal < 2 * R)]
        return int(fwd.max() if fwd.size else legal[0])

    def _act(self, i: int, obs: NDArray, start: bool) -> int:
        tr = self._tracks.setdefault(i, _Track())
        new_episode = start or tr.model is None
        if new_episode:
            tr.model = self._get_attr("model", i)
        model = tr.model
        assert model is not None
        s = state_from_observation(obs, model, self._turn())
        if not new_episode and tr.expected is not None and s != tr.expected:
            # off our prediction: a reset we were not told of, or someone else moved
            tr.model = model = self._get_attr("model", i)
            s = state_from_observation(obs, model, self._turn())
            new_episode = True
        if new_episode:
            self._replan(tr, s)
        if not tr.fallback:
            if tr.queue and tr.queue[0][0] == s:
                _, a = tr.queue.pop(0)
                tr.expected = model.apply(s, a)
                return a
            self._replan(tr, s)  # plan used up or off track
            if not tr.fallback and tr.queue and tr.queue[0][0] == s:
                _, a = tr.queue.pop(0)
                tr.expected = model.apply(s, a)
                return a
            tr.fallback = True
        a = self._fallback_action(model, s)
        legal = bool(model.action_mask(s)[a])
        tr.expected = model.apply(s, a) if legal else s
        return a

    # ------------------------------------------------------------------ SB3 API
    def predict(self, observation: NDArray, state: Any = None,
                episode_start: NDArray | None = None, deterministic: bool = True,
                action_masks: NDArray | None = None) -> tuple[NDArray, Any]:
        """Actions for one observation or a batch, with SB3's signature.

        Parameters
        ----------
        observation
            ``(obs_dim,)`` or ``(n_envs, obs_dim)``.
        state
            Unused (no recurrent state); returned as given.
        episode_start
            ``(n_envs,)`` bools: which environments just reset. ``None``: detected from
            the observations (a state the plan did not expect starts a new plan).
        deterministic
            Ignored: planners are deterministic.
        action_masks
            Ignored (accepted for MaskablePPO-style loops); the masks come from the model.

        Returns
        -------
        actions, state
            ``int64`` actions, shape ``()`` for a single observation, ``(n_envs,)`` for a
            batch; ``state`` unchanged.
        """
        obs = np.asarray(observation)
        single = obs.ndim == 1
        batch = obs[None, :] if single else obs
        if batch.ndim != 2:
            raise ValueError(f"observation shape {obs.shape}: expected (obs_dim,) or "
                             "(n_envs, obs_dim)")
        starts = (np.zeros(len(batch), dtype=bool) if episode_start is None
                  else np.asarray(episode_start, dtype=bool).reshape(-1))
        if starts.size == 1 and len(batch) > 1:
            starts = np.repeat(starts, len(batch))
        acts = np.array([self._act(i, batch[i], bool(starts[i])) for i in range(len(batch))],
                        dtype=np.int64)
        return (acts.reshape(()) if single else acts), state

    def reset(self) -> None:
        """Forget every plan (the next call plans afresh)."""
        self._tracks.clear()
        self._turn_deg = None

    def __repr__(self) -> str:
        return f"PlannerPolicy({self.name})"
