"""Demonstration datasets (Minari) and the behaviour-cloning baseline.

Recording (``graspgait dataset record TASK --policy optimal|rule --episodes N``,
:func:`record_dataset`): a planner (:class:`~graspgait_env.baselines.policies.
PlannerPolicy`, the exact optimum or the thesis's rule-based method) plays the task's
*training* env (``task.train_env_id``, ``task.train_kwargs``: the training objects,
never the held-out ones) wrapped in Minari's ``DataCollector``, from the training reset
seeds ``0, 1, 2, ...``; a seed from whose start the planner finds no gait is skipped
(a demonstration is a gait), until ``N`` demonstrations are recorded. The observation
is the env's default one, the actions its ``Discrete`` moves. The dataset is written to
Minari's data path (``MINARI_DATASETS_PATH``, else ``~/.minari/datasets``) in the
Arrow format, with

- the env spec of the recording env (``recover_environment()`` makes it again) and,
  as ``eval_env``, the task's test env (``recover_environment(eval_env=True)``);
- ``expert_policy`` set to the demonstrating planner on tasks of one object, which it
  plays from the observation alone (Minari computes ``ref_max_score`` with it); on
  ``GraspGaitRandom-v0`` the object is not in the observation, so the recorder plays
  the planner itself on the test env as Minari would (first reset seed 123, then
  unseeded) and records the mean return as ``ref_max_score``;
- ``algorithm_name`` (``"graspgait_env optimal planner"``), ``requirements`` (this
  version of graspgait_env) and a description.

Dataset ids (:func:`dataset_id`): ``graspgait/TASK/POLICY-vV`` with ``V`` the suite
version (:data:`~graspgait_env.benchmark.suite.SUITE_VERSION`), e.g.
``graspgait/map-point-ellipse/optimal-v1``: Minari's namespace ``graspgait/TASK``,
dataset name ``POLICY``. The hand-track tasks train on their map-level twin
(``map-hand-OBJECT``): record that.

Behaviour cloning (:func:`train_bc`, POLICY ``bc[:optimal|rule]`` of ``graspgait
benchmark``): a small MLP (two hidden layers of 256, ReLU) maps the observation to
action logits; the logits of the moves that the observation's legal-move mask rules
out are set to -inf, and the net is trained with cross-entropy on the demonstrations'
(observation, action) pairs (Adam, learning rate 1e-3, batches of 256, 20 epochs,
torch seeded with the run seed). It plays the legal move of highest logit.
"""

from __future__ import annotations

import contextlib
import io
import os
import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from graspgait_env.benchmark.suite import SUITE_VERSION, Task, get_task
from graspgait_env.errors import GraspGaitInputError

__all__ = ["BCPolicy", "DEMO_POLICIES", "NAMESPACE", "bc_policy_for", "dataset_id",
           "datasets_path", "load_demonstrations", "record_dataset", "train_bc"]

NAMESPACE = "graspgait"
DEMO_POLICIES = ("optimal", "rule")
DATA_FORMAT = "arrow"
REFERENCE_EPISODES = 20  # episodes of Minari's reference scores


def dataset_id(task_id: str, policy: str = "optimal", version: int = SUITE_VERSION) -> str:
    """``graspgait/TASK/POLICY-vV``: the id of a task's demonstrations."""
    return f"{NAMESPACE}/{task_id}/{policy}-v{int(version)}"


def datasets_path() -> Path:
    """Minari's data path: ``MINARI_DATASETS_PATH``, else ``~/.minari/datasets``."""
    return Path(os.environ.get("MINARI_DATASETS_PATH")
                or Path.home() / ".minari" / "datasets")


def _recording_task(task_id: str) -> Task:
    task = get_task(task_id)
    if task.train_task:
        raise GraspGaitInputError(
            f"TASK {task_id}: its policies learn on {task.train_task} (the hand track is not "
            f"trained in); record that: graspgait dataset record {task.train_task}")
    return task


def _check_policy(policy: str) -> str:
    if policy not in DEMO_POLICIES:
        raise GraspGaitInputError(f"--policy {policy!r}: demonstrations come from "
                                  f"{' or '.join(DEMO_POLICIES)}")
    return policy


class _Expert:
    """A planner as Minari's ``expert_policy`` (``obs -> action``) on a one-object env:
    it replans whenever the state is not the one it expects (so at every new episode)."""

    def __init__(self, env: Any, planner: str) -> None:
        from graspgait_env.baselines.policies import PlannerPolicy
        from graspgait_env.planners.registry import get_planner

        self.env = env
        self.policy = PlannerPolicy(env, get_planner(planner), name=planner)

    def __call__(self, obs: np.ndarray) -> int:
        return int(self.policy.predict(obs)[0])


def _play(env: Any, policy: Any, seed: int | None) -> tuple[bool, float]:
    """One episode of a PlannerPolicy from ``reset(seed)``; (success, return)."""
    obs, info = env.reset(seed=seed)
    start, total, done = True, 0.0, False
    while not done:
        action, _ = policy.predict(obs, episode_start=np.array([start]))
        start = False
        obs, r, term, trunc, info = env.step(int(action))
        total += float(r)
        done = term or trunc
    return bool(info.get("is_success", False)), total


def record_dataset(task_id: str, policy: str = "optimal", episodes: int = 100, *,
                   overwrite: bool = False, progress: bool = False,
                   reference_episodes: int | None = None) -> Any:
    """Record ``episodes`` demonstrations of ``policy`` on a task (module docstring).

    Parameters
    ----------
    reference_episodes
        Episodes of Minari's reference scores (default :data:`REFERENCE_EPISODES`).

    Returns
    -------
    minari.MinariDataset
        The dataset, already written under :func:`datasets_path`.

    Raises
    ------
    GraspGaitInputError
        A hand-track task, an unknown policy, ``episodes < 1``, or a dataset of that id
        already there (without ``overwrite``).
    """
    import minari
    from tqdm.auto import tqdm

    from graspgait_env import __version__
    from graspgait_env.agents.envs import make_env
    from graspgait_env.baselines.policies import PlannerPolicy
    from graspgait_env.planners.registry import get_planner

    task = _recording_task(task_id)
    policy = _check_policy(policy)
    if isinstance(episodes, bool) or int(episodes) < 1:
        raise GraspGaitInputError(f"--episodes {episodes}: must be >= 1, e.g. 100")
    episodes = int(episodes)
    reference_episodes = int(reference_episodes or REFERENCE_EPISODES)
    did = dataset_id(task.id, policy)
    if did in minari.list_local_datasets():
        if not overwrite:
            raise GraspGaitInputError(f"dataset {did} exists in {datasets_path()}; pass "
                                      "--overwrite to record it again")
        with contextlib.redirect_stdout(io.StringIO()):  # Minari prints "deleted!"
            minari.delete_dataset(did)
    planner = get_planner(policy)
    shadow = make_env(task.train_env_id, dict(task.train_kwargs))  # finds the starts with a gait
    env = minari.DataCollector(make_env(task.train_env_id, dict(task.train_kwargs)),
                               record_infos=False, data_format=DATA_FORMAT)
    expert = PlannerPolicy(env, planner, name=policy)
    turn = float(shadow.unwrapped.config.turn_deg)
    seed, recorded, skipped, wins = task.train_seeds[0], 0, 0, 0
    bar = tqdm(total=episodes, desc=f"record {did}", unit="ep", disable=not progress)
    try:
        while recorded < episodes:
            if seed >= task.train_seeds[1]:
                raise GraspGaitInputError(f"task {task.id}: too few starts with a gait")
            shadow.reset(seed=seed)
            u = shadow.unwrapped
            if planner(u.model, u.state, turn).plan is None:
                skipped += 1
            else:
                ok, _ = _play(env, expert, seed)
                wins += ok
                recorded += 1
                bar.update(1)
            seed += 1
        bar.close()
        test_env = make_env(task.env_id, task.env_kwargs())
        meta: dict[str, Any] = {}
        if task.env_id == "GraspGaitRandom-v0":
            meta["ref_max_score"] = _reference_return(test_env, policy, reference_episodes)
        else:
            meta["expert_policy"] = _Expert(make_env(task.env_id, task.env_kwargs()), policy)
        with warnings.catch_warnings():  # Minari asks for a code permalink and an email
            warnings.filterwarnings("ignore", message=r"`(code_permalink|author_email)`")
            dataset = env.create_dataset(
                dataset_id=did, eval_env=test_env,
                algorithm_name=f"graspgait_env {policy} planner", author="graspgait_env",
                requirements=[f"graspgait_env=={__version__}"],
                num_episodes_average_score=int(reference_episodes),
                description=(
                    f"{episodes} demonstrations of the {policy} planner on task {task.id} of "
                    f"the GraspGait benchmark suite v{SUITE_VERSION} ({task.description}): "
                    f"training reset seeds {task.train_seeds[0]}..{seed - 1}, {skipped} "
                    f"skipped (no gait from the start), {wins} reached the turn"),
                **meta)
        test_env.close()
    finally:
        env.close()
        shadow.close()
    return dataset


def _reference_return(env: Any, policy: str, episodes: int) -> float:
    """The planner's mean return on ``env`` over ``episodes`` episodes, reset as Minari
    resets for its reference scores (seed 123, then unseeded)."""
    from graspgait_env.baselines.policies import PlannerPolicy
    from graspgait_env.planners.registry import get_planner

    p = PlannerPolicy(env, get_planner(policy), name=policy)
    returns = [_play(env, p, 123 if i == 0 else None)[1] for i in range(int(episodes))]
    return float(np.mean(returns, dtype=np.float32))


def load_demonstrations(dataset: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(observations, actions, masks)`` of every step of a dataset (an id or a
    ``MinariDataset``): the observation before each action, the action, and the legal
    moves read from the observation (the env's ``layout.mask``)."""
    ds = _load(dataset)
    env = ds.recover_environment()
    try:
        sl = env.unwrapped.layout.mask
    finally:
        env.close()
    obs, acts = [], []
    for ep in ds.iterate_episodes():
        o = np.asarray(ep.observations, dtype=np.float32)
        obs.append(o[:-1])
        acts.append(np.asarray(ep.actions, dtype=np.int64).reshape(-1))
    if not obs:
        raise GraspGaitInputError(f"dataset {ds.id}: no episodes")
    X = np.concatenate(obs)
    return X, np.concatenate(acts), X[:, sl] > 0.5


def _load(dataset: Any) -> Any:
    import minari

    if not isinstance(dataset, str):
        return dataset
    try:
        return minari.load_dataset(dataset)
    except (FileNotFoundError, ValueError) as exc:
        parts = dataset.split("/")
        hint = (f"; record it: graspgait dataset record {parts[1]} --policy "
                f"{parts[2].rsplit('-v', 1)[0]}" if len(parts) == 3 else "")
        raise GraspGaitInputError(f"dataset {dataset}: not found in {datasets_path()} "
                                  f"({exc}){hint}") from None


@dataclass
class BCPolicy:
    """A behaviour-cloned policy: ``predict(obs, mask) -> action`` (the legal move of
    highest logit). ``info``: the dataset, the steps trained, the final loss."""

    net: Any
    info: dict[str, Any]

    def logits(self, obs: np.ndarray) -> np.ndarray:
        """The action logits of one observation (before the mask)."""
        import torch

        with torch.no_grad():
            x = torch.as_tensor(np.asarray(obs, dtype=np.float32).reshape(1, -1))
            return self.net(x)[0].numpy()

    def predict(self, obs: np.ndarray, mask: np.ndarray) -> int:
        """The legal move (``mask``) of highest logit; 0 when none is legal."""
        z = self.logits(obs)
        m = np.asarray(mask, dtype=bool)
        if not m.any():
            return 0
        return int(np.flatnonzero(m)[np.argmax(z[m])])

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the weights and ``info`` (``torch.save``, atomically)."""
        import torch

        from graspgait_env.atomic import atomic_write

        return atomic_write(path, lambda fh: torch.save(
            {"state_dict": self.net.state_dict(), "info": self.info}, fh))

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> BCPolicy:
        """Read a policy written by :meth:`save`."""
        import torch

        blob = torch.load(path, weights_only=True)
        info = blob["info"]
        net = _mlp(int(info["obs_dim"]), int(info["n_actions"]), tuple(info["hidden"]))
        net.load_state_dict(blob["state_dict"])
        net.eval()
        return cls(net, info)


def _mlp(obs_dim: int, n_actions: int, hidden: tuple[int, ...]) -> Any:
    from torch import nn

    layers: list[Any] = []
    width = obs_dim
    for h in hidden:
        layers += [nn.Linear(width, h), nn.ReLU()]
        width = h
    layers.append(nn.Linear(width, n_actions))
    return nn.Sequential(*layers)


def train_bc(dataset: Any, *, seed: int = 0, epochs: int = 20, batch_size: int = 256,
             lr: float = 1e-3, hidden: tuple[int, ...] = (256, 256),
             max_steps: int | None = None,
             log: Callable[[int, float], None] | None = None) -> BCPolicy:
    """Behaviour cloning on a dataset (an id or a ``MinariDataset``; module docstring).

    Parameters
    ----------
    seed
        Seeds torch (weights) and the batch order.
    epochs, batch_size, lr, hidden
        The training loop's settings.
    max_steps
        Stop after this many gradient steps (tests).
    log
        Called with ``(step, loss)`` after every step.
    """
    import torch

    torch.set_num_threads(1)
    ds = _load(dataset)
    X, y, masks = load_demonstrations(ds)
    if not masks[np.arange(len(y)), y].all():
        raise GraspGaitInputError(f"dataset {ds.id}: an action outside the observation's "
                                  "legal-move mask; not a dataset of this env")
    torch.manual_seed(int(seed))
    rng = np.random.default_rng(int(seed))
    net = _mlp(X.shape[1], masks.shape[1], tuple(hidden))
    opt = torch.optim.Adam(net.parameters(), lr=float(lr))
    Xt, yt, Mt = torch.as_tensor(X), torch.as_tensor(y), torch.as_tensor(masks)
    step, loss_v, t0 = 0, float("nan"), time.perf_counter()
    for _ in range(int(epochs)):
        for idx in np.array_split(rng.permutation(len(y)), max(1, -(-len(y) // batch_size))):
            i = torch.as_tensor(idx)
            z = net(Xt[i]).masked_fill(~Mt[i], float("-inf"))
            loss = torch.nn.functional.cross_entropy(z, yt[i])
            opt.zero_grad()
            loss.backward()
            opt.step()
            step += 1
            loss_v = float(loss.item())
            if log is not None:
                log(step, loss_v)
            if max_steps is not None and step >= max_steps:
                break
        if max_steps is not None and step >= max_steps:
            break
    net.eval()
    info = {"dataset": ds.id, "transitions": int(len(y)), "episodes": int(ds.total_episodes),
            "obs_dim": int(X.shape[1]), "n_actions": int(masks.shape[1]),
            "hidden": list(hidden), "epochs": int(epochs), "batch_size": int(batch_size),
            "lr": float(lr), "steps": step, "seed": int(seed), "final_loss": loss_v,
            "train_wall_s": time.perf_counter() - t0}
    return BCPolicy(net, info)


def bc_policy_for(task: Task, demo: str, seed: int, workdir: str | Path,
                  train_kwargs: Mapping[str, Any] | None = None) -> Any:
    """The benchmark's ``bc:DEMO`` policy for (task, seed): cloned from the demonstrations
    of the task's training task (kept in ``workdir/bc/TASK/sSEED.pt``)."""
    from graspgait_env.benchmark.policies import CellPolicy

    train_task = get_task(task.train_task) if task.train_task else task
    path = Path(workdir) / "bc" / train_task.id / f"s{int(seed)}.pt"
    if path.is_file():
        bc = BCPolicy.load(path)
    else:
        bc = train_bc(dataset_id(train_task.id, demo), seed=seed, **dict(train_kwargs or {}))
        bc.save(path)
    return CellPolicy({}, (), lambda env: bc.predict, {**bc.info, "demonstrations": demo},
                      (int(bc.info["obs_dim"]),))
