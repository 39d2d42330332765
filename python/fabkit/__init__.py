"""fabkit: parametric fabrication kits, calibration fixtures and ground truth for vision-based
tactile sensors, from Python.

The same library the ``fabkit`` command line runs, called in-process: designs (load, read and set
parameters by path, presets, validation), kits (build, meshes as numpy arrays, pour table,
export byte-identical to ``fabkit export``), fixtures (point tables as numpy arrays), extrinsics
calibration from numpy arrays, a flat sensor's camera from a board press (``calibrate_board``,
as ``fabkit calibrate board``), and ground-truth depth rendered straight into numpy arrays or read
back from a ``fabkit groundtruth`` folder (``GroundTruth``; a real sphere press's folder:
``PressGroundTruth``).

Units: mm and degrees; image coordinates in px. Frames: docs/conventions.md (sensor frame, camera
frame x right, y down, z forward). Errors are ``FabkitError`` subclasses whose message is what the
command line prints after ``error:``.
"""

from ._fabkit import (  # noqa: F401
    __version__,
    DEFAULT_CHORD_TOLERANCE_MM,
    DEFAULT_DESIGN,
    FabkitError,
    DesignError,
    ExportError,
    CalibrationError,
    GroundTruthError,
    InternalError,
    ParamError,
    Design,
    Kit,
    Part,
    build_kit,
    library_designs,
    Fixtures,
    build_fixtures,
    Camera,
    solve_extrinsics,
    calibrate_board,
    ProtrusionSet,
    DepthRenderer,
    read_protrusions,
    read_pin_captures,
    PhotometricModel,
    read_photometric,
    GROUNDTRUTH_FILES,
)
from .groundtruth import GroundTruth, PressGroundTruth, StitchedPair  # noqa: F401
from .sweep import SweepTables, sweep  # noqa: F401
