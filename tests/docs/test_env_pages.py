"""The env pages say everything about their env (docs/_scripts/gen_pages.py).

One page per registered id, with Gymnasium's sections; its Observation Space table gives
every part of the env's ``ObservationLayout`` with its index range (defaults, and each
opt-in field), its Rewards table every term of ``REWARD_TERMS`` with its default weight,
its Arguments every field of ``GraspGaitConfig``. These tests compute the same facts
from the envs themselves and look for them on the pages.
"""

from __future__ import annotations

import logging
import re
from dataclasses import fields

import gymnasium as gym
import pytest

import graspgait_env  # noqa: F401  (registers the ids)
from graspgait_env.envs.config import GraspGaitConfig
from graspgait_env.envs.map_env import REWARD_TERMS
from graspgait_env.envs.registration import ENV_IDS

SECTIONS = ("Description", "Action Space", "Observation Space", "Rewards", "Starting State",
            "Episode End", "Arguments", "Version History")


@pytest.fixture(scope="module")
def pages(gen) -> dict[str, str]:
    return {env_id: gen.env_page(env_id) for env_id in ENV_IDS}


def _section(page: str, title: str) -> str:
    m = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", page, flags=re.S | re.M)
    assert m, f"no section {title!r}"
    return m.group(1)


def _rows(text: str) -> dict[str, list[str]]:
    """The rows of the tables in ``text`` by their first cell (backticks stripped)."""
    out = {}
    for line in text.splitlines():
        if line.startswith("| `"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            out.setdefault(cells[0].strip("`"), cells)
    return out


def _span(part) -> str:
    if isinstance(part, int):
        return str(part)
    if part.stop <= part.start:
        return "-"
    return str(part.start) if part.stop - part.start == 1 else f"{part.start} .. {part.stop - 1}"


def test_every_registered_id_has_a_page_in_the_nav(gen) -> None:
    config = {"nav": [{"Environments": ["envs/index.md"]}, {"API reference": []}]}
    env_nav = gen.on_config(config)["nav"][0]["Environments"]
    assert [next(iter(e)) for e in env_nav[1:]] == list(ENV_IDS)
    assert all(e[i] == f"envs/{i}.md" for e in env_nav[1:] for i in e)


@pytest.mark.parametrize("env_id", list(ENV_IDS))
def test_the_page_has_gymnasiums_sections(pages: dict[str, str], env_id: str) -> None:
    page = pages[env_id]
    assert page.startswith(f"# {env_id}\n")
    heads = re.findall(r"^## (.+)$", page, flags=re.M)
    assert [h for h in heads if h in SECTIONS] == list(SECTIONS), heads


@pytest.mark.parametrize("env_id", list(ENV_IDS))
def test_arguments_cover_every_config_field(pages: dict[str, str], env_id: str) -> None:
    rows = _rows(_section(pages[env_id], "Arguments"))
    env = gym.make(env_id).unwrapped
    missing = [f.name for f in fields(GraspGaitConfig) if f.name not in rows]
    assert not missing, f"GraspGaitConfig fields missing from the {env_id} page: {missing}"
    for f in fields(GraspGaitConfig):
        assert rows[f.name][1] == f"`{getattr(env.config, f.name)!r}`", (env_id, f.name)
        assert rows[f.name][2], f"{env_id}: field {f.name} has no description"


@pytest.mark.parametrize("env_id", list(ENV_IDS))
def test_rewards_give_every_term_with_its_default_weight(pages: dict[str, str],
                                                         env_id: str) -> None:
    rows = _rows(_section(pages[env_id], "Rewards"))
    missing = [t for t in REWARD_TERMS if t not in rows]
    assert not missing, f"reward terms missing from the {env_id} page: {missing}"
    cfg = gym.make(env_id).unwrapped.config
    weights = {"turn": "alpha", "regrasp": "beta", "rotation": "gamma",
               "success": "success_bonus", "dead_end": "dead_end_penalty",
               "illegal": "illegal_penalty"}
    assert set(weights) == set(REWARD_TERMS)
    for term, name in weights.items():
        assert f"`{name}` = `{getattr(cfg, name)!r}`" in rows[term][2], (env_id, term)


@pytest.mark.parametrize("env_id", list(ENV_IDS))
def test_observation_table_gives_every_part_with_its_indices(gen, pages: dict[str, str],
                                                             env_id: str) -> None:
    section = _section(pages[env_id], "Observation Space")
    box, _, named = section.partition("**Named parts.**")
    rows = _rows(box)
    env = gym.make(env_id).unwrapped
    assert f"Length **{env.observation_space.shape[0]}** with the defaults" in section
    every = gym.make(env_id, **{f: v for f, v in gen.OPT_IN_PARTS.values()}).unwrapped
    parts = list(env.layout.box_parts)
    # every slice of the layout is a part, and the parts tile the vector in order
    assert {k for k, v in vars(env.layout).items() if isinstance(v, slice)} <= set(parts)
    assert parts == list(rows), (parts, list(rows))
    for part in parts:
        default = _span(getattr(env.layout, part))
        if part in gen.OPT_IN_PARTS:
            field, value = gen.OPT_IN_PARTS[part]
            alone = gym.make(env_id, **{field: value}).unwrapped
            assert default == "-" and rows[part][1] == "-"
            assert rows[part][2] == f"{_span(getattr(alone.layout, part))} (`{field}={value!r}`)"
        else:
            assert rows[part][1] == default, (env_id, part)
        assert rows[part][3] == _span(getattr(every.layout, part)), (env_id, part)
        assert rows[part][6], f"{env_id}: part {part} has no description"


@pytest.mark.parametrize("env_id", list(ENV_IDS))
def test_named_parts_table_gives_each_part_its_shape_and_flat_index(
        gen, pages: dict[str, str], env_id: str) -> None:
    section = _section(pages[env_id], "Observation Space")
    named = section.partition("**Named parts.**")[2]
    rows = _rows(named)
    env = gym.make(env_id, observation_mode="dict").unwrapped
    every = gym.make(env_id, observation_mode="dict",
                     **{f: v for f, v in gen.OPT_IN_PARTS.values()}).unwrapped
    assert list(rows) == list(every.observation_space)
    for name, (sl, shape) in every.layout.parts.items():
        assert every.observation_space[name].shape == shape
        assert rows[name][2] == f"`{shape}`, {_span(sl)}", (env_id, name)
        if name in env.layout.parts:
            own_sl, own_shape = env.layout.parts[name]
            assert env.observation_space[name].shape == own_shape
            assert rows[name][1] == f"`{own_shape}`, {_span(own_sl)}", (env_id, name)
    assert f"flattened, {env.layout.flat_size} entries with the defaults" in named
    for feature in every.layout.action_features:
        assert f"`{feature}`" in named


def test_the_pages_generate_without_warnings(gen, caplog: pytest.LogCaptureFixture) -> None:
    """A warning of the generator (a part, a term or a field it cannot place) fails the
    strict build; here it fails at once, naming what is missing."""
    with caplog.at_level(logging.WARNING):
        for env_id in ENV_IDS:
            gen.env_page(env_id)
    assert not caplog.records, [r.getMessage() for r in caplog.records]
