"""What the API reference documents, and how a docstring's cross-references resolve.

Shared by the mkdocs hook (``gen_pages.py``, which writes one page per public module) and
the griffe extension (``griffe_roles.py``, which turns the Sphinx roles of the docstrings,
``:class:`~graspgait_env.gait.GaitModel```, into mkdocstrings cross-references).

The public API is the ``__all__`` of each public module (no part of its dotted name
starts with ``_``) of ``graspgait_env``, its subpackages included
(``graspgait_env.agents``, ``graspgait_env.baselines``, ``graspgait_env.configs``).
A module's page documents the names of its ``__all__`` that it defines; the names it
re-exports link to the module that defines them.
"""

from __future__ import annotations

import builtins
import functools
import importlib
import inspect
import pkgutil
import re
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = "graspgait_env"


@functools.lru_cache(maxsize=1)
def public_modules() -> tuple[str, ...]:
    """Every public module of the package, its subpackages included, sorted."""
    out = {PACKAGE}
    mod = importlib.import_module(PACKAGE)
    for info in pkgutil.walk_packages(mod.__path__, PACKAGE + "."):
        if not any(p.startswith("_") for p in info.name.split(".")):
            out.add(info.name)
    return tuple(sorted(out))


def defined_in(obj: Any, module: str) -> bool:
    """Whether ``obj`` (a class or function) is defined in ``module``; other values
    (constants) count as defined where they are listed."""
    home = getattr(obj, "__module__", None)
    if inspect.isclass(obj) or inspect.isfunction(obj) or inspect.isbuiltin(obj):
        return home == module
    return True


def module_members(name: str) -> tuple[list[str], list[tuple[str, str]]]:
    """The ``__all__`` of module ``name`` split into the names it defines (documented on
    its page) and the names it re-exports, each with the path of its definition."""
    mod = importlib.import_module(name)
    own, again = [], []
    for n in getattr(mod, "__all__", ()):
        obj = getattr(mod, n)
        if defined_in(obj, name):
            own.append(n)
        else:
            again.append((n, canonical(obj) or f"{name}.{n}"))
    return own, again


def canonical(obj: Any) -> str | None:
    """The dotted path of the definition of a module, class or function."""
    if isinstance(obj, ModuleType):
        return obj.__name__
    if isinstance(obj, (classmethod, staticmethod)):
        obj = obj.__func__
    if isinstance(obj, property):
        obj = obj.fget
    mod, qual = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    if mod and qual and "<" not in qual:
        return f"{mod}.{qual}"
    return None


@functools.lru_cache(maxsize=1)
def documented() -> frozenset[str]:
    """The dotted paths the API reference renders: the public modules, the names each
    defines in its ``__all__``, and the public members of those classes."""
    out: set[str] = set()
    for name in public_modules():
        out.add(name)
        mod = importlib.import_module(name)
        own, _ = module_members(name)
        for n in own:
            out.add(f"{name}.{n}")
            obj = getattr(mod, n)
            if inspect.isclass(obj):
                for m in _public_class_members(obj):
                    out.add(f"{name}.{n}.{m}")
    return frozenset(out)


def _public_class_members(cls: type) -> list[str]:
    """Members defined in the class body that the reference shows (not inherited, not
    private, not set on the class from outside its body)."""
    try:
        src = inspect.getsource(cls)
    except (OSError, TypeError):
        src = ""
    out = []
    for m, v in vars(cls).items():
        if m.startswith("_"):
            continue
        if re.search(rf"^\s+(?:def\s+{m}\b|{m}\s*[:=])", src, flags=re.M):
            out.append(m)
        elif isinstance(v, property) and v.fget is not None and v.fget.__qualname__.startswith(
                cls.__qualname__ + "."):
            out.append(m)
    return out


# ----------------------------------------------------------------------- the roles
ROLE = re.compile(r":(?:py:)?(class|func|meth|mod|data|attr|exc|obj|const):`([^`]+)`")
# the roles that name a class, function, method or module: one that names nothing
# (renamed, removed, misspelled) is kept as a cross-reference, so that the strict build
# fails on it; an attribute or a constant may be set at run time, out of sight
_CALLABLE_ROLES = {"class", "func", "meth", "mod", "exc"}


def _lookup(path: str) -> tuple[bool, Any]:
    """Import the longest module prefix of ``path``, then getattr the rest."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj: Any = importlib.import_module(".".join(parts[:i]))
        except Exception:  # noqa: BLE001 - not a module: try a shorter prefix
            continue
        try:
            for p in parts[i:]:
                obj = inspect.getattr_static(obj, p) if inspect.isclass(obj) else getattr(obj, p)
        except AttributeError:
            return False, None
        return True, obj
    return False, None


def resolve(target: str, module: str, cls: str | None = None) -> tuple[str | None, bool]:
    """``(path, found)`` for a role's target seen from ``module`` (and class ``cls``, a
    dotted path): the documented path it names, or None (found but not documented,
    e.g. private or outside the project); ``found`` is False when it names nothing."""
    target = target.lstrip("~.").strip("()")
    if target.split(".")[0] in vars(builtins):
        return None, True  # ValueError, DeprecationWarning: Python's own
    tries = [target]
    if cls:
        tries.append(f"{cls}.{target}")
    tries.append(f"{module}.{target}")
    # a short name the module does not import: the one documented object of that name
    first, _, rest = target.partition(".")
    named = sorted(p for p in documented() if p.rsplit(".", 1)[-1] == first)
    if len(named) == 1:
        tries.append(f"{named[0]}.{rest}" if rest else named[0])
    for path in tries:
        found, obj = _lookup(path)
        if not found:
            continue
        if not path.startswith(PACKAGE):
            return None, True
        where = canonical(obj) if (inspect.isclass(obj) or inspect.isfunction(obj)
                                   or isinstance(obj, (ModuleType, property, classmethod,
                                                       staticmethod))) else None
        head, _, last = path.rpartition(".")
        if where is None:
            # a constant, or an attribute: documented where its owner documents it
            owner_found, owner = _lookup(head)
            base = canonical(owner) if owner_found else None
            where = f"{base}.{last}" if base else path
        return (where if where in documented() else None), True
    return None, False


def roles_to_markdown(text: str, module: str, cls: str | None = None) -> str:
    """Sphinx roles as Markdown: a cross-reference (``[`GaitModel`][graspgait_env.gait.
    GaitModel]``) to what the reference documents, inline code for the rest, and a
    cross-reference to the name itself when it names nothing (the strict build then
    fails)."""

    def one(m: re.Match[str]) -> str:
        role, body = m.group(1), " ".join(m.group(2).split())
        title, _, explicit = body.partition(" <")
        if explicit:
            target, label = explicit.rstrip(">").replace(" ", ""), title
        else:
            body = target = body.replace(" ", "")  # a dotted name wrapped at a dot
            label = body.lstrip("~.")
            if body.startswith("~"):
                label = label.rsplit(".", 1)[-1]
        if role in ("meth", "func") and not label.endswith(")") and not explicit:
            label += "()"
        path, found = resolve(target, module, cls)
        if path:
            return f"[`{label}`][{path}]"
        if not found and role in _CALLABLE_ROLES:
            return f"[`{label}`][{target.lstrip('~.')}]"  # unresolved: fails the build
        return f"`{label}`"

    return ROLE.sub(one, text)


def rst_to_markdown(text: str, module: str, cls: str | None = None) -> str:
    """A docstring's reStructuredText habits as Markdown: roles (above), ``text::``
    literal blocks, and table rows continued on the next line (a row whose first cell
    is empty) joined to the row above."""
    text = roles_to_markdown(text, module, cls)
    text = re.sub(r"(\S)::\n", r"\1:\n", text)
    text = re.sub(r"^::\n", "\n", text, flags=re.M)
    return join_table_rows(text)


_RULE = re.compile(r"\|[\s|:-]+\|")  # a table's header rule


def join_table_rows(text: str) -> str:
    """Merge each Markdown table row whose first cell is blank into the row above it,
    cell by cell (the docstrings wrap a long cell onto continuation rows)."""
    out: list[str] = []
    for line in text.split("\n"):
        s = line.strip()
        prev = out[-1].strip() if out else ""
        if (s.startswith("|") and s.endswith("|") and prev.startswith("|")
                and not _RULE.fullmatch(prev) and not _RULE.fullmatch(s)):
            cells = [c.strip() for c in s.strip("|").split("|")]
            # a continuation: its first cell is blank, or (a cell of the first column
            # wrapped) every cell after the second is
            if cells and (not cells[0] or (len(cells) >= 4 and not any(cells[2:]))):
                indent = out[-1][: len(out[-1]) - len(out[-1].lstrip())]
                above = [c.strip() for c in prev.strip("|").split("|")]
                if len(above) == len(cells):
                    merged = [(a + " " + c).strip() for a, c in zip(above, cells, strict=True)]
                    out[-1] = indent + "| " + " | ".join(merged) + " |"
                    continue
        out.append(line)
    return "\n".join(out)


if __name__ == "__main__":  # list what the reference documents
    sys.stdout.write("\n".join(sorted(documented())) + "\n")
