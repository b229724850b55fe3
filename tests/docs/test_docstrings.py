"""The public API is documented: every public module (no part of its name starts with
``_``) has a docstring, and so has every function and class of its ``__all__`` and every
public method and property of those classes (a method that overrides a documented one
inherits its docstring). The API reference of the site renders exactly these."""

from __future__ import annotations

import importlib
import inspect

import pytest


def _undocumented(apiref) -> list[str]:
    missing = []
    for name in apiref.public_modules():
        mod = importlib.import_module(name)
        if not (mod.__doc__ or "").strip():
            missing.append(f"module {name}")
        own, _ = apiref.module_members(name)
        for n in own:
            obj = getattr(mod, n)
            if not (inspect.isclass(obj) or inspect.isfunction(obj)):
                continue
            if not (obj.__doc__ or "").strip():
                missing.append(f"{name}.{n}")
            if not inspect.isclass(obj):
                continue
            for m, v in vars(obj).items():
                if m.startswith("_"):
                    continue
                if isinstance(v, property):  # an override inherits its base's docstring
                    doc = v.__doc__ or next((getattr(b, m).__doc__ for b in obj.__mro__[1:]
                                             if isinstance(vars(b).get(m), property)), None)
                elif isinstance(v, (classmethod, staticmethod)) or inspect.isfunction(v):
                    doc = inspect.getdoc(getattr(obj, m))
                else:
                    continue
                if not (doc or "").strip():
                    missing.append(f"{name}.{n}.{m}")
    return missing


def test_every_public_function_and_class_has_a_docstring(apiref) -> None:
    missing = _undocumented(apiref)
    assert not missing, f"public API without a docstring: {missing}"


def test_the_public_modules_include_the_installed_folders(apiref) -> None:
    mods = apiref.public_modules()
    for name in ("graspgait_env.envs.map_env", "graspgait_env.agents.card",
                 "graspgait_env.baselines.policies", "graspgait_env.planners.exact"):
        assert name in mods
    assert not [m for m in mods if any(p.startswith("_") for p in m.split("."))]


@pytest.mark.parametrize(("target", "module", "expected"), [
    ("~graspgait_env.gait.GaitModel", "graspgait_env.envs.map_env",
     "graspgait_env.gait.GaitModel"),
    ("GaitModel.action_mask", "graspgait_env.envs.map_env",
     "graspgait_env.gait.GaitModel.action_mask"),
    ("state_from_observation", "graspgait_env.envs.map_env",
     "graspgait_env.envs.map_env.state_from_observation"),
])
def test_roles_resolve_to_the_documented_object(apiref, target, module, expected) -> None:
    assert apiref.resolve(target, module) == (expected, True)


def test_a_role_naming_nothing_stays_a_cross_reference_that_breaks_the_build(apiref) -> None:
    md = apiref.roles_to_markdown(":func:`no_such_function_anywhere`",
                                  "graspgait_env.envs.map_env")
    assert md == "[`no_such_function_anywhere()`][no_such_function_anywhere]"
    # private helpers and other libraries are inline code, not links
    assert apiref.roles_to_markdown(":func:`time.perf_counter`", "graspgait_env.timing") == \
        "`time.perf_counter()`"
