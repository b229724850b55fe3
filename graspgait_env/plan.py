"""Gait plans: the JSON of docs/formats.md, the thesis's ``motion_file`` (7.4.1) and a validator.

A plan is a list of steps in the object frame::

    {"op": "grasp",   "contacts": {"1": 50.0, "3": 270.0}}   # first step, at theta = 0
    {"op": "rotate",  "delta": 40.0}                          # degrees, CCW positive
    {"op": "regrasp", "contacts": {"2": 140.0, "3": 270.0}}   # the new two-finger grasp

:func:`validate_plan` replays any plan without a grid (continuous angles, the shape's
own normals) and names the first step that breaks a rule and which rule:

=============================== ==========================================================
rule                            meaning
=============================== ==========================================================
``first-step-not-grasp``        the plan must open with one ``grasp`` step
``bad-step``                    unknown ``op``, missing field, non-finite number
``unknown-finger``              a finger that the hand does not have
``not-two-fingers``             a grasp or regrasp must name exactly two fingers
``outside-workspace``           a contact is outside its finger's workspace (frame F)
``not-force-closure``           the two contacts are not force-closure (or on a vertex,
                                or beyond the reach cap)
``rotation-leaves-workspace``   a rotation carries a contact out of its workspace
``zero-rotation``               a rotation by 0°
``same-finger-pair-box``        a regrasp that keeps the same two fingers
``more-than-one-contact-changed`` a regrasp that does not keep one old contact exactly
``turn-not-achieved``           the plan ends short of the requested turn
=============================== ==========================================================
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from graspgait_env.atomic import write_text_atomic
from graspgait_env.contact_model import POINT_CONTACTS, ContactModel
from graspgait_env.errors import GraspGaitInputError
from graspgait_env.force_closure import force_closure_nguyen
from graspgait_env.gait import GaitModel, GaitState
from graspgait_env.objects import load_object
from graspgait_env.shapes import Shape
from graspgait_env.workspace import Hand

# Where a user reads the plan format: in the installed command's help (a clone's docs are
# not on a user's machine).
PLAN_FORMAT_HINT = "the plan format: `graspgait plan --help`"

__all__ = [
    "Plan",
    "PlanViolation",
    "InvalidPlanError",
    "validate_plan",
    "plan_from_states",
]

_TOL_DEG = 1e-6  # (degrees) slack on workspace edges when replaying a plan


def _is_number(x: Any) -> bool:
    """A finite JSON number (not a bool, not a string)."""
    return (not isinstance(x, bool) and isinstance(x, (int, float))
            and math.isfinite(float(x)))


@dataclass
class Plan:
    """A gait plan (docs/formats.md). ``steps`` use finger numbers 1..3 as strings, degrees.

    ``contact_model``: the contact model the planner assumed
    (:meth:`ContactModel.to_json <graspgait_env.contact_model.ContactModel.to_json>`);
    None (the field left out): the thesis's point contacts.
    """

    object: str
    mu: float
    workspaces_deg: list[list[float]]
    steps: list[dict[str, Any]]
    stats: dict[str, Any] = field(default_factory=dict)
    contact_model: dict[str, Any] | None = None

    @property
    def assumed_contact_model(self) -> ContactModel:
        """The :class:`~graspgait_env.contact_model.ContactModel` the plan was made for
        (:data:`~graspgait_env.contact_model.POINT_CONTACTS` when none is recorded)."""
        if self.contact_model is None:
            return POINT_CONTACTS
        return ContactModel.from_json(self.contact_model)

    # ---------------------------------------------------------------- JSON
    def to_dict(self) -> dict[str, Any]:
        """The plan as the JSON-ready mapping of docs/formats.md."""
        d = {"object": self.object, "mu": self.mu, "workspaces_deg": self.workspaces_deg,
             "steps": self.steps, "stats": self.stats}
        if self.contact_model is not None:
            d["contact_model"] = self.contact_model
        return d

    def to_json(self) -> str:
        """JSON text (indented)."""
        return json.dumps(self.to_dict(), indent=1)

    def save(self, path: str | Path) -> None:
        """Write the JSON atomically."""
        write_text_atomic(path, self.to_json() + "\n")

    @classmethod
    def from_dict(cls, d: Any, source: str = "<plan>") -> Plan:
        """Read a plan mapping, checking every field's type before any use.

        Checked: the top-level keys (``object``, ``mu``, ``workspaces_deg``, ``steps``,
        optional ``stats`` and ``contact_model``; others are refused), ``mu`` a finite number > 0,
        ``workspaces_deg`` a list of ``[lo, hi]`` pairs of finite degrees, and each
        step: ``op`` one of grasp/rotate/regrasp, the first a grasp and only the first;
        a rotate has a finite non-zero ``delta`` (degrees); a grasp or regrasp has
        ``contacts`` mapping two distinct finger numbers (``"1"`` .. ``"N"``, N the
        number of workspaces) to finite angles (degrees). Whether the plan obeys the
        gait rules is :func:`validate_plan`'s question, not this one's.

        Raises
        ------
        GraspGaitInputError
            One line naming the source, the field (``steps[3].contacts.2``), the bad
            value and the fix.
        """
        def bad(field_: str, value: Any, want: str) -> GraspGaitInputError:
            return GraspGaitInputError(
                f"{source}: field '{field_}'={value!r}: {want} ({PLAN_FORMAT_HINT})")

        if not isinstance(d, dict):
            raise GraspGaitInputError(f"{source}: a plan must be a JSON object "
                                      f"({PLAN_FORMAT_HINT})")
        known = ("object", "mu", "workspaces_deg", "steps", "stats", "contact_model")
        for key in d:
            if key not in known:
                raise bad(str(key), d[key], f"unknown field; use only {', '.join(known)}")
        for key in known[:4]:
            if key not in d:
                raise GraspGaitInputError(
                    f"{source}: field '{key}' missing; add it ({PLAN_FORMAT_HINT})")
        if not isinstance(d["object"], str) or not d["object"].strip():
            raise bad("object", d["object"], "give a bundled object name or an object YAML path")
        mu = d["mu"]
        if not _is_number(mu) or not mu > 0:
            raise bad("mu", mu, "must be a finite number > 0, e.g. 0.7")
        ws = d["workspaces_deg"]
        if not isinstance(ws, list) or not ws:
            raise bad("workspaces_deg", ws, "give one [lo, hi] pair of degrees per finger")
        for f, w in enumerate(ws):
            if not (isinstance(w, list) and len(w) == 2 and all(_is_number(x) for x in w)):
                raise bad(f"workspaces_deg[{f}]", w, "give [lo, hi] in degrees, e.g. [0, 90]")
        fingers = {str(f) for f in range(1, len(ws) + 1)}
        steps = d["steps"]
        if not isinstance(steps, list) or not steps:
            raise bad("steps", steps, "must be a non-empty list of steps")
        for i, st in enumerate(steps):
            where = f"steps[{i}]"
            if not isinstance(st, dict):
                raise bad(where, st, "each step must be an object with an 'op'")
            op = st.get("op")
            if op not in ("grasp", "rotate", "regrasp"):
                raise bad(f"{where}.op", op, "use grasp, rotate or regrasp")
            if (op == "grasp") != (i == 0):
                raise bad(f"{where}.op", op, "the first step, and only the first, is a grasp")
            if op == "rotate":
                delta = st.get("delta")
                if not _is_number(delta) or delta == 0:
                    raise bad(f"{where}.delta", delta,
                              "give a finite non-zero rotation in degrees, CCW positive")
                continue
            contacts = st.get("contacts")
            if not isinstance(contacts, dict) or len(contacts) != 2:
                raise bad(f"{where}.contacts", contacts,
                          'give two fingers and their contact angles, e.g. {"1": 50, "3": 270}')
            for f, phi in contacts.items():
                if f not in fingers:
                    raise bad(f"{where}.contacts", f,
                              f"finger numbers are {', '.join(sorted(fingers))} (as strings)")
                if not _is_number(phi):
                    raise bad(f"{where}.contacts.{f}", phi,
                              "give the contact angle in degrees (object frame), e.g. 50.0")
        stats = d.get("stats", {})
        if not isinstance(stats, dict):
            raise bad("stats", stats, "must be an object (or be left out)")
        cm = d.get("contact_model")
        if cm is not None:
            try:
                cm = ContactModel.from_json(cm, "contact_model").to_json()
            except GraspGaitInputError as exc:
                raise GraspGaitInputError(f"{source}: {exc} ({PLAN_FORMAT_HINT})") from None
        return cls(d["object"], float(mu), [[float(x) for x in w] for w in ws],
                   [dict(st) for st in steps], dict(stats), cm)

    @classmethod
    def load(cls, path: str | Path) -> Plan:
        """Read a plan JSON file."""
        try:
            d = json.loads(Path(path).read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise GraspGaitInputError(f"{path}: no such plan file") from None
        except (OSError, json.JSONDecodeError) as exc:
            raise GraspGaitInputError(f"{path}: not a readable JSON plan ({exc})") from None
        return cls.from_dict(d, str(path))

    # ---------------------------------------------------------------- derived
    @property
    def regrasps(self) -> int:
        """Number of regrasp steps."""
        return sum(1 for s in self.steps if s.get("op") == "regrasp")

    @property
    def rotation_deg(self) -> float:
        """Net rotation (degrees, CCW positive)."""
        return float(sum(s.get("delta", 0.0) for s in self.steps if s.get("op") == "rotate"))

    def to_motion_file(self, n_fingers: int = 3) -> str:
        """The thesis's ``motion_file`` text (7.4.1).

        Lines ``i a1 a2 a3`` (initial grasp), ``r dtheta`` (rotation, degrees) and
        ``t a1 a2 a3`` (transition), with the positions of fingers 1..3 in the object
        frame. Fingers in contact are positive; a finger off the object is written as
        the negative of its last contact angle (or of 360 when it never touched), with
        0° written as 360° so that the sign always shows.
        """
        last = [360.0] * n_fingers
        lines = []
        for st in self.steps:
            if st["op"] == "rotate":
                lines.append(f"r {st['delta']:g}")
                continue
            held = {int(f): float(v) % 360.0 for f, v in st["contacts"].items()}
            vals = []
            for f in range(1, n_fingers + 1):
                if f in held:
                    last[f - 1] = held[f] or 360.0
                    vals.append(f"{last[f - 1]:g}")
                else:
                    vals.append(f"-{last[f - 1]:g}")
            lines.append(("i " if st["op"] == "grasp" else "t ") + " ".join(vals))
        return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class PlanViolation:
    """The first broken rule of a plan: 0-based ``step`` index, ``rule`` and a message."""

    step: int
    rule: str
    message: str


class InvalidPlanError(GraspGaitInputError):
    """A plan that breaks a gait rule; carries the :class:`PlanViolation`."""

    def __init__(self, v: PlanViolation) -> None:
        self.violation = v
        super().__init__(f"step {v.step}: {v.rule}: {v.message}")


def _in_arc(angle: float, arc: tuple[float, float]) -> float:
    """Offset (deg) of an F angle from the arc's start if inside, else NaN."""
    lo, hi = arc
    u = (angle - lo + _TOL_DEG) % 360.0 - _TOL_DEG
    return u if u <= hi - lo + _TOL_DEG else math.nan


def validate_plan(plan: Plan, shape: Shape | str | None = None, hand: Hand | None = None,
                  turn_deg: float | None = None, max_radius: float | None = None
                  ) -> PlanViolation | None:
    """Replay ``plan`` in continuous angles; return the first violation, or None.

    Parameters
    ----------
    plan
        The plan to check.
    shape
        The object; default ``load_object(plan.object)``.
    hand
        The hand; default the plan's ``workspaces_deg``.
    turn_deg
        If given, the plan must end at least this far round (CCW for a positive turn,
        CW for a negative one).
    max_radius
        Reach cap (m): contacts beyond it are not usable (thesis fig. 4.3).
    """
    shape = load_object(plan.object if shape is None else shape)
    hand = hand or Hand(tuple(tuple(w) for w in plan.workspaces_deg), "plan")
    mu = plan.mu
    theta = 0.0
    held: dict[int, float] = {}

    def bad(i: int, rule: str, msg: str) -> PlanViolation:
        return PlanViolation(i, rule, msg)

    def check_grasp(i: int, contacts: Any) -> PlanViolation | dict[int, float]:
        if not isinstance(contacts, dict) or len(contacts) != 2:
            return bad(i, "not-two-fingers", f"contacts {contacts!r} must name two fingers")
        out: dict[int, float] = {}
        for f, phi in contacts.items():
            try:
                fi = int(f)
            except (TypeError, ValueError):
                return bad(i, "unknown-finger", f"finger {f!r} is not a number")
            if not 1 <= fi <= hand.n_fingers:
                return bad(i, "unknown-finger", f"finger {fi}: the hand has 1..{hand.n_fingers}")
            if isinstance(phi, bool) or not isinstance(phi, (int, float)) or not math.isfinite(phi):
                return bad(i, "bad-step", f"finger {fi} contact {phi!r} is not a finite angle")
            a = (phi + theta) % 360.0
            if math.isnan(_in_arc(a, hand.workspaces_deg[fi - 1])):
                return bad(i, "outside-workspace",
                           f"finger {fi} at phi={phi:g} deg lies at F angle {a:g} deg at "
                           f"theta={theta:g}, outside its workspace "
                           f"{list(hand.workspaces_deg[fi - 1])}")
            out[fi] = float(phi)
        (f1, p1), (f2, p2) = sorted(out.items())
        phis = np.array([p1, p2])
        P = shape.contour_point(phis)
        N = shape.inward_normal(phis)
        usable = not shape.is_vertex(phis).any()
        if max_radius is not None:
            usable = usable and bool(np.all(shape.radius(phis) <= max_radius))
        if not (usable and force_closure_nguyen(P[0], N[0], P[1], N[1], mu)):
            return bad(i, "not-force-closure",
                       f"fingers {f1} at {p1:g} deg and {f2} at {p2:g} deg are not a force-closure "
                       f"grasp at mu={mu:g}")
        return out

    for i, st in enumerate(plan.steps):
        op = st.get("op") if isinstance(st, dict) else None
        if i == 0:
            if op != "grasp":
                return bad(0, "first-step-not-grasp", f"the plan opens with {op!r}, not 'grasp'")
            r = check_grasp(0, st.get("contacts"))
            if isinstance(r, PlanViolation):
                return r
            held = r
            continue
        if op == "grasp":
            return bad(i, "first-step-not-grasp", "a 'grasp' step after the first; use 'regrasp'")
        if op == "rotate":
            d = st.get("delta")
            if isinstance(d, bool) or not isinstance(d, (int, float)) or not math.isfinite(d):
                return bad(i, "bad-step", f"rotate delta {d!r} is not a finite number of degrees")
            if d == 0:
                return bad(i, "zero-rotation", "a rotation by 0 degrees")
            for f, phi in held.items():
                u = _in_arc((phi + theta) % 360.0, hand.workspaces_deg[f - 1])
                lo, hi = hand.workspaces_deg[f - 1]
                if not (-_TOL_DEG <= u + d <= hi - lo + _TOL_DEG):
                    return bad(i, "rotation-leaves-workspace",
                               f"rotating {d:g} deg carries finger {f} from F angle "
                               f"{(phi + theta) % 360:g} out of its workspace {[lo, hi]}")
            theta += d
            continue
        if op == "regrasp":
            r = check_grasp(i, st.get("contacts"))
            if isinstance(r, PlanViolation):
                return r
            if set(r) == set(held):
                return bad(i, "same-finger-pair-box",
                           f"fingers {sorted(r)} already hold the object: a regrasp must change "
                           "the finger pair box")
            kept = set(r) & set(held)
            if len(kept) != 1 or not math.isclose(r[next(iter(kept))], held[next(iter(kept))],
                                                  abs_tol=_TOL_DEG):
                return bad(i, "more-than-one-contact-changed",
                           f"{held} -> {r}: exactly one old contact must be kept in place")
            held = r
            continue
        return bad(i, "bad-step", f"unknown op {op!r}; use grasp, rotate or regrasp")
    if turn_deg is not None:
        short = theta < turn_deg - _TOL_DEG if turn_deg >= 0 else theta > turn_deg + _TOL_DEG
        if short:
            return bad(len(plan.steps) - 1, "turn-not-achieved",
                       f"the plan turns {theta:g} deg of the {turn_deg:g} deg asked")
    return None


def plan_from_states(model: GaitModel, states: list[GaitState],
                     stats: dict[str, Any] | None = None, merge_rotations: bool = False) -> Plan:
    """Turn a path of states (first at ``k = 0``) into a :class:`Plan`.

    Consecutive states differ by one move; ``merge_rotations`` joins consecutive
    rotations into one step.
    """
    steps: list[dict[str, Any]] = []

    def contacts(s: GaitState) -> dict[str, float]:
        return {str(f + 1): model.contact_deg(s.contacts[f]) for f in s.held()}

    steps.append({"op": "grasp", "contacts": contacts(states[0])})
    for a, b in zip(states, states[1:], strict=False):
        if b.k != a.k:
            d = (b.k - a.k) * model.step_deg
            if merge_rotations and steps[-1]["op"] == "rotate":
                steps[-1]["delta"] += d
                if steps[-1]["delta"] == 0:
                    steps.pop()
            else:
                steps.append({"op": "rotate", "delta": d})
        if b.contacts != a.contacts:
            steps.append({"op": "regrasp", "contacts": contacts(b)})
    cm = getattr(model, "contact_model", POINT_CONTACTS)
    return Plan(model.shape.name, model.mu, [list(w) for w in model.hand.workspaces_deg],
                steps, dict(stats or {}), None if cm.is_point else cm.to_json())
