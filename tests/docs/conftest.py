"""Helpers of the documentation tests: the site's generator scripts (docs/_scripts/)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = ROOT / "docs" / "_scripts"


def load_script(name: str) -> ModuleType:
    """Import ``docs/_scripts/NAME.py`` (the mkdocs hook and its helpers)."""
    if name in sys.modules:
        return sys.modules[name]
    if str(SCRIPTS) not in sys.path:
        sys.path.insert(0, str(SCRIPTS))
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def gen() -> ModuleType:
    """``docs/_scripts/gen_pages.py``, the mkdocs hook that writes the generated pages."""
    return load_script("gen_pages")


@pytest.fixture(scope="session")
def apiref() -> ModuleType:
    """``docs/_scripts/apiref.py``: the public API and the docstrings' cross-references."""
    return load_script("apiref")
