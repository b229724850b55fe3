"""The MuJoCo model (thesis 7.2): builder and a by-name physics accessor.

:func:`build_mjcf` reads ``assets/hand.xml`` (table, three 3-DOF point fingers with
ball tips, motors) and inserts what depends on the object and the config:

- the object, an extruded prism of the object file's contour standing on the table,
  with a free joint named ``object_free``: a circle is a ``cylinder``; a convex contour
  (polygon, or an ellipse/stadium sampled at ``mesh_segments`` points) one convex mesh;
  an ellipse is touched by the fingers on an invisible ellipsoid whose equator is the
  exact contour (smooth normals; the faceted prism only stands on the table);
  a non-convex star-shaped polygon a fan of convex triangular prisms about its origin
  (every piece is convex, as MuJoCo's collision needs);
- mass and inertia of the prism (uniform density) at the contour's centroid;
- the finger home points, 120° apart for the thesis hand (the middle of each finger's
  workspace), at radius ``max_r`` and at the object's mid-height;
- contact pairs finger tip - object piece (friction ``mu``) and table - object piece
  (friction ``table_mu``), with the config's solref/solimp; contact sensors that report
  the net force of each fingertip on the object in the world frame;
- ``<option>`` values (timestep, solver, cone, impratio, noslip).

:class:`HandPhysics` wraps ``(MjModel, MjData)`` with named accessors in the style of
dm_control's ``Physics``: addresses are looked up by element name once, at construction.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from time import perf_counter as _perf_counter

import mujoco
import numpy as np
from numpy.typing import NDArray

from graspgait_env.shapes import Circle, Ellipse, Polygon, Shape
from graspgait_env.sim.config import SimConfig
from graspgait_env.sim.frames import quat_from_yaw_deg, tilt_deg_from_quat, yaw_deg_from_quat
from graspgait_env.workspace import DEFAULT_WORKSPACES_DEG

__all__ = ["SimModel", "HandPhysics", "build_mjcf", "build_model", "contour_polygon",
           "prism_inertia", "ASSET_XML", "FINGERS"]

ASSET_XML = Path(__file__).resolve().parent / "assets" / "hand.xml"
FINGERS = (1, 2, 3)  # finger numbers as users see them


def contour_polygon(shape: Shape, segments: int = 128) -> NDArray[np.float64]:
    """Counter-clockwise outline (m, frame ``f``) of ``shape``: a polygon's own vertices,
    else ``segments`` contour points at equal polar angles."""
    if isinstance(shape, Polygon):
        return shape.vertices.copy()
    phi = np.arange(segments) * 360.0 / segments
    return shape.contour_point(phi)


def _is_convex(v: NDArray[np.float64]) -> bool:
    e = np.roll(v, -1, axis=0) - v
    cross = e[:, 0] * np.roll(e[:, 1], -1) - e[:, 1] * np.roll(e[:, 0], -1)
    return bool(np.all(cross > -1e-12))


def prism_inertia(v: NDArray[np.float64], mass: float, height: float
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centroid (x, y) and full inertia ``(ixx, iyy, izz, ixy, ixz, iyz)`` about it
    of a uniform prism of polygon ``v`` (counter-clockwise), ``mass`` and ``height``.

    Standard polygon moment formulas (area, first and second moments from the
    vertex cross products), shifted to the centroid; the prism adds ``m h^2 / 12``
    about the horizontal axes.
    """
    x, y = v[:, 0], v[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    c = x * y1 - x1 * y
    area = c.sum() / 2.0
    cx = ((x + x1) * c).sum() / (6.0 * area)
    cy = ((y + y1) * c).sum() / (6.0 * area)
    sxx = ((x * x + x * x1 + x1 * x1) * c).sum() / 12.0  # integral x^2 dA
    syy = ((y * y + y * y1 + y1 * y1) * c).sum() / 12.0  # integral y^2 dA
    sxy = ((x * y1 + 2 * x * y + 2 * x1 * y1 + x1 * y) * c).sum() / 24.0  # integral xy dA
    sxx -= area * cx * cx
    syy -= area * cy * cy
    sxy -= area * cx * cy
    rho = mass / area
    h2 = mass * height**2 / 12.0
    full = np.array([rho * syy + h2, rho * sxx + h2, rho * (sxx + syy), -rho * sxy, 0.0, 0.0])
    return np.array([cx, cy]), full


def _fmt(a) -> str:
    return " ".join(f"{float(x):.9g}" for x in np.ravel(a))


@dataclass
class SimModel:
    """A compiled model and the facts the controller needs about it.

    Attributes
    ----------
    model
        The compiled ``mujoco.MjModel``.
    xml
        The MJCF text it was compiled from.
    shape
        The object's contour.
    mu
        Finger-object friction used in the model.
    thickness, mass
        Object prism height (m) and mass (kg).
    max_r
        Radius of free finger arcs (m): ``max_r_factor * shape.r_max`` (thesis 7.4.1).
    home
        ``(3, 3)`` home points of the three tips (m, frame F).
    pieces
        Names of the object's geoms that the fingers touch.
    workspaces_deg
        The hand's workspaces (deg, frame F), one ``(lo, hi)`` per finger.
    """

    model: mujoco.MjModel
    xml: str
    shape: Shape
    mu: float
    thickness: float
    mass: float
    max_r: float
    home: NDArray[np.float64]
    pieces: tuple[str, ...]
    workspaces_deg: tuple[tuple[float, float], ...]


def build_mjcf(shape: Shape, *, mu: float, thickness: float, mass: float,
               config: SimConfig,
               workspaces_deg=DEFAULT_WORKSPACES_DEG,
               ) -> tuple[str, dict]:
    """MJCF text of the hand with ``shape`` inserted, and facts about it.

    Returns
    -------
    xml, info
        ``info`` has ``max_r``, ``home`` ((3, 3) array) and ``pieces`` (geom names).
    """
    root = ET.parse(ASSET_XML).getroot()
    cfg = config
    h = float(thickness)
    zc = h / 2.0

    opt = root.find("option")
    opt.set("timestep", f"{cfg.timestep:.9g}")
    opt.set("integrator", cfg.integrator)
    opt.set("solver", cfg.solver)
    opt.set("iterations", str(int(cfg.iterations)))
    opt.set("tolerance", f"{cfg.tolerance:.3g}")
    opt.set("cone", cfg.cone)
    opt.set("impratio", f"{cfg.impratio:.9g}")
    opt.set("noslip_iterations", str(int(cfg.noslip_iterations)))

    for d in root.find("default").iter("default"):
        if d.get("class") == "finger":
            d.find("joint").set("damping", f"{cfg.finger_damping:.9g}")
            d.find("motor").set("ctrlrange", f"{-cfg.max_force:.9g} {cfg.max_force:.9g}")

    # finger homes: 120 deg apart (the middle of each workspace), radius max_r
    max_r = cfg.max_r_factor * shape.r_max
    if cfg.home_angles_deg is not None:
        angles = np.asarray(cfg.home_angles_deg, dtype=float)
    else:
        angles = np.array([(lo + hi) / 2.0 for lo, hi in workspaces_deg])
    a = np.deg2rad(angles)
    home = np.stack([max_r * np.cos(a), max_r * np.sin(a), np.full(3, zc)], axis=1)
    world = root.find("worldbody")
    for f in FINGERS:
        body = world.find(f"body[@name='finger{f}']")
        body.set("pos", _fmt(home[f - 1]))
        tip = body.find(f"geom[@name='finger{f}_tip']")
        tip.set("size", f"{cfg.tip_radius:.9g}")
        tip.set("mass", f"{cfg.finger_mass:.9g}")

    # the object
    outline = contour_polygon(shape, cfg.mesh_segments)
    centroid, inertia = prism_inertia(outline, mass, h)
    asset = root.find("asset")
    obj = ET.SubElement(world, "body", name="object", pos=_fmt([0.0, 0.0, zc]))
    ET.SubElement(obj, "freejoint", name="object_free")
    ET.SubElement(obj, "inertial", pos=_fmt([centroid[0], centroid[1], 0.0]),
                  mass=f"{mass:.9g}", fullinertia=_fmt(inertia))
    pieces: list[str] = []  # geoms the fingers touch
    table_pieces: list[str] = []  # geoms standing on the table
    if isinstance(shape, Circle):
        ET.SubElement(obj, "geom", name="object_piece0", type="cylinder",
                      size=_fmt([shape.radius_m, h / 2]), material="object_mat",
                      mass="0")
        pieces.append("object_piece0")
        table_pieces.append("object_piece0")
    else:
        if _is_convex(outline):
            polys = [outline]
        else:  # fan of convex triangles about the origin (star-shaped about it)
            polys = [np.array([[0.0, 0.0], outline[k], outline[(k + 1) % len(outline)]])
                     for k in range(len(outline))]
        for k, poly in enumerate(polys):
            verts = np.concatenate([np.column_stack([poly, np.full(len(poly), -h / 2)]),
                                    np.column_stack([poly, np.full(len(poly), h / 2)])])
            name = f"object_piece{k}"
            ET.SubElement(asset, "mesh", name=f"{name}_mesh", vertex=_fmt(verts),
                          inertia="shell")
            ET.SubElement(obj, "geom", name=name, type="mesh", mesh=f"{name}_mesh",
                          material="object_mat", mass="0")
            table_pieces.append(name)
        if isinstance(shape, Ellipse):
            # the fingers touch an exact ellipse: an ellipsoid whose equator, at the
            # fingers' height, is the contour (smooth normals, unlike the faceted prism;
            # invisible, and no contact with the table)
            c = max(shape.a, shape.b)
            ET.SubElement(obj, "geom", name="object_rim", type="ellipsoid",
                          size=_fmt([shape.a, shape.b, c]), rgba="0 0 0 0", group="3",
                          mass="0")
            pieces.append("object_rim")
        else:
            pieces.extend(table_pieces)
    ET.SubElement(obj, "site", name="object_origin", size="0.003", pos=_fmt([0, 0, h / 2]),
                  rgba="0.1 0.1 0.1 1", group="1")
    # a stripe along the object x axis shows its orientation
    ET.SubElement(obj, "geom", name="object_x_axis", type="box", group="1", mass="0",
                  size=_fmt([0.5 * shape.radius(0.0), 0.0015, 0.0005]),
                  pos=_fmt([0.5 * shape.radius(0.0), 0.0, h / 2 + 0.0005]),
                  rgba="0.6 0.2 0.1 1")

    # contact pairs and sensors
    contact = root.find("contact")
    fr = f"{mu:.9g} {mu:.9g} 0.005 0.0001 0.0001"
    for f in FINGERS:
        for p in pieces:
            ET.SubElement(contact, "pair", name=f"finger{f}_{p}", geom1=f"finger{f}_tip",
                          geom2=p, condim="3", friction=fr,
                          solref=_fmt(cfg.finger_solref), solimp=_fmt(cfg.finger_solimp))
    tfr = f"{cfg.table_mu:.9g} {cfg.table_mu:.9g} 0.005 0.0001 0.0001"
    for p in table_pieces:
        ET.SubElement(contact, "pair", name=f"table_{p}", geom1="table", geom2=p,
                      condim="3", friction=tfr, solref=_fmt(cfg.table_solref),
                      solimp=_fmt(cfg.table_solimp))
    sensor = root.find("sensor")
    for f in FINGERS:
        # net force of the fingertip on the object (world frame) and number of contacts
        ET.SubElement(sensor, "contact", name=f"finger{f}_contact", geom1=f"finger{f}_tip",
                      body2="object", data="found force", num="1", reduce="netforce")
    ET.SubElement(sensor, "framepos", name="object_pos", objtype="body", objname="object")
    xml = ET.tostring(root, encoding="unicode")
    return xml, {"max_r": max_r, "home": home, "pieces": tuple(pieces)}


def build_model(shape: Shape, *, mu: float, thickness: float, mass: float,
                config: SimConfig,
                workspaces_deg=DEFAULT_WORKSPACES_DEG) -> SimModel:
    """Compile :func:`build_mjcf`'s MJCF into a :class:`SimModel`."""
    xml, info = build_mjcf(shape, mu=mu, thickness=thickness, mass=mass, config=config,
                           workspaces_deg=workspaces_deg)
    model = mujoco.MjModel.from_xml_string(xml)
    return SimModel(model, xml, shape, float(mu), float(thickness), float(mass),
                    float(info["max_r"]), info["home"], info["pieces"],
                    tuple(tuple(map(float, w)) for w in workspaces_deg))


class HandPhysics:
    """Named accessors over ``(MjModel, MjData)`` (dm_control's ``Physics`` style).

    Every address is resolved by element name at construction; no raw index appears
    in the controller. Positions in metres, frame F (= MuJoCo world); angles in degrees.
    """

    def __init__(self, sim: SimModel, data: mujoco.MjData | None = None) -> None:
        self.sim = sim
        self.model = m = sim.model
        self.data = data if data is not None else mujoco.MjData(m)
        self.home = sim.home.copy()
        self._finger_qpos = np.array([m.joint(f"finger{f}_{ax}").qposadr[0]
                                      for f in FINGERS for ax in "xyz"])
        self._finger_dof = np.array([m.joint(f"finger{f}_{ax}").dofadr[0]
                                     for f in FINGERS for ax in "xyz"])
        self._act = np.array([m.actuator(f"finger{f}_{ax}").id for f in FINGERS for ax in "xyz"])
        if not np.array_equal(self._act, np.arange(9)):
            raise RuntimeError("finger motors must be the model's first nine actuators, in "
                               "finger/axis order (assets/hand.xml)")
        j = m.joint("object_free")
        self._obj_qpos = int(j.qposadr[0])
        self._obj_dof = int(j.dofadr[0])
        self._obj_body = m.body("object").id
        self._contact_adr = np.array([m.sensor(f"finger{f}_contact").adr[0] for f in FINGERS])
        qa = self._finger_qpos
        self._finger_qpos_slice = (slice(qa[0], qa[0] + 9)
                                   if np.array_equal(qa, qa[0] + np.arange(9)) else qa)
        self._ctrl = self.data.ctrl  # view: written in place each servo cycle
        self._home_flat = self.home.reshape(9).tolist()
        self.step_wall_s = 0.0  # wall time spent in mj_step (s)
        self.steps = 0  # physics steps taken

    # ------------------------------------------------------------------ fingers
    def tip_positions(self) -> NDArray[np.float64]:
        """``(3, 3)`` fingertip ball centres (m, frame F): home + joint displacements."""
        return self.home + self.data.qpos[self._finger_qpos_slice].reshape(3, 3)

    def tip_positions_flat(self) -> list[float]:
        """Fingertip ball centres as 9 floats ``[x1, y1, z1, ..., z3]`` (the servo's
        layout, :mod:`graspgait_env.sim.servo`)."""
        q = self.data.qpos[self._finger_qpos_slice].tolist()
        h = self._home_flat
        return [h[k] + q[k] for k in range(9)]

    def tip_velocities(self) -> NDArray[np.float64]:
        """``(3, 3)`` true fingertip velocities (m/s) (for monitoring; the controller
        estimates velocity from positions, thesis 7.4.6)."""
        return self.data.qvel[self._finger_dof].reshape(3, 3)

    def set_finger_forces(self, forces: NDArray[np.float64]) -> None:
        """Command ``(3, 3)`` tip forces (N, frame F); the motors clip to ``max_force``."""
        self._ctrl[:9] = forces.reshape(9)

    def set_finger_forces_flat(self, forces: list[float]) -> None:
        """Command tip forces given as 9 floats (the servo's layout)."""
        self._ctrl[:9] = forces

    def finger_forces(self) -> NDArray[np.float64]:
        """``(3, 3)`` commanded tip forces (N)."""
        return self.data.ctrl[:9].reshape(3, 3).copy()

    def set_tip_positions(self, tips: NDArray[np.float64]) -> None:
        """Teleport the tips (for resets); zero their velocities."""
        self.data.qpos[self._finger_qpos] = (np.asarray(tips) - self.home).reshape(9)
        self.data.qvel[self._finger_dof] = 0.0

    # ------------------------------------------------------------------ contacts
    def tip_contact_forces(self) -> NDArray[np.float64]:
        """``(3, 3)`` net force of each fingertip on the object (N, frame F); zero when
        the tip does not touch it (MuJoCo contact sensor, ``reduce="netforce"``)."""
        sd = self.data.sensordata
        return np.stack([sd[a + 1:a + 4] for a in self._contact_adr])

    def tip_in_contact(self) -> NDArray[np.bool_]:
        """``(3,)`` True where a fingertip touches the object."""
        return self.data.sensordata[self._contact_adr] > 0

    # ------------------------------------------------------------------ object
    def object_pose(self) -> tuple[float, float, float]:
        """True object pose ``(x, y, theta_deg)`` in frame F (theta in (-180, 180])."""
        q = self.data.qpos
        a = self._obj_qpos
        return float(q[a]), float(q[a + 1]), yaw_deg_from_quat(q[a + 3], q[a + 4], q[a + 5],
                                                               q[a + 6])

    def object_height(self) -> float:
        """Height of the object's origin above the table (m)."""
        return float(self.data.qpos[self._obj_qpos + 2])

    def object_tilt_deg(self) -> float:
        """Angle between the object's z axis and the vertical (deg)."""
        w, x, y, z = self.data.qpos[self._obj_qpos + 3:self._obj_qpos + 7]
        return tilt_deg_from_quat(w, x, y, z)

    def set_object_pose(self, x: float, y: float, theta_deg: float) -> None:
        """Place the object flat on the table at ``(x, y, theta_deg)``, at rest."""
        a = self._obj_qpos
        self.data.qpos[a:a + 7] = [x, y, self.sim.thickness / 2.0, *quat_from_yaw_deg(theta_deg)]
        self.data.qvel[self._obj_dof:self._obj_dof + 6] = 0.0

    def apply_object_force(self, force_xy: tuple[float, float] | NDArray[np.float64]) -> None:
        """Apply a horizontal disturbance force (N, frame F) at the object's centre of
        mass until changed (a tug, thesis 7.5)."""
        fx, fy = float(force_xy[0]), float(force_xy[1])
        self.data.xfrc_applied[self._obj_body, :3] = [fx, fy, 0.0]

    # ------------------------------------------------------------------ time
    @property
    def time(self) -> float:
        """Simulation time (s)."""
        return float(self.data.time)

    def step(self, nstep: int = 1) -> None:
        """Advance the physics ``nstep`` timesteps with the controls held.

        The wall time spent in ``mj_step`` and the steps taken accumulate in
        :attr:`step_wall_s` and :attr:`steps` (the step-rate benchmark)."""
        t0 = _perf_counter()
        mujoco.mj_step(self.model, self.data, nstep)
        self.step_wall_s += _perf_counter() - t0
        self.steps += nstep

    def reset(self) -> None:
        """Reset the data to the model's initial state (fingers home, object at origin)."""
        mujoco.mj_resetData(self.model, self.data)
        self.set_object_pose(0.0, 0.0, 0.0)
        mujoco.mj_forward(self.model, self.data)
