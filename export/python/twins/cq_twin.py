"""The CadQuery twin of one manifest part: dispatch on its role (and name) to the family's
builder, then the recorded print placement."""

from __future__ import annotations

from . import cq_common as C
from . import cq_casing, cq_fixtures, cq_flat, cq_housing, cq_layers, cq_molds, cq_shaft_body
from .families import family  # noqa: F401 (re-exported)


def build(part: dict):
    """The exact solid of `part` in print orientation (the manifest's placement applied)."""
    return C.place(_build_sensor(part), part["params"],
                   "T_print_indenter" if part["role"] == "indenter" else "T_print_sensor")


def _build_sensor(part: dict):
    """The exact solid in its own frame (sensor frame; indenter frame for indenters)."""
    role, name, p = part["role"], part["name"], part["params"]
    if role == "master_pattern":
        s = cq_molds.master_pattern(p) if "master" in p else cq_layers.boundary_master(p)
    elif role == "mold_box":
        s = cq_molds.mold_box(p) if "master" in p else cq_layers.boundary_box(p)
    elif role in ("core_holder", "casting_jig"):
        s = cq_molds.core_holder(p)
    elif role == "mold_half":
        s = cq_molds.mold_half(p, name.rsplit("_", 1)[1])
    elif role == "open_mold":
        s = cq_layers.open_mold(p)
    elif role == "open_mold_piece":
        s = cq_layers.open_mold_piece(p)
    elif role == "printed_skin":
        s = cq_layers.printed_skin(p, tips=False)
    elif role == "marker_tips":
        s = cq_layers.printed_skin(p, tips=True)
    elif role == "negative_mold":
        s = cq_layers.boundary_negative(p)
    elif role == "shell_half":
        s = cq_housing.shell_half(p, name.rsplit("_", 1)[1])
    elif role == "shell_tube":
        s = cq_housing.shell_tube(p)
    elif role == "shell_collar":
        s = cq_housing.shell_collar(p)
    elif role == "shell_base":
        s = cq_housing.shell_base(p)
    elif role == "tip_fitting":
        s = cq_shaft_body.tip_fitting(p)
    elif role == "shaft_body":
        s = cq_shaft_body.shaft_body(p)
    elif role == "robot_mount":
        s = cq_shaft_body.robot_mount(p)
    elif role == "casing":
        s = cq_casing.casing(p)
    elif role == "gripper_base":
        s = cq_casing.gripper_base(p)
    elif role in ("shell_holder", "sensor_base", "camera_holder", "diffusion_ring"):
        s = cq_casing.fingertip_part(p, role)
    elif role == "casting_tray":
        s = cq_flat.casting_tray(p)
    elif role == "indenter":
        s = cq_fixtures.indenter(p)
    elif name == "grid_plate":
        s = cq_fixtures.grid_plate(p)
    elif name == "pin_dome":
        s = cq_fixtures.pin_dome(p)
    elif name == "pin_dome_ring":
        s = cq_fixtures.pin_dome_ring(p)
    elif role == "calibration pin":
        s = cq_fixtures.pin(p)
    elif name == "semiplate_holder":
        s = cq_fixtures.semiplate_holder(p)
    elif name.startswith("semiplate_"):
        s = cq_fixtures.semiplate_half(p)
    elif name == "semidome_holder":
        s = cq_fixtures.semidome_holder(p)
    elif name.startswith("semidome_"):
        s = cq_fixtures.semidome_half(p)
    else:
        raise C.TwinError(f"part {name!r} (role {role!r}): no CadQuery twin")
    return s
