"""The CadQuery twin of one manifest part: dispatch on its role (and name) to the family's
builder, then the recorded print placement."""

from __future__ import annotations

from . import cq_common as C
from . import cq_fixtures, cq_housing, cq_layers, cq_molds
from .families import family  # noqa: F401 (re-exported)


# Parts with more marker features than this are checked on a sample (see `sampling`).
MAX_FULL_FEATURES = 200
# The sampled region: the wedge of azimuths [0, WEDGE_DEG] about the sensor axis.
WEDGE_DEG = 45.0


def _marker_sets(p: dict) -> list:
    base = p.get("base", p)
    return base.get("markers") or []


def sampling(part: dict):
    """None when the whole part is checked, else the documented sample: the part is cut to the
    wedge of azimuths [0, WEDGE_DEG] (sensor frame) on both sides, and the twin carries only the
    features that reach into that wedge. Used for parts with more than MAX_FULL_FEATURES marker
    features (the 543-dimple ShadowTac mold): OCCT needs about 75 s to mesh all of them for the
    Hausdorff distance, over the CI budget. Every feature is still checked by the manifold3d
    twin, and STEP export builds the whole part."""
    sets = _marker_sets(part["params"])
    total = sum(len(m["placements_deg"]) for m in sets)
    if total <= MAX_FULL_FEATURES:
        return None
    return {"wedge_deg": [0.0, WEDGE_DEG], "features_total": total}


def _in_wedge(params: dict, sample: dict) -> tuple[dict, int]:
    """A copy of `params` whose marker sets keep the features reaching into the wedge."""
    import copy
    import math
    q = copy.deepcopy(params)
    base = q.get("base", q)
    kept = 0
    lo, hi = sample["wedge_deg"]
    for ms in base.get("markers") or []:
        f = ms["feature"]
        reach = f["diameter_mm"] + f["height_mm"]
        body = C.Body(base["body"])
        keep = []
        for polar, az in ms["placements_deg"]:
            r = body.surface_point(ms["surface_offset_mm"], polar)[0]
            margin = 180.0 if r <= reach else math.degrees(math.asin(reach / r))
            a = (az - lo) % 360.0
            if a <= hi - lo + margin or a >= 360.0 - margin:
                keep.append([polar, az])
        ms["placements_deg"] = keep
        kept += len(keep)
    return q, kept


def wedge(sample: dict, size: float = 1000.0):
    """The sampled wedge as a solid, sensor frame."""
    import math
    lo, hi = (math.radians(a) for a in sample["wedge_deg"])
    mid = 0.5 * (lo + hi)
    far = size / math.cos(0.5 * (hi - lo))
    pts = [(0.0, 0.0), (far * math.cos(lo), far * math.sin(lo)),
           (size / math.cos(0.0) * 2 * math.cos(mid), size * 2 * math.sin(mid)),
           (far * math.cos(hi), far * math.sin(hi))]
    import cadquery as cq
    w = cq.Wire.makePolygon([cq.Vector(x, y, -size) for x, y in pts], close=True)
    return cq.Solid.extrudeLinear(cq.Face.makeFromWires(w), cq.Vector(0, 0, 2 * size))


def build(part: dict, sample: dict | None = None):
    """The exact solid of `part` in print orientation (the manifest's placement applied); with
    `sample` (see `sampling`), only its wedge, with the features that reach into it."""
    if sample is not None:
        params, kept = _in_wedge(part["params"], sample)
        sample["features_kept"] = kept
        whole = _build_sensor({**part, "params": params})
        return C.place(C.common(whole, wedge(sample)), part["params"])
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
    elif role == "printed_skin":
        s = cq_layers.printed_skin(p, tips=False)
    elif role == "marker_tips":
        s = cq_layers.printed_skin(p, tips=True)
    elif role == "negative_mold":
        s = cq_layers.boundary_negative(p)
    elif role == "shell_half":
        s = cq_housing.shell_half(p, name.rsplit("_", 1)[1])
    elif role == "indenter":
        s = cq_fixtures.indenter(p)
    elif name == "pin_dome":
        s = cq_fixtures.pin_dome(p)
    elif role == "calibration pin":
        s = cq_fixtures.pin(p)
    elif name == "semidome_holder":
        s = cq_fixtures.semidome_holder(p)
    elif name.startswith("semidome_"):
        s = cq_fixtures.semidome_half(p)
    else:
        raise C.TwinError(f"part {name!r} (role {role!r}): no CadQuery twin")
    return s
