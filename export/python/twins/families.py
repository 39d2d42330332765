"""Part families of the report (no CadQuery needed)."""


def family(part: dict) -> str:
    """The part family the report groups rows by."""
    role, name, params = part["role"], part["name"], part["params"]
    if role in ("master_pattern", "mold_box"):
        return "master patterns and mold boxes" if "master" in params else \
            "master patterns and mold boxes (boundary)"
    if role == "negative_mold":
        return "slot molds (inner negatives)"
    if role in ("mold_half", "core_holder", "casting_jig"):
        return "two-piece molds" if role == "mold_half" else "core holders / casting jigs"
    if role == "open_mold":
        return "dimple molds"
    if role == "open_mold_piece":
        return "two-piece dimple molds"
    if role == "recess_insert":
        return "recess inserts"
    if role == "printed_skin":
        return "layer shells"
    if role == "marker_tips":
        return "pin tips"
    if role in ("shell_half", "shell_collar", "shell_tube", "shell_base"):
        return "housings"
    if role in ("tip_fitting", "shaft_body", "robot_mount"):
        return "bayonet bodies and fittings"
    if role in ("casing", "gripper_base", "shell_holder", "sensor_base", "camera_holder",
                "diffusion_ring"):
        return "casings and bases"
    if role in ("flat_shell", "flat_base", "isolation_ring"):
        return "flat housings"
    if role == "casting_tray":
        return "casting trays (flat skins)"
    if role == "indenter":
        return "indenters"
    if name == "grid_plate":
        return "indenter grid plates (flat skins)"
    if name in ("pin_dome", "pin_dome_ring") or role == "calibration pin":
        return "pin-hole domes and pins"
    if name.startswith("semidome"):
        return "semi-domes"
    if name.startswith("semiplate"):
        return "semi-plates (flat skins)"
    return role
