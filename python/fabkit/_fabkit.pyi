"""Type stubs of fabkit's native module (PyO3). Units: mm, degrees, px; frames: docs/conventions.md.

Every call that builds, renders or solves releases the GIL. Every error is a FabkitError subclass
whose message is what the ``fabkit`` command line prints after ``error:`` for the same failure; a
Rust panic is raised as InternalError, never passed to the interpreter.
"""

from os import PathLike
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
#: The library design `Design.load()` loads by default (`rtac0`).
DEFAULT_DESIGN: str
#: The default chord tolerance of every build, mm (0.01).
DEFAULT_CHORD_TOLERANCE_MM: float
#: The names of a ground-truth dataset's files (manifest, pairs, left_mask, right_mask,
#: reference_dir, maps, delta_maps, normals, npy_suffix, png16_suffix, preview_suffix,
#: arrays_npz, points, contact_mask, image, pairs_header) and its 16-bit PNG encodings
#: (png16_depth, png16_delta: scale_mm_per_count, offset_counts), as the writer uses them.
GROUNDTRUTH_FILES: Dict[str, Any]

StrPath = Union[str, PathLike]
#: progress(done, total, message), called as long work advances (from any thread, GIL held).
Progress = Callable[[int, int, str], Any]

class FabkitError(Exception):
    """Base class of every fabkit error."""

class DesignError(FabkitError):
    """A design or fixture parameters that do not load or break their rules.

    ``errors`` lists every violated rule at once (empty for a YAML error, whose message gives
    file:line:column)."""

    errors: List[ParamError]

class ExportError(FabkitError):
    """An export that cannot be written; nothing is written then."""

class CalibrationError(FabkitError):
    """A camera, point set or observation set that cannot be read, or a pose that cannot be solved."""

class GroundTruthError(FabkitError):
    """Ground-truth inputs that cannot be read or rendered."""

class InternalError(FabkitError):
    """A defect in fabkit (a Rust panic caught at the boundary): please report it."""

class ParamError:
    """One violated rule: ``path = value: rule``."""

    path: str
    value: str
    rule: str

class Design:
    """A parametric sensor design (the YAML schema of designs/library/*.yaml).

    Parameters are read and set by the paths presets and sweep files use
    (``design["layers[1].outer_radius_mm"] = 12.5``); a short path naming one parameter
    (``markers.spacing_mm``) works too. Setting checks the value's type at once (DesignError);
    the rules between parameters are checked by ``validate()`` and by every build."""

    @staticmethod
    def load(
        source: Optional[StrPath] = None,
        *,
        allow_data_dirs: Sequence[StrPath] = ...,
        max_data_file_bytes: Optional[int] = None,
    ) -> Design:
        """A library design by name (default ``rtac0``) or a YAML file (marker CSV files read
        relative to it). Raises DesignError (file:line:column), TypeError."""
    @staticmethod
    def from_yaml(text: str, origin: str = "<yaml>") -> Design: ...
    @staticmethod
    def from_dict(data: Mapping[str, Any]) -> Design:
        """A design from the YAML's form as a dict (what ``to_dict()`` returns)."""
    def to_dict(self) -> Dict[str, Any]: ...
    def to_json(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str:
        """The path, ``embedded:<name>``, ``<yaml>`` or ``<dict>``."""
    @property
    def sha256(self) -> str:
        """sha256 of the design's text as loaded, as in an export's manifest."""
    @property
    def presets(self) -> List[str]: ...
    def parameter_paths(self) -> List[str]: ...
    def __getitem__(self, path: str) -> Any:
        """The value at a parameter path; KeyError (with the nearest paths) for an unknown one."""
    def __setitem__(self, path: str, value: Any) -> None:
        """KeyError for an unknown path; DesignError (path, value, rule) for a value of the
        wrong type."""
    def with_values(self, values: Mapping[str, Any]) -> Design: ...
    def with_preset(self, name: str) -> Design:
        """The design with a preset applied (as ``--preset``), renamed ``<name>_<preset>``."""
    def validate(self, chord_tolerance_mm: float = 0.01) -> Dict[str, Any]:
        """Every rule at once, as ``fabkit validate``; returns the resolved layer stack (mm,
        inner to outer). Raises DesignError whose ``errors`` lists every violation."""

def library_designs() -> List[Tuple[str, str]]:
    """(name, description) of every library design, as ``fabkit designs``."""

class Part:
    """One printable part, in print orientation (resting on z = 0), mm."""

    @property
    def name(self) -> str: ...
    @property
    def role(self) -> str: ...
    @property
    def material(self) -> str: ...
    @property
    def technology(self) -> str:
        """``FDM`` or ``SLA``."""
    def mesh(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]:
        """(vertices (n, 3) float64 mm, triangles (m, 3) uint32): the mesh ``fabkit export``
        writes (float32-rounded coordinates, shared vertices, counter-clockwise from outside)."""
    def numbers(self) -> Dict[str, Any]:
        """The manifest's parts[] entry without file and sha256: volume_mm3, mass_g,
        surface_area_mm2, bbox_mm, vertices, triangles, genus, role, material, params..."""

class Kit:
    """A built kit: the printable parts of a design and its pours."""

    @property
    def name(self) -> str: ...
    @property
    def design(self) -> Design: ...
    @property
    def chord_tolerance_mm(self) -> float: ...
    @property
    def parts(self) -> List[Part]: ...
    def part(self, name: str) -> Part: ...
    def casts(self) -> List[Dict[str, Any]]:
        """The pour table in casting order, as the manifest's casts[]."""
    def summary(self) -> Dict[str, Any]: ...
    def export(
        self,
        out: StrPath,
        *,
        formats: Sequence[str] = ("stl", "3mf"),
        force: bool = False,
        command_line: Optional[Sequence[str]] = None,
        progress: Optional[Progress] = None,
    ) -> Dict[str, Any]:
        """Writes the folder ``fabkit export`` (or ``fabkit fixtures``) writes, byte for byte
        for the same options and ``command_line``; returns the manifest. ``formats``: ``stl``,
        ``3mf``, ``step``, and for a sensor's kit the simulators' ``mjcf``, ``urdf``, ``usd``
        (the design's nominal camera and lights, as the CLI's). Raises ExportError, or
        ValueError for an unknown format or a simulator format of fixtures; nothing is written
        then."""
    def __len__(self) -> int: ...

def build_kit(
    design: Design,
    *,
    chord_tolerance_mm: float = 0.01,
    max_triangles: int = ...,
    progress: Optional[Progress] = None,
) -> Kit:
    """Validates and builds the kit (as ``fabkit export``), refused before building when
    estimated over ``max_triangles``. Raises DesignError, ValueError."""

class Fixtures:
    """A design's calibration fixtures: printable parts and data files."""

    @property
    def kit(self) -> Kit: ...
    @property
    def point_table(self) -> Dict[str, np.ndarray]:
        """point_table.csv as arrays, sensor frame, mm: id (n,) uint32, ring (n,) uint32,
        tip_mm (n, 3), contact_mm (n, 3), axis (n, 3) unit, indentation_depth_mm (n,)."""
    @property
    def capture_plan(self) -> List[List[int]]: ...
    @property
    def files(self) -> Dict[str, bytes]: ...

def build_fixtures(
    design: Design,
    *,
    params: Union[None, Mapping[str, Any], StrPath] = None,
    pins_preset: Optional[str] = None,
    semidomes: Optional[int] = None,
    seed: Optional[int] = None,
    chord_tolerance_mm: float = 0.01,
    max_triangles: int = ...,
    progress: Optional[Progress] = None,
) -> Fixtures:
    """As ``fabkit fixtures`` (``--params``, ``--pins-preset``, ``--semidomes``, ``--seed``).
    The library's R-Tac0 defaults to its paper's kit: the published dome and 100 semi-domes
    (``pins_preset="default"`` for fabkit's own dome, ``semidomes=0`` for none)."""

class Camera:
    """Intrinsics (px), image size and lens distortion (``fisheye``, ``plumb_bob``,
    ``rational_polynomial`` as OpenCV). Camera frame x right, y down, z forward."""

    def __init__(
        self,
        fx_px: float,
        fy_px: float,
        cx_px: float,
        cy_px: float,
        width_px: int,
        height_px: int,
        distortion_model: str = "plumb_bob",
        coefficients: Sequence[float] = (0.0, 0.0, 0.0, 0.0, 0.0),
    ) -> None: ...
    @staticmethod
    def from_file(path: StrPath, model: Optional[str] = None) -> Camera:
        """OpenCV YAML/XML, ROS camera_info YAML or fabkit JSON (as ``--camera``, with
        ``--camera-model`` ``model``). Raises CalibrationError naming file, line and field."""
    @property
    def intrinsics(self) -> Dict[str, Any]: ...
    @property
    def shape(self) -> Tuple[int, int]:
        """(height, width), px."""
    def project(self, points_mm: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Camera-frame points (n, 3) mm to pixels (n, 2) px; NaN where not imaged."""

def solve_extrinsics(
    points_mm: npt.ArrayLike,
    pixels_px: npt.ArrayLike,
    camera: Union[Camera, StrPath],
    *,
    ids: Optional[Sequence[str]] = None,
    ransac: bool = True,
    threshold_px: float | None = None,
    seed: Optional[int] = None,
    design: Optional[Design] = None,
) -> Dict[str, Any]:
    """The camera pose from sensor-frame points (n, 3) mm and pixels (n, 2) px, as ``fabkit
    calibrate extrinsics``. Returns T_cam_sensor (4, 4) (sensor -> camera, mm), residuals_px
    (n, 2) (NaN where a point does not project), inliers and outliers (n,) bool,
    rms_reprojection_error_px and report (extrinsics.json's content). With ``design`` the rays
    bend by Snell's law at its interfaces (the filling gel's free surface, the core's faces,
    ...), as ``calibrate extrinsics --design``; the report lists them (``optical_path``). The
    same pairs in any order give the same pose; ``seed`` has no effect (a DeprecationWarning). Raises
    CalibrationError (a non-finite entry: ``points_mm[i, j] = nan: must be finite``),
    ValueError (shapes)."""

def calibrate_board(
    points: StrPath,
    reference: StrPath,
    images: Union[StrPath, Sequence[StrPath]],
    out: StrPath,
    *,
    plane_distance_mm: Optional[float] = None,
    design: Union[Design, StrPath, None] = None,
    capture_plan: Optional[StrPath] = None,
    board_turn_deg: float = 0,
    points_from: str = "contact",
    force: bool = False,
    command_line: Optional[Sequence[str]] = None,
) -> Dict[str, Any]:
    """A flat sensor's camera from a press of its calibration board (one capture, or a grid
    plate's several with ``capture_plan``), written into ``out`` as ``fabkit calibrate board``
    writes it (extrinsics.json/.yaml, camera.yaml, camera_info.yaml, camera.json,
    observations.csv, pixel_to_plane_mm.npy, overlay.png). ``plane_distance_mm`` None: from
    ``design``'s flat housing (a Design, library name or YAML path) or the design the point
    table names. ``board_turn_deg`` (0, 90, 180, 270): the board's grid turned in the image
    (the camera turned about its optical axis; +x along u turned towards v). Returns
    T_cam_sensor (4, 4), camera (Camera, read back from camera.json), ids, observed_px and
    residuals_px (n, 2), rms_reprojection_error_px, report (extrinsics.json's content), files,
    warnings. Raises CalibrationError with the CLI's message, DesignError (a design that does
    not load), ValueError / TypeError (arguments)."""

class ProtrusionSet:
    """One semi-dome (semi-plate) configuration: a pattern at 0 deg (+x half) or 180 deg;
    or one capture of a pin dome (read_pin_captures)."""

    @property
    def name(self) -> str:
        """``<pattern>_<orientation_deg>`` (a pin capture: its pins, ``01_02_06_14_22``), the
        frame's folder in a ground-truth output."""
    @property
    def pattern(self) -> str: ...
    @property
    def orientation_deg(self) -> int: ...
    @property
    def pins(self) -> List[str]:
        """A pin capture's pin ids in the capture plan's order; empty for a pattern."""
    def __len__(self) -> int: ...

def read_protrusions(fixtures_dir: StrPath, design: Design) -> List[ProtrusionSet]:
    """The configurations of a ``fabkit fixtures`` folder (protrusions/index.json), two per
    pattern in index order. Raises GroundTruthError naming the file."""

def read_pin_captures(fixtures_dir: StrPath, design: Design) -> List[ProtrusionSet]:
    """The captures of a pin dome's ``fabkit fixtures`` folder (points/capture_plan.csv),
    each its planned pins pressed in, named by its pins as ``fabkit groundtruth
    --pin-captures`` names its folders. Raises GroundTruthError naming the file and line."""

class PhotometricModel:
    """A sensor's photometric model from ``fabkit calibrate photometric`` (read_photometric)."""

    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def bit_depth(self) -> int:
        """8 or 16, that of the captures it was fitted to."""

def read_photometric(dir: StrPath) -> PhotometricModel:
    """The model in the output folder of ``fabkit calibrate photometric`` (photometric.json,
    appearance.npy). Raises GroundTruthError naming the file and what does not fit.
    ``DepthRenderer.image(..., photometric=model)`` refuses it (GroundTruthError) for another
    design, camera file or extrinsics file than it was fitted with (by sha256, as
    ``fabkit groundtruth --photometric``), and warns (UserWarning) where the renderer's camera
    or pose was given as values, which cannot be checked."""

class DepthRenderer:
    """Ground-truth depth of a design's skin through a calibrated camera (R-Tac0 Sec. IV-B,
    Eq. (2)-(3)), the frames ``fabkit groundtruth`` writes, as arrays: (H, W) row-major
    float32, NaN where the pixel's ray misses the skin."""

    def __init__(
        self,
        design: Design,
        camera: Union[Camera, StrPath],
        T_cam_sensor: Union[npt.ArrayLike, StrPath],
        *,
        max_pixels: int = 2048 * 2048,
    ) -> None:
        """T_cam_sensor (4, 4): sensor frame -> camera frame, mm, or the path of the
        extrinsics.json of ``fabkit calibrate extrinsics``; the camera centre must be inside
        the sensor body. max_pixels: 1 to 2048 * 2048 (the render's memory budget,
        2 GiB), else ValueError. Raises GroundTruthError for a larger image or a camera that
        sees the skin in under 1 % of its pixels."""
    @property
    def shape(self) -> Tuple[int, int]: ...
    @property
    def camera_centre_mm(self) -> Tuple[float, float, float]: ...
    def reference(self) -> Dict[str, np.ndarray]:
        """range_mm, zdepth_mm (H, W) float32 mm; normals (H, W, 3) float32, camera frame,
        out of the elastomer."""
    def indented(self, protrusions: ProtrusionSet) -> Dict[str, np.ndarray]:
        """As reference() for the skin pushed in by the protrusions, plus delta_range_mm,
        delta_zdepth_mm (indented minus reference, mm) and contact (H, W) bool."""
    def indented_all(
        self, protrusions: Sequence[ProtrusionSet], *, progress: Optional[Progress] = None
    ) -> List[Dict[str, np.ndarray]]: ...
    def masks(self) -> Tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
        """(left, right) half masks (H, W): rays meeting the reference surface at sensor-frame
        x < 0 / x >= 0."""
    def image(
        self,
        protrusions: Optional[ProtrusionSet] = None,
        *,
        frame: int = 0,
        photometric: Optional[PhotometricModel] = None,
    ) -> np.ndarray:
        """The tactile image the camera sees, (H, W, 3) RGB uint8 or uint16
        (optics.camera.bit_depth), as `fabkit groundtruth --images` writes image.png: the
        reference skin, or the skin indented by the protrusions with their shadows, under the
        design's lights, markers moved with the skin, the camera's gain, vignetting and seeded
        noise. frame: the frame's own noise (the CLI: reference 0, configuration i -> i + 1).
        photometric: the sensor's own appearance from its fitted model instead (``fabkit
        groundtruth --images --photometric``), noise-free, at the model's bit depth.
        Raises GroundTruthError naming the path of a bad optics value, or for a model of
        another camera size."""
    def write(
        self,
        out: StrPath,
        fixtures: StrPath,
        *,
        pin_captures: bool = False,
        format: str = "npy",
        images: bool = False,
        photometric: Optional[PhotometricModel] = None,
        force: bool = False,
        max_output_bytes: int = 1_000_000_000,
        yes: bool = False,
        command_line: Optional[Sequence[str]] = None,
        progress: Optional[Progress] = None,
    ) -> List[str]:
        """Writes the ground-truth dataset of a ``fabkit fixtures`` folder to ``out`` as
        ``fabkit groundtruth`` does, byte for byte for the same inputs and ``command_line``
        (default ``sys.argv``; recorded in manifest.json). format: npy, npz or png (ValueError
        else); images: each frame's image.png, from ``photometric`` when given. ``out`` is
        replaced only when it holds earlier ground truth of the same inputs (any, with force).
        The output is bounded first: over max_output_bytes it is refused unless yes, and
        beyond the free space. Returns the relative paths written, manifest.json last. Raises
        GroundTruthError naming the file and the rule."""

def _library_build_seconds(
    design: Design, repeats: int, *, chord_tolerance_mm: float = 0.01
) -> List[float]:
    """Benchmark hook: wall times, s, of the library's kit build alone."""

# The native side of fabkit.sweep (python/fabkit/sweep.py); not a public interface.
def _sweep_plan(
    design: Design, variants: Any, chord_tolerance_mm: float
) -> Tuple[List[str], List[Tuple[int, str, str]]]: ...
def _sweep_base(design: Design) -> str: ...
def _sweep_evaluate(
    base_json: str, chord_tolerance_mm: float, max_triangles: int, index: int, id: str,
    params_json: str, outputs: List[str] = ..., out: Optional[str] = None, source: str = "",
    command_line: List[str] = ...,
) -> str: ...
def _sweep_run_threads(
    base_json: str, chord_tolerance_mm: float, max_triangles: int,
    variants: List[Tuple[int, str, str]], jobs: int, progress: Optional[Progress] = None,
    outputs: List[str] = ..., out: Optional[str] = None, source: str = "",
    command_line: List[str] = ...,
) -> List[str]: ...
def _sweep_check_outputs(outputs: List[str], out: Optional[str] = None) -> None: ...
def _sweep_tables(parameters: List[str], results: List[str], build_time: bool) -> Tuple[str, str]: ...
