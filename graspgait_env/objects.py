"""Object files: load and validate the object YAML of docs/formats.md.

Format (``configs/objects/NAME.yaml`` or any path)::

    name: pentagon
    type: polygon            # polygon | ellipse | circle | stadium
    vertices: [[0.0, 0.08], [-0.076, 0.0247], ...]   # metres, object frame, either winding
    # ellipse: {a: 0.09, b: 0.06}   circle: {radius: 0.0762}
    # stadium: {half_length: 0.04, radius: 0.03}  (flat sides along x, round ends)

Optional physical fields (used by the MuJoCo layer) with their defaults:
``thickness`` 0.02 m (prism height), ``mass`` 0.1 kg, and a free-text ``description``.
Unknown keys are an error. Every refusal is a :class:`~graspgait_env.errors.ConfigError`
naming the file, the field, the bad value and the fix.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import yaml

from graspgait_env.errors import ConfigError
from graspgait_env.resources import bundled_file, bundled_names, config_dir
from graspgait_env.shapes import Circle, Ellipse, Polygon, Shape, Stadium

__all__ = [
    "load_object",
    "object_from_dict",
    "bundled_objects",
    "CONFIG_DIR",
    "OBJECT_DEFAULTS",
    "read_yaml_mapping",
    "resolve_object_path",
    "load_object_physical",
    "positive_length",
]

CONFIG_DIR = config_dir("objects").parent  # the bundled configs (graspgait_env.resources)
OBJECT_DIR = config_dir("objects")

OBJECT_DEFAULTS: dict[str, Any] = {"thickness": 0.02, "mass": 0.1, "description": ""}
_TYPE_FIELDS: dict[str, tuple[str, ...]] = {
    "polygon": ("vertices",),
    "ellipse": ("a", "b"),
    "circle": ("radius",),
    "stadium": ("half_length", "radius"),
}


def bundled_objects() -> list[str]:
    """Names of the object files shipped in ``configs/objects/`` (sorted)."""
    return bundled_names("objects")


def read_yaml_mapping(path: Path, what: str) -> dict[str, Any]:
    """Read a YAML file that must hold a mapping; refuse anything else with a ConfigError."""
    src = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(src, "", "file not found", f"give an existing {what} YAML path") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(src, "", f"cannot read file ({exc})",
                          "give a readable UTF-8 file") from None
    if not text.strip():
        raise ConfigError(src, "", "the file is empty", f"write a {what} mapping into it")
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        line = getattr(getattr(exc, "problem_mark", None), "line", None)
        at = f" at line {line + 1}" if line is not None else ""
        raise ConfigError(src, "", f"unreadable YAML{at}", "fix the YAML syntax") from None
    if not isinstance(data, dict):
        raise ConfigError(
            src, "", f"expected a mapping of fields, got {type(data).__name__}",
            f"write the {what} as 'key: value' lines",
        )
    return data


def positive_length(src: str, field: str, value: Any) -> float:
    """Validate a finite length > 0 (metres); refuse bools, strings, NaN, inf, <= 0."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(src, field, f"expected a number (metres), got {value!r}",
                          f"set {field} to a positive length in metres")
    try:
        finite = math.isfinite(value)
    except OverflowError:  # an integer too large for a float
        finite = False
    if not finite:
        raise ConfigError(src, field, f"{str(value)[:20]} is not finite",
                          f"set {field} to a finite positive length in metres")
    if value <= 0:
        raise ConfigError(src, field, f"{value!r} is not > 0",
                          f"set {field} to a positive length in metres")
    return float(value)


def _vertices(src: str, value: Any) -> list[list[float]]:
    fix = "give vertices as a list of at least 3 [x, y] pairs in metres"
    if not isinstance(value, list):
        raise ConfigError(src, "vertices", f"expected a list, got {value!r}", fix)
    out: list[list[float]] = []
    for k, pt in enumerate(value):
        f = f"vertices[{k}]"
        if not isinstance(pt, (list, tuple)) or len(pt) != 2:
            raise ConfigError(src, f, f"expected an [x, y] pair, got {pt!r}", fix)
        xy = []
        for c in pt:
            if isinstance(c, bool) or not isinstance(c, (int, float)):
                raise ConfigError(src, f, f"coordinate {c!r} is not a number", fix)
            try:
                finite = math.isfinite(c)
            except OverflowError:  # an integer too large for a float
                finite = False
            if not finite:
                raise ConfigError(src, f, f"coordinate {str(c)[:20]} is not finite", fix)
            xy.append(float(c))
        out.append(xy)
    if len(out) < 3:
        raise ConfigError(src, "vertices", f"only {len(out)} vertices", fix)
    return out


def object_from_dict(data: dict[str, Any], source: str = "<dict>") -> tuple[Shape, dict[str, Any]]:
    """Build a shape from an already-parsed object mapping.

    Returns
    -------
    shape, physical
        The :class:`~graspgait_env.shapes.Shape` and a dict of the physical fields
        (``thickness``, ``mass``, ``description``) with defaults filled in.
    """
    src = source
    if not isinstance(data, dict):
        raise ConfigError(src, "", f"expected a mapping, got {type(data).__name__}",
                          "give the object as 'key: value' fields")
    for req in ("name", "type"):
        if req not in data:
            raise ConfigError(src, req, "missing", f"add '{req}:' to the object file")
    name = data["name"]
    if not isinstance(name, str) or not name.strip():
        raise ConfigError(src, "name", f"expected a non-empty string, got {name!r}",
                          "give the object a name")
    kind = data["type"]
    if not isinstance(kind, str) or kind not in _TYPE_FIELDS:
        raise ConfigError(src, "type", f"unknown type {kind!r}",
                          f"use one of {', '.join(_TYPE_FIELDS)}")
    allowed = {"name", "type", *_TYPE_FIELDS[kind], *OBJECT_DEFAULTS}
    unknown = sorted(set(data) - allowed, key=str)
    if unknown:
        raise ConfigError(src, str(unknown[0]), f"unknown key for type {kind!r}",
                          f"remove it; allowed keys: {', '.join(sorted(allowed))}")
    for req in _TYPE_FIELDS[kind]:
        if req not in data:
            raise ConfigError(src, req, "missing", f"a {kind} needs '{req}:'")
    physical = dict(OBJECT_DEFAULTS)
    for key in ("thickness", "mass"):
        if key in data:
            physical[key] = positive_length(src, key, data[key])
    if "description" in data:
        if not isinstance(data["description"], str):
            raise ConfigError(src, "description", f"expected text, got {data['description']!r}",
                              "quote the description")
        physical["description"] = data["description"]
    try:
        if kind == "polygon":
            shape: Shape = Polygon(_vertices(src, data["vertices"]), name=name)
        elif kind == "ellipse":
            shape = Ellipse(positive_length(src, "a", data["a"]),
                            positive_length(src, "b", data["b"]), name=name)
        elif kind == "circle":
            shape = Circle(positive_length(src, "radius", data["radius"]), name=name)
        else:
            shape = Stadium(positive_length(src, "half_length", data["half_length"]),
                            positive_length(src, "radius", data["radius"]), name=name)
    except ValueError as exc:
        if isinstance(exc, ConfigError):
            raise
        msg = str(exc)
        problem, _, fix = msg.partition("; ")
        raise ConfigError(src, _TYPE_FIELDS[kind][0], problem.split(": ", 1)[-1],
                          fix or "correct the shape") from None
    return shape, physical


def resolve_object_path(name_or_path: str | Path) -> Path:
    """The YAML path for a bundled object name or a path; refuse names that are neither."""
    s = str(name_or_path)
    path = Path(s)
    if s.endswith((".yaml", ".yml")) or path.is_file():  # a folder named "circle" is no object
        return path
    bundled = bundled_file("objects", s)
    if bundled is None:
        raise ConfigError(
            s, "object", "no bundled object of that name and no such file",
            f"use one of {', '.join(bundled_objects())} or a path to an object YAML",
        )
    return bundled


def load_object_physical(name_or_path: str | Path) -> tuple[Shape, dict[str, Any]]:
    """Like :func:`load_object`, also returning the physical fields with defaults."""
    path = resolve_object_path(name_or_path)
    return object_from_dict(read_yaml_mapping(path, "object"), source=str(path))


def load_object(name_or_path: str | Path | Shape) -> Shape:
    """Load a shape from a bundled name (``"ellipse"``) or a YAML path.

    A :class:`Shape` passes through unchanged, so every API that takes an object takes
    a name, a path or a shape.

    Raises
    ------
    ConfigError
        The name is not bundled and no such file exists, or the file is malformed.
    """
    if isinstance(name_or_path, Shape):
        return name_or_path
    return load_object_physical(name_or_path)[0]
