"""graspgait_env: grasp gaits for planar object manipulation (Leveroni, MIT 1997).

The map-level core (this package's top level) is pure NumPy: shapes, force closure,
grasp maps, workspaces. Physics (``graspgait_env.sim``) and Gymnasium environments
(``graspgait_env.envs``) build on it and are imported only when used.
"""

from graspgait_env.errors import ConfigError, GraspGaitInputError, NoGaitError
from graspgait_env.force_closure import (
    cone_margin_deg,
    force_closure_nguyen,
    force_closure_wrench,
)
from graspgait_env.grasp_map import GraspMap, grasp_map, grid_angles_deg
from graspgait_env.objects import bundled_objects, load_object, object_from_dict
from graspgait_env.shapes import Circle, Ellipse, Polygon, Shape, Stadium
from graspgait_env.workspace import (
    CircularReach,
    FingerPairBox,
    Hand,
    effective_hand,
    load_hand,
    workspace_map,
)

__version__ = "0.2.0"

# `import graspgait_env` registers every Gymnasium id (GraspGait-v0, GraspGaitRandom-v0);
# registration is skipped when gymnasium is not installed, so the map-level core keeps
# working without it.
from graspgait_env.envs.registration import register_envs as _register_envs  # noqa: E402

_register_envs()

__all__ = [
    "Circle",
    "CircularReach",
    "ConfigError",
    "Ellipse",
    "FingerPairBox",
    "GraspGaitInputError",
    "GraspMap",
    "Hand",
    "NoGaitError",
    "Polygon",
    "Shape",
    "Stadium",
    "bundled_objects",
    "cone_margin_deg",
    "effective_hand",
    "force_closure_nguyen",
    "force_closure_wrench",
    "grasp_map",
    "grid_angles_deg",
    "load_hand",
    "load_object",
    "object_from_dict",
    "workspace_map",
]
