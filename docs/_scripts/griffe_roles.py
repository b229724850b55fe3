"""A griffe extension: the docstrings' reStructuredText habits as Markdown for mkdocstrings.

The docstrings cross-reference with Sphinx roles (``:class:`~graspgait_env.gait.GaitModel```,
``:meth:`action_masks```). This extension rewrites each role as a mkdocstrings
cross-reference to the documented object it names (resolved from the docstring's module
and class, as Python would resolve the name there), or as inline code for what the API
reference does not document (private helpers, other libraries). A role that names
nothing (a renamed or removed function) stays a cross-reference, which the strict build
reports as broken. Markdown headings inside a docstring (the env pages' sections)
become bold paragraphs, so that they do not enter the reference page's table of
contents.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Any

import griffe

sys.path.insert(0, str(Path(__file__).resolve().parent))
import apiref  # noqa: E402


class SphinxRoles(griffe.Extension):
    """Rewrite every docstring of the loaded package (see the module docstring)."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        self._walk(pkg)

    def _walk(self, obj: griffe.Object) -> None:
        if obj.docstring is not None:
            module = obj.module.path
            cls = obj.path if obj.is_class else (obj.parent.path if obj.parent is not None
                                                 and obj.parent.is_class else None)
            text = apiref.rst_to_markdown(obj.docstring.value, module, cls)
            obj.docstring.value = re.sub(r"^#{1,6} +(.+)$", r"**\1**", text, flags=re.M)
        for member in list(obj.members.values()):
            if not member.is_alias:
                self._walk(member)
