"""mkdocs hook: the pages generated from the code at every build.

- ``envs/ID.md``, one page per registered id (``graspgait_env.envs.registration.ENV_IDS``),
  from the env class's docstring (its ``## Description``, ``## Action Space``, ...
  sections; a section the class leaves out is its base class's). The tables of those
  pages are computed: the *Observation Space* table gives every part's index range
  from the env's own :class:`ObservationLayout`, with the defaults and with each opt-in
  field (its rows' wording is the docstring table's); the *Rewards* table gives every
  term of ``REWARD_TERMS`` with the docstring's formula and the default of each weight
  it names; *Arguments* lists every ``GraspGaitConfig`` field by group
  (:data:`ARGUMENT_GROUPS`) with the env's default and the field's docstring.
- ``api/MODULE.md``, one page per public module (``apiref.public_modules``), rendered by
  mkdocstrings, and ``api/index.md``, the list of them.
- ``changelog.md``, the repository's ``CHANGELOG.md``.

Anything these pages cannot say (a part of the observation without a row in the
docstring's table, a reward term without a row, a config field in no group) is logged as
a warning, which fails the strict build (``mkdocs build --strict``, ``make docs``).
``tests/docs`` imports this module to check the pages.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import logging
import re
import sys
from dataclasses import fields
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
import apiref  # noqa: E402

log = logging.getLogger("mkdocs.plugins.graspgait_pages")
ROOT = apiref.ROOT

# Gymnasium's sections of an env page, in order; other sections of a docstring (Info,
# Pickling) come after Episode End
SECTIONS = ("Description", "Action Space", "Observation Space", "Rewards", "Starting State",
            "Episode End", "Arguments", "Version History")

# The GraspGaitConfig fields by what they set, for the Arguments table. A field in no
# group is missing from the env pages (a warning, and tests/docs/test_env_pages.py fails).
ARGUMENT_GROUPS: dict[str, tuple[str, ...]] = {
    "The task": ("hand", "turn_deg", "n", "max_backward_deg", "contact_model"),
    "Reward weights (see *Rewards*)": ("alpha", "beta", "gamma", "turn_scale_deg",
                                       "success_bonus", "dead_end_penalty",
                                       "illegal_penalty", "to_go_weight"),
    "The observation (see *Observation Space*)": ("map_window_deg", "map_window_cells",
                                                  "map_lines", "rotation_lookahead",
                                                  "regrasp_lookahead", "observation_mode"),
    "Move rules beyond the thesis (see *Action Space*)": ("forbid_reversal",
                                                          "forbid_revisit"),
}

# The opt-in observation fields: the layout part each appends, and the value that
# turns it on in the tables (the reach look-ahead's depth D = 3, the env's example
# value)
OPT_IN_PARTS: dict[str, tuple[str, Any]] = {
    "lines": ("map_lines", True),
    "lookahead": ("rotation_lookahead", True),
    "reach": ("regrasp_lookahead", 3),
}


# ----------------------------------------------------------------------- helpers
def _env_class(env_id: str) -> type:
    from graspgait_env.envs.registration import ENV_IDS

    module, name = ENV_IDS[env_id].split(":")
    return getattr(importlib.import_module(module), name)


def _sections(cls: type) -> tuple[str, dict[str, tuple[str, type]]]:
    """The summary and the ``## `` sections of ``cls``'s docstring, each with the class
    whose docstring holds it (a section ``cls`` leaves out is its nearest base's)."""
    out: dict[str, tuple[str, type]] = {}
    summary = ""
    for klass in cls.__mro__:
        doc = klass.__dict__.get("__doc__")
        if not doc or not klass.__module__.startswith(apiref.PACKAGE):
            continue
        parts = re.split(r"^## +(.+?)\s*$", inspect.cleandoc(doc), flags=re.M)
        if klass is cls:
            summary = parts[0].strip()
        for title, body in zip(parts[1::2], parts[2::2], strict=True):
            out.setdefault(title, (body.strip(), klass))
    return summary, out


def _md(text: str, klass: type) -> str:
    return apiref.rst_to_markdown(text, klass.__module__,
                                  f"{klass.__module__}.{klass.__qualname__}")


def _split_table(text: str) -> tuple[str, list[list[str]], str]:
    """``(before, rows, after)``: the first Markdown table of ``text`` (continuation
    rows joined, the header row first, the separator row left out)."""
    lines = apiref.join_table_rows(text).split("\n")
    idx = [i for i, ln in enumerate(lines) if ln.strip().startswith("|")]
    if not idx:
        return text, [], ""
    first = idx[0]
    last = first
    while last + 1 < len(lines) and lines[last + 1].strip().startswith("|"):
        last += 1
    rows = [[c.strip() for c in ln.strip().strip("|").split("|")]
            for ln in lines[first:last + 1]]
    rows = [r for r in rows if not all(re.fullmatch(r":?-+:?", c) for c in r)]
    return "\n".join(lines[:first]), rows, "\n".join(lines[last + 1:])


def _table(header: list[str], rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def _span(part: slice | int) -> str:
    """Inclusive index range of a layout part, ``-`` when empty."""
    if isinstance(part, int):
        return str(part)
    if part.stop <= part.start:
        return "-"
    return str(part.start) if part.stop - part.start == 1 else f"{part.start} .. {part.stop - 1}"


def _length(part: slice | int) -> int:
    return 1 if isinstance(part, int) else max(0, part.stop - part.start)


def _bounds(env: Any, part: slice | int) -> str:
    if _length(part) == 0:
        return "-"
    sl = part if isinstance(part, slice) else slice(part, part + 1)
    lo, hi = env.observation_space.low[sl], env.observation_space.high[sl]
    return f"[{float(lo.min()):.4g}, {float(hi.max()):.4g}]"


def layout_parts(layout: Any) -> list[str]:
    """The parts of an :class:`ObservationLayout`'s box vector, in index order."""
    return list(layout.box_parts)


def _code(value: Any) -> str:
    return f"`{value!r}`".replace("|", "\\|")


def config_field_docs() -> dict[str, str]:
    """Each GraspGaitConfig field's docstring (the string under it in the class body)."""
    from graspgait_env.envs import config

    tree = ast.parse(Path(config.__file__).read_text(encoding="utf-8"))
    cls = next(n for n in tree.body if isinstance(n, ast.ClassDef)
               and n.name == "GraspGaitConfig")
    out = {}
    for a, b in zip(cls.body, cls.body[1:], strict=False):
        if (isinstance(a, ast.AnnAssign) and isinstance(a.target, ast.Name)
                and isinstance(b, ast.Expr) and isinstance(b.value, ast.Constant)
                and isinstance(b.value.value, str)):
            out[a.target.id] = inspect.cleandoc(b.value.value)
    return out


# ----------------------------------------------------------------------- env pages
def _make(cls: type, **kw: Any) -> Any:
    env = cls(**kw)
    env.close()
    return env


def observation_table(env_id: str, rows: list[list[str]]) -> str:
    """The *Observation Space* table of ``env_id``: every part of its layout with its
    index range with the defaults, with each opt-in field alone and with every opt-in
    field, its bounds, and the wording of the docstring table's row for it (``rows``:
    header first)."""
    cls = _env_class(env_id)
    base = _make(cls)
    alone = {p: _make(cls, **{f: v}) for p, (f, v) in OPT_IN_PARTS.items()}
    every = _make(cls, **{f: v for f, v in OPT_IN_PARTS.values()})
    parts = layout_parts(base.layout)
    body = rows[1:]
    if len(body) != len(parts):
        log.warning("%s: the Observation Space table of the docstring has %d rows for the "
                    "%d parts of ObservationLayout (%s)", env_id, len(body), len(parts),
                    ", ".join(parts))
    col = {name.lower(): i for i, name in enumerate(rows[0])}
    what = col.get("observation", 1)
    out = []
    for k, part in enumerate(parts):
        text = body[k][what] if k < len(body) else ""
        own = ""
        if part in OPT_IN_PARTS:
            field, value = OPT_IN_PARTS[part]
            env = alone[part]
            default = "-"
            own = f"{_span(getattr(env.layout, part))} (`{field}={value!r}`)"
            n = _length(getattr(env.layout, part))
            bounds = _bounds(env, getattr(env.layout, part))
        elif _length(getattr(base.layout, part)) == 0:
            log.warning("%s: the observation part %r is empty by default and no opt-in "
                        "field in OPT_IN_PARTS appends it", env_id, part)
            default, n, bounds = "-", 0, "-"
        else:
            default = _span(getattr(base.layout, part))
            n = _length(getattr(base.layout, part))
            bounds = _bounds(base, getattr(base.layout, part))
        out.append([f"`{part}`", default, own, _span(getattr(every.layout, part)), str(n),
                    bounds, text])
    table = _table(["Part (`env.layout.`)", "Index (defaults)", "Index (the field alone)",
                    "Index (every opt-in field)", "Entries", "Bounds", "Observation"], out)
    fields_on = ", ".join(f"`{f}={v!r}`" for f, v in OPT_IN_PARTS.values())
    return (f"Length **{base.layout.size}** with the defaults"
            + "".join(f"; {alone[p].layout.size} with `{f}={v!r}`"
                      for p, (f, v) in OPT_IN_PARTS.items())
            + f"; {every.layout.size} with every opt-in field ({fields_on}). "
            "The indices below are computed from the env's `ObservationLayout` "
            f"(`env.layout`) at `n = {base.config.n}` with the default hand "
            f"({base.action_space.n} actions) and `map_window_cells = "
            f"{base.config.map_window_cells}`; an opt-in part is appended after the "
            "grasp-map window, in the order of the table.\n\n" + table)


def _space_bounds(space: Any) -> str:
    return f"[{float(space.low.min()):.4g}, {float(space.high.max()):.4g}]"


def named_parts_table(env_id: str) -> str:
    """The named parts of ``observation_mode="dict"`` (and their place in the
    ``"flat"`` vector) with the defaults and with every opt-in field, then the columns
    of the ``actions`` part, all from the env's ``ObservationLayout``."""
    from graspgait_env.envs.observation import ACTION_FEATURES

    cls = _env_class(env_id)
    base = _make(cls, observation_mode="dict")
    every = _make(cls, observation_mode="dict", **{f: v for f, v in OPT_IN_PARTS.values()})
    rows = []
    for name, (sl, shape) in every.layout.parts.items():
        own = base.layout.parts.get(name)
        rows.append([f"`{name}`",
                     f"`{own[1]}`, {_span(own[0])}" if own else "-",
                     f"`{shape}`, {_span(sl)}",
                     _space_bounds(base.observation_space[name]) if own
                     else _space_bounds(every.observation_space[name])])
    table = _table(["Part", "Shape, flat index (defaults)",
                    "Shape, flat index (every opt-in field)", "Bounds"], rows)
    extra = [c for c in every.layout.action_features if c not in ACTION_FEATURES]
    return ("With `observation_mode=\"dict\"` the observation is a `Dict` of these parts "
            "(`env.layout.parts`); with `observation_mode=\"flat\"` it is that dict "
            f"flattened, {base.layout.flat_size} entries with the defaults and "
            f"{every.layout.flat_size} with every opt-in field, each part at the flat "
            "index given:\n\n" + table + "\n\nThe columns of `actions` "
            "(`env.layout.action_features`, thesis 5.2 for rotations and 4.2 for "
            "regrasps; [`graspgait_env.envs.observation`][graspgait_env.envs.observation] "
            "defines each): "
            + ", ".join(f"`{c}`" for c in ACTION_FEATURES)
            + ", then, where those fields are on, " + ", ".join(f"`{c}`" for c in extra)
            + " (`rotation_lookahead`, `regrasp_lookahead = 3`).")


def rewards_table(env_id: str, rows: list[list[str]]) -> str:
    """The *Rewards* table of ``env_id``: every term of ``REWARD_TERMS`` with the
    docstring's formula and each weight it names with the env's default."""
    from graspgait_env.envs.map_env import REWARD_TERMS

    env = _make(_env_class(env_id))
    names = [f.name for f in fields(env.config)]
    by_term = {r[0].strip("`"): r[1] for r in rows[1:] if r}
    out = []
    for term in REWARD_TERMS:
        formula = by_term.get(term)
        if formula is None:
            log.warning("%s: reward term %r has no row in the Rewards table of the "
                        "docstring", env_id, term)
            formula = ""
        weights = [n for n in names if re.search(rf"(?<![\w.]){n}(?!\w)", formula)]
        if not weights:
            log.warning("%s: the formula of reward term %r names no GraspGaitConfig "
                        "field", env_id, term)
        out.append([f"`{term}`", formula,
                    "; ".join(f"`{w}` = {_code(getattr(env.config, w))}" for w in weights)])
    extra = sorted(set(by_term) - set(REWARD_TERMS))
    if extra:
        log.warning("%s: the Rewards table has rows for no reward term: %s", env_id, extra)
    return _table(["Term (`info[\"reward_terms\"]`)", "Value", "Default weight"], out)


def arguments_table(env_id: str) -> str:
    """The env's own keyword arguments, then every GraspGaitConfig field by group, with
    the env's default and the field's docstring."""
    cls = _env_class(env_id)
    env = _make(cls)
    docs = config_field_docs()
    sig = inspect.signature(cls.__init__)
    own = [[f"`{p.name}`", _code(p.default) if p.default is not p.empty else "(required)"]
           for p in sig.parameters.values()
           if p.name != "self" and p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)]
    text = ["The keyword arguments of `gymnasium.make(\"graspgait_env:" + env_id + "\", ...)`:",
            "", _table(["Argument", "Default"], own), "",
            "and every field of [`GraspGaitConfig`][graspgait_env.envs.config.GraspGaitConfig] "
            "(as keywords or as `config=GraspGaitConfig(...)`), with this env's defaults:"]
    grouped = [f for g in ARGUMENT_GROUPS.values() for f in g]
    unknown = sorted(set(grouped) - set(docs))
    if unknown:
        log.warning("ARGUMENT_GROUPS names %s, which GraspGaitConfig has not", unknown)
    missing = [f.name for f in fields(env.config) if f.name not in grouped]
    if missing:
        log.warning("GraspGaitConfig fields in no group of ARGUMENT_GROUPS (so on no env "
                    "page): %s", missing)
    for title, group in ARGUMENT_GROUPS.items():
        rows = [[f"`{f}`", _code(getattr(env.config, f)),
                 " ".join(apiref.rst_to_markdown(docs.get(f, ""),
                                                 "graspgait_env.envs.config").split())]
                for f in group if f in docs]
        text += ["", f"**{title}**", "", _table(["Field", "Default", "Meaning"], rows)]
    return "\n".join(text)


def env_page(env_id: str) -> str:
    """The Markdown page of a registered id (see the module docstring)."""
    from graspgait_env.envs.registration import (
        ENV_IDS,
        MAX_EPISODE_STEPS,
        VECTOR_ENTRY_POINTS,
    )

    cls = _env_class(env_id)
    summary, sections = _sections(cls)
    env = _make(cls)
    path = f"{cls.__module__}.{cls.__qualname__}"
    facts = [["Make", f'`gym.make("graspgait_env:{env_id}")`'],
             ["Class", f"[`{cls.__name__}`][{path}]"],
             ["Action space", f"`Discrete({env.action_space.n})`"],
             ["Observation space", f"`Box(float32, ({env.observation_space.shape[0]},))` "
                                   "with the defaults"],
             ["Reward terms", ", ".join(f"`{t}`" for t in _reward_terms())],
             ["Time limit", f"{MAX_EPISODE_STEPS} steps (`max_episode_steps`)"],
             ["Batched", "`gymnasium.make_vec(..., vectorization_mode=\"vector_entry_point\")`"
              if env_id in VECTOR_ENTRY_POINTS else "Gymnasium's `sync` or `async` vector envs"],
             ["Entry point", f"`{ENV_IDS[env_id]}`"]]
    out = [f"# {env_id}", "", _md(summary, cls), "",
           _table(["Registered version", f"`graspgait_env:{env_id}`"], facts), "",
           "```python", "import gymnasium as gym", "",
           "import graspgait_env  # registers the ids", "",
           f'env = gym.make("graspgait_env:{env_id}")',
           "obs, info = env.reset(seed=0)", "```", "",
           "This page is generated from the class docstring "
           f"([`{cls.__name__}`][{path}]) at every build of the site."]
    order = list(SECTIONS[:6]) + [s for s in sections if s not in SECTIONS] + list(SECTIONS[6:])
    for title in order:
        if title not in sections:
            log.warning("%s: no %r section in the docstring of %s or its bases", env_id,
                        title, cls.__name__)
            continue
        body, owner = sections[title]
        if title == "Observation Space":
            body = _observation_section(env_id, body, owner, cls)
        elif title == "Rewards":
            body = _rewards_section(env_id, body, owner, cls)
        else:
            body = _md(body, owner)
        if title == "Arguments":
            body += "\n\n" + arguments_table(env_id)
        if owner is not cls:
            body = (f"As [`{owner.__name__}`][{owner.__module__}.{owner.__qualname__}]:\n\n"
                    + body)
        out += ["", f"## {title}", "", body]
    return "\n".join(out) + "\n"


def _reward_terms() -> tuple[str, ...]:
    from graspgait_env.envs.map_env import REWARD_TERMS

    return REWARD_TERMS


def _table_source(cls: type, title: str) -> list[list[str]]:
    """The first table of section ``title`` in the docstrings of ``cls`` and its bases."""
    for klass in cls.__mro__:
        doc = klass.__dict__.get("__doc__")
        if not doc:
            continue
        parts = re.split(r"^## +(.+?)\s*$", inspect.cleandoc(doc), flags=re.M)
        for t, body in zip(parts[1::2], parts[2::2], strict=True):
            if t == title:
                _, rows, _ = _split_table(_md(body, klass))
                if rows:
                    return rows
    return []


def _observation_section(env_id: str, body: str, owner: type, cls: type) -> str:
    before, rows, after = _split_table(_md(body, owner))
    named = "**Named parts.** " + named_parts_table(env_id)
    if not rows:  # the section refers to GraspGait-v0's: the table comes from there
        rows = _table_source(cls, "Observation Space")
        return (before.rstrip() + "\n\n" + observation_table(env_id, rows) + "\n\n"
                + named)
    return (before.rstrip() + "\n\n" + observation_table(env_id, rows) + "\n\n"
            + after.strip() + "\n\n" + named)


def _rewards_section(env_id: str, body: str, owner: type, cls: type) -> str:
    before, rows, after = _split_table(_md(body, owner))
    if not rows:
        rows = _table_source(cls, "Rewards")
        return before.rstrip() + "\n\n" + rewards_table(env_id, rows)
    return before.rstrip() + "\n\n" + rewards_table(env_id, rows) + "\n\n" + after.strip()


# ----------------------------------------------------------------------- API pages
API_GROUPS = (  # nav sections of the API reference, by module prefix (the first match)
    ("Environments", "graspgait_env.envs"),
    ("Planners", "graspgait_env.planners"),
    ("MuJoCo hand", "graspgait_env.sim"),
    ("Agents", "graspgait_env.agents"),
    ("Baselines", "graspgait_env.baselines"),
    ("Bundled configs", "graspgait_env.configs"),
    ("Benchmark", "graspgait_env.benchmark"),
    ("Core", "graspgait_env"),
)


# the order of the API reference's sections: the core first
API_ORDER = ("Core", "Environments", "Planners", "MuJoCo hand", "Baselines", "Agents",
             "Benchmark", "Bundled configs")
assert {t for t, _ in API_GROUPS} == set(API_ORDER)


def api_group(module: str) -> str:
    return next(title for title, prefix in API_GROUPS
                if module == prefix or module.startswith(prefix + "."))


def api_page(module: str) -> str:
    """One module's reference page: its docstring and the names of its ``__all__`` it
    defines (mkdocstrings), then links to the names it re-exports."""
    own, again = apiref.module_members(module)
    opts = ("      members: [" + ", ".join(own) + "]") if own else "      members: false"
    out = [f"::: {module}", "    options:", opts, ""]
    if again:
        out += ["**Re-exported here** (documented where they are defined):", ""]
        out += [f"- [`{name}`][{path}]" for name, path in again]
    return "\n".join(out) + "\n"


def api_index() -> str:
    out = ["# API reference", "",
           "The public API: the names in the `__all__` of each public module, with their "
           "docstrings. Cross-references in the docstrings link here; the environments' "
           "documentation pages are under [Environments](../envs/index.md).", ""]
    for title in API_ORDER:
        mods = [m for m in apiref.public_modules() if api_group(m) == title]
        out += [f"## {title}", "", "| module | what it is |", "|---|---|"]
        for m in mods:
            doc = inspect.getdoc(importlib.import_module(m)) or ""
            first = " ".join(doc.split("\n\n")[0].split())
            first = apiref.roles_to_markdown(first, m).replace("|", "\\|")
            out.append(f"| [`{m}`]({m}.md) | {first} |")
        out.append("")
    return "\n".join(out)


# ----------------------------------------------------------------------- the hooks
def on_config(config: Any, **kwargs: Any) -> Any:
    """Put the generated pages in the nav."""
    from graspgait_env.envs.registration import ENV_IDS

    for item in config["nav"] or []:
        if not isinstance(item, dict):
            continue
        (title, entries), = item.items()
        if title == "Environments":
            entries += [{i: f"envs/{i}.md"} for i in ENV_IDS]
        elif title == "API reference":
            for group in API_ORDER:
                mods = [m for m in apiref.public_modules() if api_group(m) == group]
                entries.append({group: [{m: f"api/{m}.md"} for m in mods]})
    return config


def on_files(files: Any, config: Any, **kwargs: Any) -> Any:
    """Add the generated pages (env pages, API pages, the changelog)."""
    from mkdocs.structure.files import File

    from graspgait_env.envs.registration import ENV_IDS

    for env_id in ENV_IDS:
        files.append(File.generated(config, f"envs/{env_id}.md", content=env_page(env_id)))
    files.append(File.generated(config, "api/index.md", content=api_index()))
    for m in apiref.public_modules():
        files.append(File.generated(config, f"api/{m}.md", content=api_page(m)))
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    files.append(File.generated(config, "changelog.md", content=changelog))
    return files
