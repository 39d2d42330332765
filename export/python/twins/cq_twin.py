"""The CadQuery twin of one manifest part: the registry of family twin modules ([`TWINS`]),
each asked in turn for the part's solid, then the recorded print placement."""

from __future__ import annotations

from . import cq_common as C
from . import (cq_casing, cq_fixtures, cq_flat, cq_housing, cq_layers, cq_molds, cq_shaft_body,
               cq_spacer)
from .families import family  # noqa: F401 (re-exported)

# The twin modules, one per part family: each has `twin(part)`, the part's exact solid in its
# own frame, or None for a part of another family. Adding a family adds its module here.
TWINS = (cq_molds, cq_layers, cq_housing, cq_shaft_body, cq_casing, cq_flat, cq_spacer,
         cq_fixtures)


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
