"""The CadQuery twin of one manifest part: the registry of family twin modules ([`TWINS`]),
each asked in turn for the part's solid, then the recorded print placement."""

from __future__ import annotations

from . import cq_common as C
from . import (cq_casing, cq_fixtures, cq_flat, cq_flat_housing, cq_housing, cq_layers, cq_molds,
               cq_shaft_body, cq_spacer)
from .families import family  # noqa: F401 (re-exported)

# The twin modules, one line per family as in the Rust registries (designs/src/parts/
# registry.rs, layer_registry.rs): each has `twin(part)`, the part's exact solid in its own
# frame, or None for a part of another family. Adding a family adds its line here.
TWINS = (
    cq_molds,       # parts::molds: master patterns, mold boxes, mold halves, core holders
    cq_layers,      # parts::layers and the layer features: skins, tips, open molds, inserts
    cq_housing,     # parts::housing
    cq_shaft_body,  # parts::shaft_body and robot_mount
    cq_casing,      # parts::casing and fingertip_base
    cq_flat,        # parts::flat and lasercut: casting trays
    cq_flat_housing,  # parts::flat_housing: a flat sensor's shell, base, isolation ring
    cq_spacer,      # parts::spacer
    cq_fixtures,    # fixtures: pin domes, pins, semi-domes, plates, indenters
)


def build(part: dict):
    """The exact solid of `part` in print orientation (the manifest's placement applied)."""
    return C.place(_build_sensor(part), part["params"],
                   "T_print_indenter" if part["role"] == "indenter" else "T_print_sensor")


def _build_sensor(part: dict):
    """The exact solid in its own frame (sensor frame; indenter frame for indenters)."""
    for module in TWINS:
        s = module.twin(part)
        if s is not None:
            return s
    raise C.TwinError(f"part {part['name']!r} (role {part['role']!r}): no CadQuery twin")
