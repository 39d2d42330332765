"""CadQuery twin of the spacer ring (designs/src/parts/spacer.rs, the worked example family of
docs/src/development.md), from the part's manifest `params`: the ring's parameters and the
base plane's height."""

from __future__ import annotations

from . import cq_common as C


def spacer(params: dict):
    """The ring, sensor frame: the outer cylinder less the bore, from `height_mm` below the
    base plane up to it."""
    p, zb = params["spacer"], params["base_z_mm"]
    z0 = zb - p["height_mm"]
    return C.cut(C.cylinder_z(p["outer_diameter_mm"] / 2.0, z0, zb),
                 [C.cylinder_z(p["inner_diameter_mm"] / 2.0, z0 - 1.0, zb + 1.0)])


def twin(part: dict):
    """The twin of the spacer (sensor frame), or None when `part` is not it."""
    return spacer(part["params"]) if part["role"] == "spacer" else None
