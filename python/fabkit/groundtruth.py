"""Reader for the output folder of ``fabkit groundtruth``.

``fabkit groundtruth --out DIR`` renders the elastomer surface of a sensor through a calibrated
camera: a *reference* frame (undeformed skin) and one frame per protrusion configuration
``<pattern>_0`` (pattern on the sensor's +x half) and ``<pattern>_180`` (pattern on the -x
half). N patterns give N x N *stitched pairs* (R-Tac0 Sec. IV-B, Fig. 6): pair ``k`` of
``pairs.csv`` takes the right (+x) half of ``<right_pattern>_0`` on ``right_mask.png`` and the
left (-x) half of ``<left_pattern>_180`` on ``left_mask.png``.

:class:`GroundTruth` is a plain Python sequence of :class:`StitchedPair` (``len``, indexing,
iteration), loading frames lazily from disk, so it can back a PyTorch ``Dataset`` without this
module importing torch. Only numpy and the standard library are used (the 8- and 16-bit PNGs
are decoded with :mod:`zlib`).

Conventions (from the folder's ``manifest.json``, ``conventions``):

* arrays are ``(H, W)`` row-major, ``H = image_height_px``, ``W = image_width_px``; pixel
  ``(u, v) = (column, row)``, ``(0, 0)`` the centre of the top-left pixel;
* camera frame: x right, y down, z forward; sensor frame: ``docs/conventions.md``, split plane
  ``x = 0``;
* ``range_mm``: distance along the pixel's ray from the camera centre to the surface, mm;
  ``zdepth_mm``: z of the surface point in the camera frame, mm;
* ``delta_*``: indented minus reference, mm (negative where the skin is pushed towards the
  camera, 0 elsewhere on the surface);
* a pixel whose ray misses the skin is NaN in float arrays and in neither half mask.

Example::

    from fabkit import GroundTruth
    gt = GroundTruth("out/gt")
    for pair in gt:
        depth = pair.zdepth_mm          # (H, W) float32, mm, NaN off the skin
        target = pair.delta_zdepth_mm   # (H, W) float32, mm
"""

from __future__ import annotations

import csv
import json
import os
import struct
import zlib
from collections import OrderedDict
from typing import Dict, List, NamedTuple, Optional, Tuple

import numpy as np

from ._fabkit import GROUNDTRUTH_FILES as _F

__all__ = ["GroundTruth", "PressGroundTruth", "StitchedPair"]

#: Header row of ``pairs.csv``.
PAIRS_HEADER = list(_F["pairs_header"])
#: Keys every ``fabkit groundtruth`` manifest has.
_MANIFEST_KEYS = ("reference", "configurations", "masks_and_pairs", "image", "camera", "extrinsics")
#: Scalar maps of a configuration frame; the reference has only the first two.
_SCALARS = tuple(_F["maps"]) + tuple(_F["delta_maps"])
_MANIFEST = _F["manifest"]
_PAIRS = _F["pairs"]
_LEFT_MASK = _F["left_mask"]
_RIGHT_MASK = _F["right_mask"]
_NORMALS = _F["normals"]
_NPY = _F["npy_suffix"]
_NPZ = _F["arrays_npz"]
_CONTACT = _F["contact_mask"]
#: The fit of a press's ground truth (`fabkit groundtruth --press-image`).
_PRESS_JSON = _F["press_json"]


def _png16(map_name: str) -> str:
    """``range_mm`` -> ``range_um.png``: a map's 16-bit PNG."""
    stem = map_name[: -len("_mm")] if map_name.endswith("_mm") else map_name
    return stem + _F["png16_suffix"]
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


class StitchedPair(NamedTuple):
    """One stitched pair: right (+x) half of ``<right_pattern>_0``, left (-x) half of
    ``<left_pattern>_180``.

    A :class:`~typing.NamedTuple`, so ``torch.utils.data.default_collate`` batches it field by
    field (when ``normals`` is not ``None``). Every array is newly allocated (safe to modify)
    and has shape ``(H, W)`` (``normals``: ``(H, W, 3)``). Pixels on ``right_mask.png`` come
    from the right frame, pixels on ``left_mask.png`` from the left frame, all other pixels
    (rays that miss the skin) are NaN (``contact``: False).

    Attributes:
        index: the pair's row ``pair`` in ``pairs.csv`` (0 .. N*N - 1; right pattern major).
        right_pattern: pattern name on the +x half (frame folder ``right_dir``).
        left_pattern: pattern name on the -x half (frame folder ``left_dir``).
        right_dir: frame folder of the right half, ``<right_pattern>_0``.
        left_dir: frame folder of the left half, ``<left_pattern>_180``.
        range_mm: float32, mm: complete range of the indented skin along each pixel's ray
            from the camera centre.
        zdepth_mm: float32, mm: complete z-depth (camera frame z) of the indented skin.
        delta_range_mm: float32, mm: indented minus reference range (<= 0).
        delta_zdepth_mm: float32, mm: indented minus reference z-depth.
        contact: bool: True where a protrusion pushes the skin in (the surface seen is a
            protrusion), from each frame's ``contact_mask.png``.
        normals: float32 ``(H, W, 3)``, unit normals of the surface pointing out of the
            elastomer, camera frame; NaN off the skin. ``None`` for a ``--format png``
            folder, which holds no normal arrays.
    """

    index: int
    right_pattern: str
    left_pattern: str
    right_dir: str
    left_dir: str
    range_mm: np.ndarray
    zdepth_mm: np.ndarray
    delta_range_mm: np.ndarray
    delta_zdepth_mm: np.ndarray
    contact: np.ndarray
    normals: Optional[np.ndarray]


def _refuse_other_kinds(m: dict, p: str) -> None:
    """Refuses the folders of ``fabkit groundtruth`` that hold no stitched pairs."""
    fixtures = m.get("fixtures")
    if isinstance(fixtures, dict) and "pin_captures" in fixtures:
        raise ValueError(
            f"{p}: the ground truth of a pin dome's captures (`fabkit groundtruth "
            "--pin-captures`) has no stitched pairs; its frames are the folders its "
            "configurations list (numpy.load each <capture>/range_mm.npy), or render them "
            "with fabkit.read_pin_captures and DepthRenderer"
        )
    if "press" in m and fixtures is None:
        raise ValueError(
            f"{p}: the ground truth of a real press (`fabkit groundtruth --press-image`) has "
            "no stitched pairs: open it with fabkit.PressGroundTruth (its reference and "
            "pressed frames, the fit of press.json and the captures)"
        )


class _Folder:
    """What the readers of a ``fabkit groundtruth`` folder share: its manifest's image size,
    camera and pose, its frames' arrays (read when first needed, the last few kept), the
    reference frame and the half masks."""

    def _open(self, folder, cache_frames, missing_what: str, check_kind) -> None:
        """Opens ``folder``: the manifest (``check_kind(manifest, path)`` refuses another kind
        of folder), the image size, camera, pose, frames and format."""
        self.folder = os.fspath(folder)
        if not os.path.isdir(self.folder):
            raise FileNotFoundError(
                f"{self.folder}: no such folder (expected the --out folder of `fabkit groundtruth`)"
            )
        if int(cache_frames) < 0:
            raise ValueError(f"cache_frames = {cache_frames}: must be >= 0")
        self._cache_size = int(cache_frames)
        self._cache: "OrderedDict[str, Dict[str, np.ndarray]]" = OrderedDict()

        self.manifest = self._read_manifest(missing_what, check_kind)
        m = self.manifest
        try:
            h = int(m["image"]["height_px"])
            w = int(m["image"]["width_px"])
        except (KeyError, TypeError, ValueError):
            raise ValueError(
                f"{self._path(_MANIFEST)}: image = {m.get('image')!r}: must hold "
                "width_px and height_px"
            ) from None
        self.shape: Tuple[int, int] = (h, w)
        if not isinstance(m["camera"], dict) or not isinstance(m["extrinsics"], dict):
            raise ValueError(
                f"{self._path(_MANIFEST)}: camera and extrinsics must be JSON objects"
            )
        self.camera: dict = dict(m["camera"])
        try:
            t = np.asarray(m["extrinsics"].get("T_cam_sensor"), dtype=np.float64)
        except (TypeError, ValueError):
            t = np.zeros(0)
        if t.shape != (4, 4):
            raise ValueError(
                f"{self._path(_MANIFEST)}: extrinsics.T_cam_sensor: must be a 4 x 4 matrix"
            )
        self.T_cam_sensor: np.ndarray = t

        self._frames: Dict[str, dict] = {}  # frame dir -> {"files": {rel path: entry}}
        ref_dir = m["reference"].get("dir", _F["reference_dir"])
        self._reference_dir = ref_dir
        self._frames[ref_dir] = self._frame_entry(m["reference"])
        for c in m["configurations"]:
            if not isinstance(c, dict) or "dir" not in c:
                raise ValueError(
                    f"{self._path(_MANIFEST)}: configurations: an entry has no 'dir'"
                )
            self._frames[c["dir"]] = self._frame_entry(c)
        self.format: str = self._detect_format(ref_dir)
        self._reference: Optional[Dict[str, np.ndarray]] = None

    def _check_frame_files(self, dirs: List[str]) -> None:
        """Every file read for the frames ``dirs`` is there (FileNotFoundError naming it)."""
        for d in dirs:
            for rel in self._frame_files(d, reference=(d == self._reference_dir)):
                p = self._path(rel)
                if not os.path.isfile(p):
                    raise FileNotFoundError(
                        f"{p}: missing: manifest.json lists it for frame {d!r} "
                        f"(--format {self.format}); the folder is incomplete"
                    )

    def _open_masks(self) -> None:
        left = self._read_mask(_LEFT_MASK)
        right = self._read_mask(_RIGHT_MASK)
        if (left & right).any():
            raise ValueError(
                f"{self._path(_LEFT_MASK)}: overlaps {_RIGHT_MASK}: the half masks must be disjoint"
            )
        left.flags.writeable = False
        right.flags.writeable = False
        self.masks: Tuple[np.ndarray, np.ndarray] = (left, right)

    @property
    def reference(self) -> Dict[str, np.ndarray]:
        """The reference (undeformed skin) frame: ``range_mm``, ``zdepth_mm`` ((H, W) float32,
        mm, NaN off the skin) and ``normals`` ((H, W, 3) float32, camera frame; not in a
        ``--format png`` folder). Read-only arrays, loaded on first access.

        Raises:
            FileNotFoundError, ValueError: as :class:`GroundTruth`.
        """
        if self._reference is None:
            arrays = dict(self._load_frame(self._reference_dir, reference=True))
            for a in arrays.values():
                a.flags.writeable = False
            self._reference = arrays
        return self._reference

    def _path(self, rel: str) -> str:
        return os.path.join(self.folder, *rel.split("/"))

    def _read_manifest(self, missing_what: str, check_kind) -> dict:
        p = self._path(_MANIFEST)
        if not os.path.isfile(p):
            raise FileNotFoundError(f"{p}: missing: {missing_what}")
        try:
            with open(p, "rb") as f:
                m = json.loads(f.read().decode("utf-8"))
        except json.JSONDecodeError as e:
            raise ValueError(f"{p}:{e.lineno}:{e.colno}: not JSON: {e.msg}") from None
        except UnicodeDecodeError as e:
            raise ValueError(f"{p}: not UTF-8 text: {e}") from None
        if not isinstance(m, dict):
            raise ValueError(f"{p}: must be a JSON object (the manifest of `fabkit groundtruth`)")
        missing = [k for k in _MANIFEST_KEYS if k not in m]
        if missing:
            raise ValueError(
                f"{p}: no {', '.join(repr(k) for k in missing)}: not the manifest of "
                "`fabkit groundtruth` (a manifest of another fabkit command?); "
                f"a ground-truth manifest has {', '.join(_MANIFEST_KEYS)}"
            )
        if not isinstance(m["configurations"], list) or not isinstance(m["reference"], dict):
            raise ValueError(
                f"{p}: configurations must be a list and reference an object "
                "(the manifest of `fabkit groundtruth`)"
            )
        check_kind(m, p)
        return m

    def _frame_entry(self, entry: dict) -> dict:
        files = {}
        for f in entry.get("files") or []:
            if isinstance(f, dict) and isinstance(f.get("file"), str):
                files[f["file"]] = f
        return {"files": files}

    def _detect_format(self, ref_dir: str) -> str:
        files = self._frames[ref_dir]["files"]
        candidates = (
            ("npz", f"{ref_dir}/{_NPZ}"),
            ("npy", f"{ref_dir}/{_SCALARS[0]}{_NPY}"),
            ("png", f"{ref_dir}/{_png16(_SCALARS[0])}"),
        )
        for fmt, rel in candidates:
            if rel in files:
                return fmt
        raise ValueError(
            f"{self._path(_MANIFEST)}: reference.files lists none of "
            f"{', '.join(rel for _, rel in candidates)}: cannot tell the --format"
        )

    def _frame_files(self, d: str, reference: bool) -> List[str]:
        """Relative paths of the files read for frame ``d``."""
        names = _SCALARS[:2] if reference else _SCALARS
        if self.format == "npy":
            files = [f"{d}/{n}{_NPY}" for n in names + (_NORMALS,)]
        elif self.format == "npz":
            files = [f"{d}/{_NPZ}"]
        else:
            files = [f"{d}/{_png16(n)}" for n in names]
        if not reference:
            files.append(f"{d}/{_CONTACT}")
        return files

    def _read_mask(self, rel: str) -> np.ndarray:
        a = _read_png(self._path(rel))
        if a.shape != self.shape or a.dtype != np.uint8:
            raise ValueError(
                f"{self._path(rel)}: {a.dtype} {a.shape}: must be 8-bit greyscale of shape {self.shape}"
            )
        return a != 0

    def _check(self, path: str, a: np.ndarray, shape: tuple) -> np.ndarray:
        if a.dtype != np.float32 or a.shape != shape:
            raise ValueError(f"{path}: {a.dtype} {a.shape}: must be float32 of shape {shape}")
        return a

    def _load_frame(self, d: str, reference: bool) -> Dict[str, np.ndarray]:
        if d in self._cache:
            self._cache.move_to_end(d)
            return self._cache[d]
        h, w = self.shape
        names = _SCALARS[:2] if reference else _SCALARS
        out: Dict[str, np.ndarray] = {}
        if self.format == "npy":
            for n in names + (_NORMALS,):
                p = self._path(f"{d}/{n}{_NPY}")
                shape = (h, w, 3) if n == _NORMALS else (h, w)
                out[n] = self._check(p, _np_load(p), shape)
        elif self.format == "npz":
            p = self._path(f"{d}/{_NPZ}")
            try:
                with np.load(p, allow_pickle=False) as z:
                    for n in names + (_NORMALS,):
                        if n not in z.files:
                            raise ValueError(f"{p}: no array {n!r} (holds {sorted(z.files)})")
                        shape = (h, w, 3) if n == _NORMALS else (h, w)
                        out[n] = self._check(f"{p}[{n}]", z[n], shape)
            except FileNotFoundError:
                raise FileNotFoundError(f"{p}: missing (frame {d!r})") from None
            except (OSError, zlib.error) as e:
                raise ValueError(f"{p}: cannot read as .npz: {e}") from None
        else:
            entries = self._frames[d]["files"]
            for n in names:
                rel = f"{d}/{_png16(n)}"
                p = self._path(rel)
                e = entries.get(rel, {})
                enc = _F["png16_delta"] if n in _F["delta_maps"] else _F["png16_depth"]
                scale = float(e.get("scale_mm_per_count", enc["scale_mm_per_count"]))
                offset = int(e.get("offset_counts", enc["offset_counts"]))
                counts = _read_png(p)
                if counts.dtype != np.uint16 or counts.shape != (h, w):
                    raise ValueError(
                        f"{p}: {counts.dtype} {counts.shape}: must be 16-bit greyscale of shape {(h, w)}"
                    )
                v = ((counts.astype(np.float64) - offset) * scale).astype(np.float32)
                v[counts == 0] = np.nan
                out[n] = v
        if not reference:
            p = self._path(f"{d}/{_CONTACT}")
            c = _read_png(p)
            if c.dtype != np.uint8 or c.shape != (h, w):
                raise ValueError(f"{p}: {c.dtype} {c.shape}: must be 8-bit greyscale of shape {(h, w)}")
            out["contact"] = c != 0
        if self._cache_size:
            self._cache[d] = out
            while len(self._cache) > self._cache_size:
                self._cache.popitem(last=False)
        return out


class GroundTruth(_Folder):
    """The stitched pairs of a ``fabkit groundtruth`` output folder, as a read-only sequence.

    ``len(gt)`` is N*N (N patterns); ``gt[i]`` (negative ``i`` counts from the end; a slice
    gives a list) loads and stitches pair ``i`` (:class:`StitchedPair`); ``for pair in gt``
    iterates them in ``pairs.csv`` order. Frames are read from disk when first needed and the
    last ``cache_frames`` frames are kept.

    Supported ``--format``:

    * ``npy``: ``<frame>/<name>.npy`` float32 maps (exact values);
    * ``npz``: ``<frame>/arrays.npz`` holding the same float32 maps (exact values);
    * ``png``: the 16-bit PNGs ``<frame>/<stem>_um.png`` decoded as
      ``value_mm = (count - offset_counts) * scale_mm_per_count`` (count 0 -> NaN), i.e.
      quantised to 1 micrometre, and without normals (``normals`` is ``None``).

    Args:
        folder: the ``--out`` folder of ``fabkit groundtruth``.
        cache_frames: how many decoded frames to keep in memory (>= 0); 4 by default. Pairs
            are in right-pattern-major order, so the right frame is reused N times in a row.

    Attributes:
        folder: the folder (``str``).
        manifest: ``manifest.json`` as a dict.
        format: ``"npy"``, ``"npz"`` or ``"png"`` (found from the reference frame's files).
        shape: ``(H, W)`` of every map.
        patterns: the pattern names, in ``manifest.json`` order (N of them).
        pairs: the rows of ``pairs.csv``: ``(index, right_pattern, right_dir, left_pattern,
            left_dir)``.
        camera: the manifest's ``camera`` dict (intrinsics: ``fx_px``, ``fy_px``, ``cx_px``,
            ``cy_px``, ``distortion_model``, ``distortion_coefficients``,
            ``image_width_px``, ``image_height_px``, the camera file and its sha256).
        T_cam_sensor: ``(4, 4)`` float64, homogeneous transform mapping sensor-frame points
            (mm) to camera-frame points (mm).
        masks: ``(left, right)``, ``(H, W)`` bool arrays (read-only): pixels whose ray meets
            the reference surface at sensor-frame x < 0, resp. x >= 0. Disjoint; their union
            is the pixels that see the skin.
        reference: dict of the reference (undeformed) frame's arrays (read-only):
            ``range_mm``, ``zdepth_mm`` (``(H, W)`` float32, mm, NaN off the skin) and, for
            ``npy``/``npz`` folders, ``normals`` (``(H, W, 3)`` float32, camera frame).

    Raises:
        FileNotFoundError: ``folder``, ``manifest.json``, ``pairs.csv``, a mask or a frame
            file is missing (the message names the path). Frame files are checked when the
            folder is opened and again when read.
        ValueError: the folder is not a ``fabkit groundtruth`` folder or is inconsistent: the
            manifest is not JSON or is of another kind (no ``configurations``,
            ``reference``, ...), ``pairs.csv`` has another header, rows out of order, unknown
            frame folders or not N*N rows, an array or PNG has the wrong shape or dtype or
            cannot be decoded. The message names the file and the rule.
    """

    def __init__(self, folder, cache_frames: int = 4):
        self._open(
            folder,
            cache_frames,
            "not a `fabkit groundtruth` output folder (it writes manifest.json, pairs.csv, "
            "left_mask.png, right_mask.png and a folder per frame)",
            _refuse_other_kinds,
        )
        m = self.manifest
        self.patterns: List[str] = list((m.get("fixtures") or {}).get("patterns") or [])
        self.pairs: List[Tuple[int, str, str, str, str]] = self._read_pairs()
        ref_dir = self._reference_dir
        self._check_frame_files(
            [ref_dir] + sorted({p[2] for p in self.pairs} | {p[4] for p in self.pairs})
        )
        self._open_masks()

    # ----------------------------------------------------------------- sequence protocol

    def __len__(self) -> int:
        return len(self.pairs)

    def __getitem__(self, i):
        """Pair ``i`` (:class:`StitchedPair`), or a list of pairs for a slice.

        Raises:
            IndexError: ``i`` outside ``-len(self) .. len(self) - 1``.
            TypeError: ``i`` is neither an integer nor a slice.
            FileNotFoundError, ValueError: a frame file is missing or malformed (named).
        """
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        try:
            k = int(i.__index__())
        except AttributeError:
            raise TypeError(
                f"GroundTruth indices must be integers or slices, not {type(i).__name__}"
            ) from None
        n = len(self)
        if k < 0:
            k += n
        if not 0 <= k < n:
            raise IndexError(f"pair index {i} out of range for {n} stitched pairs")
        return self._stitch(k)

    def __iter__(self):
        for k in range(len(self)):
            yield self._stitch(k)

    def __repr__(self) -> str:
        h, w = self.shape
        return (
            f"GroundTruth({self.folder!r}: {len(self)} stitched pairs of {len(self.patterns)} "
            f"patterns, {w} x {h} px, --format {self.format})"
        )

    # ----------------------------------------------------------------- internals

    def _read_pairs(self) -> List[Tuple[int, str, str, str, str]]:
        p = self._path(_PAIRS)
        if not os.path.isfile(p):
            raise FileNotFoundError(f"{p}: missing: a `fabkit groundtruth` folder lists its stitched pairs there")
        with open(p, newline="", encoding="utf-8") as f:
            rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
        if not rows or rows[0] != PAIRS_HEADER:
            got = ",".join(rows[0]) if rows else "(empty)"
            raise ValueError(f"{p}:1: header = {got}: must be {','.join(PAIRS_HEADER)}")
        cfg_dirs = set(self._frames) - {self._reference_dir}
        pairs = []
        for k, r in enumerate(rows[1:]):
            line = k + 2
            if len(r) != 5:
                raise ValueError(f"{p}:{line}: {len(r)} columns: must be 5 ({','.join(PAIRS_HEADER)})")
            if r[0] != str(k):
                raise ValueError(f"{p}:{line}: pair = {r[0]}: must be {k} (rows numbered from 0 in order)")
            for col, side in ((2, "right_dir"), (4, "left_dir")):
                if r[col] not in cfg_dirs:
                    raise ValueError(
                        f"{p}:{line}: {side} = {r[col]}: not a configuration of manifest.json"
                    )
            pairs.append((k, r[1], r[2], r[3], r[4]))
        n = len(self.patterns)
        if n and len(pairs) != n * n:
            raise ValueError(
                f"{p}: {len(pairs)} pairs: must be N x N = {n * n} for the manifest's {n} patterns"
            )
        return pairs

    def _stitch(self, k: int) -> StitchedPair:
        index, rp, rdir, lp, ldir = self.pairs[k]
        right = self._load_frame(rdir, reference=False)
        left = self._load_frame(ldir, reference=False)
        lm, rm = self.masks
        h, w = self.shape

        def stitch(name, fill, dtype, extra=()):
            a = np.full((h, w) + extra, fill, dtype=dtype)
            a[rm] = right[name][rm]
            a[lm] = left[name][lm]
            return a

        maps = {n: stitch(n, np.nan, np.float32) for n in _SCALARS}
        normals = stitch("normals", np.nan, np.float32, (3,)) if "normals" in right else None
        return StitchedPair(
            index=index,
            right_pattern=rp,
            left_pattern=lp,
            right_dir=rdir,
            left_dir=ldir,
            range_mm=maps["range_mm"],
            zdepth_mm=maps["zdepth_mm"],
            delta_range_mm=maps["delta_range_mm"],
            delta_zdepth_mm=maps["delta_zdepth_mm"],
            contact=stitch("contact", False, bool),
            normals=normals,
        )


class PressGroundTruth(_Folder):
    """The ground truth of a real press of a sphere (``fabkit groundtruth DESIGN --press-image
    CAPTURE --press-reference REF --sphere-radius-mm R --out DIR``): the sphere found in the
    capture against its reference through the calibrated camera (``press.json``), and the
    reference and pressed frames rendered with the sphere placed where the fit puts it, beside
    byte-for-byte copies of the two captures (calibration/src/groundtruth/press.rs).

    The folder holds no stitched pairs (no ``pairs.csv``): one pressed frame, ``press/`` (the
    indenter's surface; its ``skin/``, the skin as the sphere deforms it: :attr:`skin`), and the
    reference, ``reference/``, each with its maps as :class:`GroundTruth`'s frames (``--format``
    ``npy``, ``npz`` or ``png``) and ``capture.png`` (or ``.jpg``), the half masks,
    ``press.json`` and ``manifest.json``.

    Args:
        folder: the ``--out`` folder of ``fabkit groundtruth --press-image``.

    Attributes:
        folder, manifest, format, shape, camera, T_cam_sensor, masks, reference: as
            :class:`GroundTruth` (``reference``: the unpressed skin's ``range_mm``,
            ``zdepth_mm`` and, but for ``png``, ``normals``).
        fit: ``press.json`` as a dict (the fit, its uncertainty, the sphere placed, the files
            it came from).
        radius_mm: the sphere's radius, mm (``--sphere-radius-mm``).
        centre_mm: ``(2,)`` float64, the sphere's centre over the skin's contact face (sensor
            frame x, y), mm; ``centre_std_mm`` its standard deviations.
        depth_mm: how far the sphere's lowest point lies below the contact face, mm;
            ``depth_std_mm`` its standard deviation; ``depth_spread_mm`` how far it moves with
            the fitted core (a response not linear in depth).
        sphere_centre_mm: ``(3,)`` float64, the sphere's centre, sensor frame, mm.
        lowest_point_px: ``(2,)`` float64, the pixel the sphere's lowest point projects to
            (``None`` if it does not project).
        capture_file, reference_capture_file: paths of the copies of the press's capture and
            of its reference (:meth:`capture`, :meth:`reference_capture` decode them).
        elastic: ``press.json``'s ``elastic`` (the deformed skin's model, its contact radius,
            its sink round the contact, its assumptions), or ``None``.

    Raises:
        FileNotFoundError: ``folder``, ``manifest.json``, ``press.json``, a mask, a frame file
            or a capture's copy is missing (named).
        ValueError: not the folder of a press (another ``fabkit groundtruth`` folder: open it
            with :class:`GroundTruth`), or an inconsistent one (named, with the rule).
    """

    def __init__(self, folder, cache_frames: int = 2):
        self._open(
            folder,
            cache_frames,
            "not a `fabkit groundtruth --press-image` output folder (it writes manifest.json, "
            "press.json, left_mask.png, right_mask.png, reference/ and press/)",
            _require_press,
        )
        m = self.manifest
        p = self._path(_MANIFEST)
        if len(m["configurations"]) != 1:
            raise ValueError(
                f"{p}: configurations: {len(m['configurations'])} entries: a press's ground "
                "truth has one, the pressed frame"
            )
        self._press_dir: str = m["configurations"][0]["dir"]
        self._check_frame_files([self._reference_dir, self._press_dir])
        self._open_masks()
        fit_rel = m["press"].get("file", _PRESS_JSON) if isinstance(m["press"], dict) else None
        if not isinstance(fit_rel, str):
            raise ValueError(f"{p}: press must be an object naming its file ({_PRESS_JSON})")
        fp = self._path(fit_rel)
        if not os.path.isfile(fp):
            raise FileNotFoundError(f"{fp}: missing: the press's fit (manifest.json names it)")
        try:
            with open(fp, "rb") as f:
                fit = json.loads(f.read().decode("utf-8"))
        except json.JSONDecodeError as e:
            raise ValueError(f"{fp}:{e.lineno}:{e.colno}: not JSON: {e.msg}") from None
        except UnicodeDecodeError as e:
            raise ValueError(f"{fp}: not UTF-8 text: {e}") from None
        if not isinstance(fit, dict):
            raise ValueError(f"{fp}: must be a JSON object (the press's fit)")
        self.fit: dict = fit

        def number(*keys, shape=()):
            v = fit
            try:
                for k in keys:
                    v = v[k]
                a = np.asarray(v, dtype=np.float64)
            except (KeyError, TypeError, ValueError, IndexError):
                a = None
            if a is None or a.shape != shape:
                want = "a number" if shape == () else f"{shape[0]} numbers"
                raise ValueError(f"{fp}: {'.'.join(keys)} = {v!r}: must be {want}") from None
            return float(a) if shape == () else a

        self.radius_mm: float = number("indenter", "radius_mm")
        self.centre_mm: np.ndarray = number("centre_mm", shape=(2,))
        self.centre_std_mm: np.ndarray = number("centre_std_mm", shape=(2,))
        self.depth_mm: float = number("depth_mm")
        self.depth_std_mm: float = number("depth_std_mm")
        self.depth_spread_mm: float = number("depth_spread_mm")
        self.sphere_centre_mm: np.ndarray = number("sphere", "centre_mm", shape=(3,))
        lowest = (fit.get("sphere") or {}).get("lowest_point_px")
        self.lowest_point_px: Optional[np.ndarray] = (
            None if lowest is None else number("sphere", "lowest_point_px", shape=(2,))
        )

        def copy(which: str) -> str:
            rel = (fit.get(which) or {}).get("copy")
            if not isinstance(rel, str):
                raise ValueError(f"{fp}: {which}.copy = {rel!r}: must name the capture's copy")
            path = self._path(rel)
            if not os.path.isfile(path):
                raise FileNotFoundError(f"{path}: missing: press.json's {which}.copy")
            return path

        self.capture_file: str = copy("capture")
        self.reference_capture_file: str = copy("reference")
        self._press: Optional[Dict[str, np.ndarray]] = None
        skin = m["configurations"][0].get("skin")
        self._skin_dir: Optional[str] = skin.get("dir") if isinstance(skin, dict) else None
        if self._skin_dir is not None:
            self._check_frame_files([self._skin_dir])
        self._skin: Optional[Dict[str, np.ndarray]] = None
        elastic = fit.get("elastic")
        self.elastic: Optional[dict] = elastic if isinstance(elastic, dict) else None

    @property
    def press(self) -> Dict[str, np.ndarray]:
        """The pressed frame: ``range_mm``, ``zdepth_mm`` (complete, (H, W) float32, mm, NaN
        off the skin), ``delta_range_mm``, ``delta_zdepth_mm`` (pressed minus reference, mm,
        <= 0 in the contact), ``normals`` ((H, W, 3) float32, camera frame; not in a
        ``--format png`` folder) and ``contact`` ((H, W) bool: the sphere's intersection with
        the contact face). Read-only arrays, loaded on first access.

        Raises:
            FileNotFoundError, ValueError: as :class:`PressGroundTruth`.
        """
        if self._press is None:
            arrays = dict(self._load_frame(self._press_dir, reference=False))
            for a in arrays.values():
                a.flags.writeable = False
            self._press = arrays
        return self._press

    @property
    def skin(self) -> Dict[str, np.ndarray]:
        """The skin as the sphere deforms it (``press/skin/``: an elastic layer bonded to its
        base, pressed to the fitted depth; ``elastic`` holds the model and its assumptions):
        the arrays of :attr:`press`, its ``contact`` where the sphere touches the deformed
        skin. Read-only arrays, loaded on first access.

        Raises:
            ValueError: a folder written before the skin was modelled (no ``press/skin/``).
            FileNotFoundError: as :class:`PressGroundTruth`.
        """
        if self._skin_dir is None:
            raise ValueError(
                f"{self._path(_MANIFEST)}: configurations[0] has no 'skin': written by a "
                "fabkit without the elastic skin; render the press again"
            )
        if self._skin is None:
            arrays = dict(self._load_frame(self._skin_dir, reference=False))
            for a in arrays.values():
                a.flags.writeable = False
            self._skin = arrays
        return self._skin

    def capture(self) -> np.ndarray:
        """The press's real capture (its copy in the folder), decoded: ``(H, W)`` or ``(H, W,
        C)`` uint8 (uint16 for a 16-bit PNG). A JPEG capture needs Pillow.

        Raises:
            ValueError: the copy cannot be decoded (named).
        """
        return _read_capture(self.capture_file)

    def reference_capture(self) -> np.ndarray:
        """The reference capture (the unpressed skin, its copy in the folder), decoded as
        :meth:`capture`."""
        return _read_capture(self.reference_capture_file)

    def __repr__(self) -> str:
        h, w = self.shape
        return (
            f"PressGroundTruth({self.folder!r}: a {self.radius_mm:g} mm sphere "
            f"{self.depth_mm:.3f} mm deep at ({self.centre_mm[0]:.3f}, {self.centre_mm[1]:.3f}) "
            f"mm, {w} x {h} px, --format {self.format})"
        )


def _require_press(m: dict, p: str) -> None:
    """Refuses a ``fabkit groundtruth`` folder that is not a press's."""
    if "press" not in m:
        raise ValueError(
            f"{p}: no 'press': not the ground truth of a real press (`fabkit groundtruth "
            "--press-image`); open a folder of protrusion patterns with fabkit.GroundTruth"
        )


def _read_capture(path: str) -> np.ndarray:
    """A capture's copy: a PNG by this module's decoder, anything else by Pillow."""
    with open(path, "rb") as f:
        is_png = f.read(8) == _PNG_SIGNATURE
    if is_png:
        return _read_png(path)
    try:
        from PIL import Image
    except ImportError:
        raise ValueError(
            f"{path}: not a PNG: decoding a JPEG capture needs Pillow (pip install pillow)"
        ) from None
    with Image.open(path) as im:
        return np.asarray(im)


def _np_load(path: str) -> np.ndarray:
    try:
        a = np.load(path, allow_pickle=False)
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: missing") from None
    except (OSError, ValueError) as e:
        raise ValueError(f"{path}: cannot read as .npy: {e}") from None
    if not isinstance(a, np.ndarray):
        raise ValueError(f"{path}: not a single .npy array")
    return a


def _read_png(path: str) -> np.ndarray:
    """Decodes a non-interlaced 8- or 16-bit greyscale / RGB / grey+alpha / RGBA PNG.

    Returns ``(H, W)`` (one channel) or ``(H, W, C)`` uint8 / uint16 (native byte order).

    Raises:
        FileNotFoundError: ``path`` is missing.
        ValueError: not a PNG, a bad CRC, or a form this decoder does not read (palette, bit
            depth below 8, interlaced); the message names the file.
    """
    try:
        with open(path, "rb") as f:
            data = f.read()
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: missing") from None
    if not data.startswith(_PNG_SIGNATURE):
        raise ValueError(f"{path}: not a PNG file (bad signature)")
    pos, ihdr, idat = 8, None, []
    while pos + 12 <= len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + n]
        if len(body) != n or pos + 12 + n > len(data):
            raise ValueError(f"{path}: truncated PNG chunk {kind!r}")
        (crc,) = struct.unpack(">I", data[pos + 8 + n : pos + 12 + n])
        if zlib.crc32(kind + body) & 0xFFFFFFFF != crc:
            raise ValueError(f"{path}: PNG chunk {kind!r}: bad CRC")
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + n
    if ihdr is None or not idat:
        raise ValueError(f"{path}: PNG without IHDR or IDAT")
    w, h, depth, colour, _, _, interlace = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if channels is None or depth not in (8, 16) or interlace != 0:
        raise ValueError(
            f"{path}: PNG colour type {colour}, bit depth {depth}, interlace {interlace}: "
            "only non-interlaced 8/16-bit grey, grey+alpha, RGB or RGBA PNGs are read"
        )
    try:
        raw = zlib.decompress(b"".join(idat))
    except zlib.error as e:
        raise ValueError(f"{path}: PNG image data does not inflate: {e}") from None
    bpp = channels * depth // 8
    stride = w * bpp
    if len(raw) < h * (stride + 1):
        raise ValueError(f"{path}: PNG image data holds {len(raw)} bytes, {h * (stride + 1)} expected")
    pixels = _unfilter(raw, h, stride, bpp, path)
    a = np.frombuffer(pixels, dtype=np.uint8 if depth == 8 else ">u2")
    a = a.astype(np.uint8 if depth == 8 else np.uint16)
    return a.reshape((h, w) if channels == 1 else (h, w, channels))


def _unfilter(raw: bytes, h: int, stride: int, bpp: int, path: str) -> bytes:
    """Undoes the PNG row filters (None, Sub, Up, Average, Paeth)."""
    out = bytearray(h * stride)
    prior = np.zeros(stride, dtype=np.uint8)
    for y in range(h):
        start = y * (stride + 1)
        ftype = raw[start]
        row = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=start + 1)
        if ftype == 0:
            cur = row.copy()
        elif ftype == 1:  # Sub: running sum with stride bpp, modulo 256
            cur = np.cumsum(row.reshape(-1, bpp), axis=0, dtype=np.uint8).reshape(-1)
        elif ftype == 2:  # Up
            cur = row + prior
        elif ftype in (3, 4):  # Average, Paeth: sequential along the row
            r = row.tolist()
            b = prior.tolist()
            c = r  # reconstructed in place
            if ftype == 3:
                for i in range(stride):
                    a_ = c[i - bpp] if i >= bpp else 0
                    c[i] = (r[i] + ((a_ + b[i]) >> 1)) & 0xFF
            else:
                for i in range(stride):
                    if i >= bpp:
                        a_, c_ = c[i - bpp], b[i - bpp]
                    else:
                        a_ = c_ = 0
                    b_ = b[i]
                    p = a_ + b_ - c_
                    pa, pb, pc = abs(p - a_), abs(p - b_), abs(p - c_)
                    if pa <= pb and pa <= pc:
                        pr = a_
                    elif pb <= pc:
                        pr = b_
                    else:
                        pr = c_
                    c[i] = (r[i] + pr) & 0xFF
            cur = np.array(c, dtype=np.uint8)
        else:
            raise ValueError(f"{path}: PNG row {y}: unknown filter type {ftype}")
        out[y * stride : (y + 1) * stride] = cur.tobytes()
        prior = cur
    return bytes(out)
