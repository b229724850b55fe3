"""Contact models for planning: the thesis's point contacts, or the hand's ball tips.

The grasp map of thesis 3.2 treats fingers as point contacts with Coulomb friction, and
a grasp as force closure the moment the line between the contacts lies inside both
friction cones (thesis 2.3). The hand of thesis 7.2 is not quite that: its fingertips
are balls of radius 0.307 in that roll on the object (7.2), and its grip must also
carry the load of turning the object on the table. A :class:`ContactModel` names what
a plan assumes, and :func:`graspgait_env.grasp_map.grasp_map` draws the map for it:

- :data:`POINT_CONTACTS` (``name="point"``): the thesis's idealized maps, bit for bit;
- :func:`hand_contact_model` (``name="hand"``): the maps of plans meant for the
  simulated hand (``graspgait plan`` by default), derived below from the hand's
  geometry and the loads its controller carries.

Friction margin (the load of a rotation)
----------------------------------------
A rotation turns the object against the table's friction and its own inertia: a torque
``tau`` about its centre. Two fingers at ``p1``, ``p2`` hold it; the object does not
translate, so their forces are equal and opposite, ``f2 = -f1``, and the torque is
``(p1 - p2) x f1``: on top of the grip ``G`` along the chord, each finger carries a force
``tau / d`` perpendicular to the chord (``d = |p1 - p2|``). The finger's force then
leans ``atan(tau / (G d))`` further from the chord, toward one cone edge, so a grasp
holds through the rotation only when the chord lies that much inside both cones::

    angle(chord, normal_i) < atan(mu) - atan(tau / (G d))        (i = 1, 2)

With ``tau = 0`` this is the thesis's test. The bounds used (:func:`hand_contact_model`):

- table friction: at most ``mu_table m g r_max`` (the whole weight on the contour's
  farthest point; MuJoCo puts it on the rim and the vertices, a real table anywhere);
- inertia: ``I alpha`` with ``I`` the polar moment of the (uniform) object about its
  centre and ``alpha = a / (r_min + rho)``: the trajectory planner limits the tip
  acceleration to ``a`` (``rotation_accel``), and no tip is nearer the centre than
  ``r_min + rho``;
- ``G``: the nominal grip force (``grip_force``); the grip check may raise it (7.4.4),
  but only after a finger's force has already left the cone.

Measured on the thesis circle (contacts 120° apart, the grasp of its rule-based gait):
a 90° rotation raises the tangential force of one finger by 0.27 N; this model predicts
``tau / d = 0.25`` N (``tau = 0.033`` N m, ``d = 0.132`` m).

Rolling (the ball tips)
-----------------------
A ball that cannot spin rolls on the object (thesis 7.2, :func:`rolling_contacts_deg`):
while the object turns ``theta``, each contact moves back ``rho theta`` along a flat
edge (on a curve of radius ``r``, ``rho theta r / (r + rho)``), against the turn. The
thesis neglects it (1/10 of the motion); over a 90° rotation it is 12 mm, an eighth of
a pentagon's edge. So the hand's map

- leaves out contacts nearer a vertex than ``rho`` times the largest rotation (the
  widest workspace): a ball there may roll over the corner (``vertex_clearance_m``,
  measured along the straight line to the vertex, never longer than along the
  contour);
- keeps a grasp only if it also holds (with the margin above) where its contacts have
  rolled to after the object turned the gait's way by half and by all of the largest
  rotation (``max_rotation_deg``, signed with the turn: CCW positive). Measured on the
  pentagon's rule-based gait planned without this check: fingers at 272° and 36° hold
  at the start, but in the gait's 84° rotation the contact at 272° rolls 11 mm along
  its edge, the chord leans 4.7° further from that edge's normal, and the object drops
  in 10 of 10 perturbed runs.

Examples
--------
>>> POINT_CONTACTS.is_point, POINT_CONTACTS.margin_deg(0.1)
(True, 0.0)
>>> cm = hand_contact_model("circle")
>>> cm.name, round(cm.tip_radius_m, 4), round(cm.vertex_clearance_m * 1000, 1)
('hand', 0.0078, 12.2)
>>> round(float(cm.margin_deg(0.1320)), 1)         # the circle's 120-degree chord
7.1
>>> ContactModel.from_json(cm.to_json()) == cm
True
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from graspgait_env.errors import GraspGaitInputError
from graspgait_env.objects import (
    OBJECT_DEFAULTS,
    load_object,
    load_object_physical,
    read_yaml_mapping,
)
from graspgait_env.resources import config_dir
from graspgait_env.shapes import Polygon, Shape
from graspgait_env.workspace import DEFAULT_WORKSPACES_DEG

__all__ = ["ContactModel", "POINT_CONTACTS", "hand_contact_model", "contact_model_named",
           "CONTACT_MODELS", "polar_moment_of_inertia", "rolling_contacts_deg", "GRAVITY"]

GRAVITY = 9.81  # (m/s^2)
CONTACT_MODELS = ("point", "hand")  # the names a user may give


@dataclass(frozen=True)
class ContactModel:
    """What a plan assumes of the fingertips (see the module docstring for the physics).

    Attributes
    ----------
    name
        ``"point"`` (the thesis's point contacts) or ``"hand"`` (the simulated hand).
    tip_radius_m
        Fingertip ball radius ``rho`` (m); 0 for point contacts.
    load_torque_nm
        Torque about the object's centre the grip transmits during a rotation (N m):
        table friction and inertia. With ``grip_n`` it is the friction margin
        (:meth:`margin_deg`); 0 for point contacts.
    grip_n
        Grip force between the gripping pair (N) that carries that load.
    max_rotation_deg
        Largest rotation a grasp is held through (deg): the widest workspace, signed
        with the gait's turn (CCW positive). The map checks the grasps where their
        contacts roll to in such a rotation; with ``tip_radius_m`` its size sets
        :attr:`vertex_clearance_m`.
    """

    name: str
    tip_radius_m: float = 0.0
    load_torque_nm: float = 0.0
    grip_n: float = 0.0
    max_rotation_deg: float = 0.0

    def __post_init__(self) -> None:
        if self.name not in CONTACT_MODELS:
            raise GraspGaitInputError(f"contact_model.name={self.name!r}: use one of "
                                      f"{', '.join(CONTACT_MODELS)}")
        for f in fields(self)[1:]:
            v = getattr(self, f.name)
            signed = f.name == "max_rotation_deg"
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (
                    math.isfinite(v) and (signed or v >= 0)):
                raise GraspGaitInputError(f"contact_model.{f.name}={v!r}: give a finite "
                                          f"number{'' if signed else ' >= 0'}")
        if self.load_torque_nm > 0 and not self.grip_n > 0:
            raise GraspGaitInputError(
                f"contact_model.grip_n={self.grip_n!r}: a load torque needs a grip force "
                "> 0 (N) to carry it")

    @property
    def is_point(self) -> bool:
        """No ball and no load: the thesis's point contacts (maps bit-identical to them)."""
        return (self.tip_radius_m == 0.0 and self.load_torque_nm == 0.0
                and self.max_rotation_deg * self.tip_radius_m == 0.0)

    @property
    def vertex_clearance_m(self) -> float:
        """How far (m) a contact must stay from a vertex: ``rho`` times the largest
        rotation (radians), the distance a rolling ball slides back along a flat edge."""
        return self.tip_radius_m * math.radians(abs(self.max_rotation_deg))

    def margin_deg(self, chord_m: ArrayLike) -> NDArray[np.float64] | float:
        """Friction margin (deg) of a grasp whose contacts are ``chord_m`` apart:
        ``atan(load_torque / (grip chord))``, the lean of each finger's force from the
        chord while it carries the rotation's load. 0 for point contacts; 90 for a
        zero chord."""
        if self.load_torque_nm == 0.0:
            return 0.0 if np.ndim(chord_m) == 0 else np.zeros(np.shape(chord_m))
        d = np.asarray(chord_m, dtype=np.float64)
        with np.errstate(divide="ignore"):
            out = np.degrees(np.arctan2(self.load_torque_nm, self.grip_n * d))
        return float(out) if out.ndim == 0 else out

    def to_json(self) -> dict[str, Any]:
        """The plan JSON's ``contact_model`` field (docs/formats.md)."""
        return asdict(self)

    @classmethod
    def from_json(cls, d: Any, source: str = "contact_model") -> ContactModel:
        """Read :meth:`to_json`'s mapping (unknown keys refused).

        Raises
        ------
        GraspGaitInputError
            Not a mapping, an unknown key, a bad name or value, naming the field.
        """
        if not isinstance(d, Mapping):
            raise GraspGaitInputError(f"{source}={d!r}: give a mapping with a 'name' "
                                      f"({', '.join(CONTACT_MODELS)})")
        known = [f.name for f in fields(cls)]
        for k in d:
            if k not in known:
                raise GraspGaitInputError(f"{source}.{k}: unknown field; use only "
                                          f"{', '.join(known)}")
        if "name" not in d:
            raise GraspGaitInputError(f"{source}: field 'name' missing; give one of "
                                      f"{', '.join(CONTACT_MODELS)}")
        return cls(**{k: (v if k == "name" or isinstance(v, bool) or not isinstance(
            v, int) else float(v)) for k, v in d.items()})


POINT_CONTACTS = ContactModel("point")
"""The thesis's idealized point contacts with friction (thesis 2.3, 7.2)."""


def rolling_contacts_deg(shape: Shape, phi0_deg: ArrayLike, turn_deg: ArrayLike,
                         tip_radius: float, step_deg: float = 0.02) -> NDArray[np.float64]:
    """Where ball tips that roll without slipping touch the object after it turns.

    Thesis 7.2 gives the rolling of a ball tip on a circle, ``theta_o = (1 + r_f / r_o)
    theta_f``. For any contour: a ball of radius ``rho`` that cannot spin rolls on the
    object, so the arc length its contact travels along the contour equals the arc
    length it travels on the ball, ``rho`` times the turn of the contact normal
    relative to the ball. When the object turns ``theta`` (CCW positive) and the
    contact moves from ``phi0`` to ``phi`` (polar angles, frame f)::

        s(phi0) - s(phi) = rho * (theta - (psi(phi0) - psi(phi)))

    with ``s`` the contour's arc length and ``psi`` the direction of its inward normal
    (both increasing counter-clockwise on a convex contour); that is
    ``H(phi) = H(phi0) - rho theta`` with ``H = s + rho psi`` increasing. On a circle
    of radius ``r``: ``phi0 - phi = theta rho / (r + rho)`` (the thesis's equation); on
    a flat edge the contact slides back ``rho theta`` along it; at a vertex the ball
    rolls round the corner (the normal turns, the contact stays). The contact always
    moves against the turn.

    Parameters
    ----------
    shape
        The object's contour.
    phi0_deg
        Contacts at the start (deg, frame f), any shape.
    turn_deg
        Object turns since the start (deg, CCW positive), broadcast against
        ``phi0_deg``.
    tip_radius
        Ball radius ``rho`` (m).
    step_deg
        The contour is tabulated every ``step_deg`` (vectorized: one interpolation).

    Returns
    -------
    ndarray
        Contact angles (deg, frame f), the broadcast shape of the inputs, unwrapped
        from ``phi0_deg``.

    Examples
    --------
    >>> from graspgait_env.shapes import Circle
    >>> phi = rolling_contacts_deg(Circle(0.0762), 30.0, 90.0, 0.0078)
    >>> round(float(phi), 2), round(30 - 90 * 0.0078 / (0.0762 + 0.0078), 2)
    (21.64, 21.64)
    """
    phi0, turn = np.broadcast_arrays(np.asarray(phi0_deg, dtype=np.float64),
                                     np.asarray(turn_deg, dtype=np.float64))
    u = np.arange(-180.0, 540.0 + step_deg / 2, step_deg)  # a turn and a half either way
    P = shape.contour_point(u)
    N = shape.inward_normal(u)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(P, axis=0).T))])
    H = np.maximum.accumulate(s + tip_radius * np.unwrap(np.arctan2(N[:, 1], N[:, 0])))
    base = np.mod(phi0, 360.0)
    h = np.interp(base, u, H) - tip_radius * np.radians(turn)
    return np.interp(h, H, u) + (phi0 - base)


def polar_moment_of_inertia(shape: Shape, mass_kg: float, segments: int = 720) -> float:
    """Polar moment of inertia (kg m^2) of a uniform lamina of ``shape`` about its origin
    (the centre of rotation), from its contour (a polygon's own vertices, else
    ``segments`` points): ``m / (6 A) sum c_i (x_i^2 + x_i x_j + x_j^2 + y_i^2 + y_i y_j
    + y_j^2)`` with ``c_i = x_i y_j - x_j y_i``, ``j = i + 1`` and ``A = sum c_i / 2``.

    >>> from graspgait_env.shapes import Circle
    >>> round(polar_moment_of_inertia(Circle(0.1), 1.0) / (0.5 * 0.1 ** 2), 4)   # m r^2 / 2
    1.0
    """
    if isinstance(shape, Polygon):
        v = shape.vertices
    else:
        v = shape.contour_point(np.arange(segments) * 360.0 / segments)
    x, y = v[:, 0], v[:, 1]
    xj, yj = np.roll(x, -1), np.roll(y, -1)
    c = x * yj - xj * y
    area = 0.5 * float(np.sum(c))
    s = float(np.sum(c * (x * x + x * xj + xj * xj + y * y + y * yj + yj * yj)))
    return abs(mass_kg * s / (12.0 * area))


_SIM_KEYS = ("tip_radius", "table_mu", "rotation_accel", "grip_force", "object_mass")


@functools.lru_cache(maxsize=1)
def _default_sim_values() -> tuple[tuple[str, Any], ...]:
    """The bundled ``configs/sim/default.yaml``, read once."""
    return tuple(read_yaml_mapping(config_dir("sim") / "default.yaml",
                                   "simulation config").items())


def _sim_values(sim_config: Any) -> dict[str, Any]:
    """The sim-config values the hand's contact model reads: the bundled
    ``configs/sim/default.yaml`` under a mapping, a YAML path or a ``SimConfig``."""
    vals = dict(_default_sim_values())
    if sim_config is None:
        pass
    elif isinstance(sim_config, (str, Path)):
        vals.update(read_yaml_mapping(Path(sim_config), "simulation config"))
    elif isinstance(sim_config, Mapping):
        vals.update(sim_config)
    else:  # a SimConfig (graspgait_env.sim.config), read by attribute
        vals.update({k: getattr(sim_config, k) for k in _SIM_KEYS})
    return {k: vals.get(k) for k in _SIM_KEYS}


def hand_contact_model(shape: Shape | str, sim_config: Any = None, *,
                       mass_kg: float | None = None,
                       workspaces_deg: Sequence[Sequence[float]] = DEFAULT_WORKSPACES_DEG,
                       turn_deg: float = 360.0) -> ContactModel:
    """The simulated hand's contact model for ``shape`` (module docstring: derivation).

    Parameters
    ----------
    shape
        The object (a :class:`~graspgait_env.shapes.Shape`, bundled name or YAML path).
    sim_config
        The simulation config whose hand and controller carry the plan: None for the
        bundled ``configs/sim/default.yaml``, a YAML path (its keys over the default's),
        a mapping, or a ``graspgait_env.sim.config.SimConfig``. Read: ``tip_radius``
        (ball radius, m), ``table_mu``, ``rotation_accel`` (tip acceleration of
        rotations, m/s^2), ``grip_force`` (N), ``object_mass`` (kg, null: the object
        file's).
    mass_kg
        Object mass (kg); default ``object_mass``, else the object file's (0.1 kg).
    workspaces_deg
        The hand's finger workspaces (deg): the widest is the largest rotation.
    turn_deg
        The gait's turn (deg); its sign is the way the object turns, and the way the
        balls roll (default CCW, as the thesis's 360° gaits).

    Returns
    -------
    ContactModel
        ``name="hand"``, ``tip_radius_m = tip_radius``, ``load_torque_nm =
        table_mu m g r_max + I rotation_accel / (r_min + tip_radius)``, ``grip_n =
        grip_force``, ``max_rotation_deg`` the widest workspace (negative for a
        clockwise turn).

    Raises
    ------
    GraspGaitInputError
        A value of the config that is not a finite positive number, naming it.
    """
    if isinstance(shape, Shape):
        obj, file_mass = shape, OBJECT_DEFAULTS["mass"]
    else:
        obj, physical = load_object_physical(shape)
        file_mass = physical["mass"]
    obj = load_object(obj)
    v = _sim_values(sim_config)
    for k in ("tip_radius", "table_mu", "rotation_accel", "grip_force"):
        x = v[k]
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not (
                math.isfinite(x) and x >= 0) or (k != "table_mu" and x == 0):
            raise GraspGaitInputError(f"sim config {k}={x!r}: give a finite number > 0 "
                                      "(the bundled values: `graspgait config sim default`)")
    m = mass_kg if mass_kg is not None else (v["object_mass"] or file_mass)
    rho = float(v["tip_radius"])
    inertia = polar_moment_of_inertia(obj, m)
    alpha = float(v["rotation_accel"]) / (obj.r_min + rho)
    torque = float(v["table_mu"]) * m * GRAVITY * obj.r_max + inertia * alpha
    widest = max(float(hi) - float(lo) for lo, hi in workspaces_deg)
    return ContactModel("hand", tip_radius_m=rho, load_torque_nm=torque,
                        grip_n=float(v["grip_force"]),
                        max_rotation_deg=widest if turn_deg >= 0 else -widest)


def contact_model_named(name: str, shape: Shape | str, sim_config: Any = None, *,
                        workspaces_deg: Sequence[Sequence[float]] = DEFAULT_WORKSPACES_DEG,
                        turn_deg: float = 360.0, field: str = "contact_model"
                        ) -> ContactModel:
    """The contact model a user names: ``"point"`` (:data:`POINT_CONTACTS`) or
    ``"hand"`` (:func:`hand_contact_model` of ``shape``).

    Raises
    ------
    GraspGaitInputError
        Another name, in one line naming ``field``.
    """
    if name == "point":
        return POINT_CONTACTS
    if name == "hand":
        return hand_contact_model(shape, sim_config, workspaces_deg=workspaces_deg,
                                  turn_deg=turn_deg)
    raise GraspGaitInputError(f"{field}={name!r}: use one of {', '.join(CONTACT_MODELS)}")
