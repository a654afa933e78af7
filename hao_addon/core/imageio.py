# SPDX-License-Identifier: GPL-3.0-or-later
"""Exact, atomic AO map files: 16-bit grayscale PNG and 32-bit float EXR (pure numpy + zlib).

Blender's own savers apply view transforms and choose bit depths from scene settings; AO is
data, so these writers store the numbers as they are. Files are written to a temporary name
beside the target and renamed into place, so a failed or cancelled write never leaves a
half-written image. Arrays are (H, W) with row 0 at the *bottom* (Blender's pixel order);
files get the standard top-row-first orientation.
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import struct
import tempfile
import zlib
from pathlib import Path

import numpy as np

from .errors import BakeInputError
from .folders import make_folders, nearest_existing, remove_made, unmakeable_reason

FORMATS = {".png": "PNG", ".exr": "OPEN_EXR"}
TEMP_PREFIX = ".hao-"


def format_for_path(path: str | Path) -> str:
    ext = Path(path).suffix.lower()
    if ext not in FORMATS:
        raise BakeInputError(f"unsupported output extension '{ext}': use .png (16-bit) or .exr (32-bit float)")
    return FORMATS[ext]


def file_bytes_estimate(path: str | Path, width: int, height: int, channels: int) -> int:
    """Upper bound of the file's size: EXR is uncompressed float32, PNG is 16-bit whose deflate
    stream is at most slightly larger than the raw rows."""
    per_sample = 4 if format_for_path(path) == "OPEN_EXR" else 2
    raw = width * height * channels * per_sample + height * (8 + 1)
    return raw + raw // 1000 + 4096


def check_writable(path: str | Path, width: int, height: int, channels: int, source: str | Path | None = None) -> Path:
    """Refuse, before any work, an output that could not be written: unsupported extension, the
    input file itself, a folder that cannot be made (a missing one is made when the file is
    written), a read-only folder, a name too long for the file system, an existing folder or
    read-only file of that name, or too little free space. Returns the absolute path. (The
    write itself is atomic: a temporary file renamed into place.)"""
    path = Path(os.path.abspath(path))
    format_for_path(path)
    if source is not None and path == Path(os.path.abspath(source)):
        raise BakeInputError(f"the output '{path}' is the input file: choose another name")
    reason = unmakeable_reason(path.parent)
    if reason:
        raise BakeInputError(f"cannot write '{path}': cannot make its folder, {reason}")
    folder = nearest_existing(path.parent)  # where the file, or its first missing folder, goes
    try:
        name_max = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):  # no pathconf (Windows): NTFS allows 255
        name_max = 255
    if len(os.fsencode(path.name)) > name_max:
        raise BakeInputError(f"cannot write '{path.name}': the name is longer than the file system's "
                             f"{name_max}-byte limit")
    if path.is_dir():
        raise BakeInputError(f"cannot write '{path}': it is a folder")
    if not _can_create_in(folder) or (path.exists() and not os.access(path, os.W_OK)):
        raise BakeInputError(f"cannot write '{path}': permission denied")
    needed = file_bytes_estimate(path, width, height, channels)
    free = shutil.disk_usage(folder).free
    if needed > free:
        raise BakeInputError(f"cannot write '{path}': it needs up to {byte_size(needed)}, "
                             f"the disk has {byte_size(free)} free")
    return path


def byte_size(count: int) -> str:
    """A byte count in the largest binary unit that keeps it at 1 or more ('12 bytes',
    '3.5 KiB', '1.2 GiB'): a free space of 40 KiB is not '0.0 MiB'."""
    if count < 1024:
        return f"{count} bytes"
    value = float(count)
    for unit in ("KiB", "MiB", "GiB", "TiB"):
        value /= 1024.0
        if value < 1024.0 or unit == "TiB":
            return f"{value:.1f} {unit}"
    raise AssertionError("unreachable")


def _can_create_in(folder: Path) -> bool:
    """Whether a file can be created there: tried, since os.access answers yes for root even
    where the file system refuses (sysfs, read-only mounts, some network shares)."""
    try:
        fd, probe = tempfile.mkstemp(prefix=TEMP_PREFIX, suffix=".probe", dir=folder)
    except OSError:
        return False
    os.close(fd)
    os.unlink(probe)
    return True


def temporary_prefix(path: Path) -> str:
    """The prefix of a target's temporary files: short (the target's own name can already be
    at the length limit) and the target's own, so a later write of it finds what a killed
    run left."""
    return f"{TEMP_PREFIX}{hashlib.blake2b(Path(path).name.encode(), digest_size=4).hexdigest()}-"


def remove_stale_temporaries(path: Path) -> int:
    """Remove the temporary files a killed earlier write of this target left beside it
    (.part, and .bak backups of a commit that never finished); returns how many. Only one
    run writes a given file (every run's outputs are checked for collisions first)."""
    removed = 0
    prefix = temporary_prefix(path)
    try:
        names = os.listdir(path.parent)
    except OSError:
        return 0
    for name in names:
        if name.startswith(prefix) and name.endswith((".part", ".bak")):
            try:
                os.unlink(path.parent / name)
                removed += 1
            except OSError:
                pass
    return removed


@contextlib.contextmanager
def named_write_errors(path: Path):
    """An OSError while writing path's bytes (a full disk, a quota) names the file: the
    system's own message names none ('[Errno 28] No space left on device')."""
    try:
        yield
    except OSError as exc:
        if exc.filename is None:
            raise OSError(exc.errno, f"cannot write '{path}': {exc.strerror or exc}") from None
        raise


def _temporary_for(path: Path) -> tuple[int, str]:
    remove_stale_temporaries(path)
    return tempfile.mkstemp(prefix=temporary_prefix(path), suffix=".part", dir=path.parent)


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write data to path through a temporary file in the same folder, renamed into place."""
    path = Path(path)
    made = make_folders(path.parent)
    fd, tmp = _temporary_for(path)
    try:
        with os.fdopen(fd, "wb") as fh, named_write_errors(path):
            fh.write(data)
        # mkstemp creates 0600; give the file the permissions a plain open() would.
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        remove_made(made)
        raise


class StagedFiles:
    """Several files written all or none. ``write`` puts each file's bytes under a temporary
    name beside its target; ``commit`` renames them all into place, keeping any file it
    replaces under a hidden backup name until ``release`` (drop the backups) or ``rollback``
    (put the earlier files back, remove the new ones). ``discard`` removes what was staged.
    A bake that fails after its maps are in place (an image that cannot be stored, a glTF
    export) thus leaves the folder as it found it."""

    def __init__(self) -> None:
        self._staged: list[tuple[Path, str]] = []  # (target, temporary file)
        self._placed: list[tuple[Path, str | None]] = []  # (target, backup of the file it replaced)
        self._made: list[Path] = []  # folders made for the files, removed again by discard()

    @property
    def paths(self) -> list[str]:
        """The targets staged or placed, in the order written."""
        return [str(target) for target, _tmp in self._staged] + [str(target) for target, _b in self._placed]

    def write_bytes(self, path: str | Path, data: bytes) -> None:
        path = Path(path)
        self._made += make_folders(path.parent)
        fd, tmp = _temporary_for(path)
        self._staged.append((path, tmp))  # first: removed by discard() even if the write fails
        with os.fdopen(fd, "wb") as fh, named_write_errors(path):
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())

    def write_image(self, path: str | Path, image: np.ndarray, text: dict[str, str] | None = None,
                    png_bits: int = 16, dither: bool = False) -> None:
        """(H, W) or (H, W, 4) to .png (16-bit, or png_bits) or .exr (32-bit float), as
        encode_image."""
        self.write_bytes(path, encode_image(path, image, text, png_bits, dither))

    def commit(self) -> list[str]:
        """Rename every staged file into place; returns their paths. On failure, rolls back."""
        try:
            while self._staged:
                target, tmp = self._staged[0]
                backup = None
                if target.exists():
                    backup = tempfile.mktemp(prefix=temporary_prefix(target), suffix=".bak", dir=target.parent)
                    os.link(target, backup)  # the earlier file stays reachable until release()
                self._placed.append((target, backup))
                self._staged.pop(0)
                os.replace(tmp, target)
        except BaseException:
            self.rollback()
            raise
        return [str(target) for target, _b in self._placed]

    def release(self) -> None:
        """Keep the new files: drop the backups of the ones they replaced."""
        for _target, backup in self._placed:
            if backup is not None and os.path.lexists(backup):
                os.unlink(backup)
        self._placed.clear()
        self._made.clear()  # they hold the new files now

    def rollback(self) -> None:
        """Put back what commit replaced, remove what it added, and discard what is staged."""
        for target, backup in reversed(self._placed):
            if backup is not None and os.path.lexists(backup):
                os.replace(backup, target)
            elif backup is None and os.path.lexists(target):
                os.unlink(target)
        self._placed.clear()
        self.discard()

    def discard(self) -> None:
        for _target, tmp in self._staged:
            if os.path.lexists(tmp):
                os.unlink(tmp)
        self._staged.clear()
        if not self._placed:  # nothing of ours is left in them
            remove_made(self._made)
            self._made.clear()


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


# The text entry a bake's files carry: a digest of what made them (the input files, the
# settings, the version; cli/farm.py), so that --skip-existing can tell a finished output
# from one of other settings. PNG: a tEXt chunk; EXR: a string attribute.
BAKE_KEY = "hao_bake_key"
# An EXR's digest of its scanline blocks (blake2b, hex), a string attribute.
EXR_PIXELS_KEY = "hao_pixels"


def pixels_digest(data: bytes) -> str:
    """The digest an EXR carries of its scanline blocks (EXR_PIXELS_KEY; core/file_checks.py)."""
    return hashlib.blake2b(data, digest_size=16).hexdigest()


# The dither's noise is drawn from this seed for each image shape: a re-run writes the same
# bytes (a farm task re-run after a kill included).
DITHER_SEED = 0x4A0D17


def quantized(image: np.ndarray, bits: int, dither: bool = False) -> np.ndarray:
    """image (H, W[, C]) in [0, 1] as unsigned integers of `bits` bits (uint16 or uint8):
    rounded; or, with dither, floor(v L + u) with u uniform in [0, 1) per sample (L the top
    level): its mean over many samples is exactly v L, so a smooth gradient shows no bands,
    and a value on a level (0, 1, any k / L) stays on it, noise-free."""
    top = (1 << bits) - 1
    scaled = np.clip(np.nan_to_num(np.asarray(image, np.float64)), 0.0, 1.0) * top
    if dither:
        noise = np.random.Generator(np.random.PCG64(DITHER_SEED)).random(scaled.shape)
        levels = np.floor(scaled + noise)
        on_level = np.abs(scaled - np.round(scaled)) < 1e-9  # float error must not push a level off
        levels = np.where(on_level, np.round(scaled), levels)
    else:
        levels = np.round(scaled)
    return np.clip(levels, 0, top).astype(np.uint16 if bits == 16 else np.uint8)


def png16_bytes(image: np.ndarray, text: dict[str, str] | None = None, bits: int = 16,
                dither: bool = False) -> bytes:
    """16-bit (or 8-bit: bits) PNG of image (H, W) gray or (H, W, 4) RGBA in [0, 1], row 0 =
    bottom, quantized (dither: see quantized); text: Latin-1 tEXt entries (keyword -> value),
    before the image data."""
    img = np.asarray(image)
    h, w = img.shape[:2]
    channels = 1 if img.ndim == 2 else img.shape[2]
    if channels not in (1, 4):
        raise ValueError(f"PNG writer takes gray or RGBA images, got {channels} channels")
    if bits not in (8, 16):
        raise ValueError(f"PNG writer takes 8 or 16 bits, got {bits}")
    q = quantized(img[::-1], bits, dither).astype(">u2" if bits == 16 else np.uint8)  # top-first, big-endian
    row_bytes = (bits // 8) * w * channels
    raw = np.concatenate([np.zeros((h, 1), np.uint8), q.view(np.uint8).reshape(h, row_bytes)], axis=1)

    def chunk(tag: bytes, payload: bytes) -> bytes:
        return struct.pack(">I", len(payload)) + tag + payload + struct.pack(">I", zlib.crc32(tag + payload))

    colour_type = 0 if channels == 1 else 6  # gray or RGBA
    ihdr = struct.pack(">IIBBBBB", w, h, bits, colour_type, 0, 0, 0)
    texts = b"".join(chunk(b"tEXt", key.encode("latin-1") + b"\0" + value.encode("latin-1"))
                     for key, value in sorted((text or {}).items()))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + texts + chunk(b"IDAT", zlib.compress(raw.tobytes(), 6))
            + chunk(b"IEND", b""))


def exr32_bytes(image: np.ndarray, text: dict[str, str] | None = None) -> bytes:
    """32-bit float scanline OpenEXR, uncompressed, row 0 = bottom: channel 'Y' for (H, W),
    channels A, B, G, R (EXR stores them sorted by name) for (H, W, 4) RGBA."""
    img = np.asarray(image, np.float32)[::-1]
    h, w = img.shape[:2]
    if img.ndim == 2:
        names, planes = ["Y"], [img]
    elif img.shape[2] == 4:
        names, planes = ["A", "B", "G", "R"], [img[..., 3], img[..., 2], img[..., 1], img[..., 0]]
    else:
        raise ValueError(f"EXR writer takes gray or RGBA images, got {img.shape[2]} channels")

    def attr(name: str, kind: str, payload: bytes) -> bytes:
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(payload)) + payload

    # FLOAT (2), linear 0, sampling 1 1 per channel
    channels = b"".join(n.encode() + b"\0" + struct.pack("<iBxxxii", 2, 0, 1, 1) for n in names) + b"\0"
    line_bytes = 4 * w * len(names)
    block = 8 + line_bytes
    rows = np.empty((h, block), np.uint8)
    rows[:, 0:4] = np.arange(h, dtype="<i4").view(np.uint8).reshape(h, 4)
    rows[:, 4:8] = np.frombuffer(struct.pack("<i", line_bytes), np.uint8)
    # Within a scanline, each channel's samples follow one another, in channel-name order.
    data = np.stack([np.ascontiguousarray(p, dtype="<f4") for p in planes], axis=1)  # (h, c, w)
    rows[:, 8:] = data.view(np.uint8).reshape(h, line_bytes)
    # Uncompressed EXR has no checksum of its own: the pixels' digest in the header lets
    # exr_is_whole tell a damaged file from a finished one.
    text = {**(text or {}), EXR_PIXELS_KEY: pixels_digest(rows.tobytes())}
    header = (struct.pack("<ii", 20000630, 2)
              + attr("channels", "chlist", channels)
              + attr("compression", "compression", b"\0")
              + attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
              + attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
              + attr("lineOrder", "lineOrder", b"\0")
              + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + b"".join(attr(key, "string", value.encode()) for key, value in sorted((text or {}).items()))
              + b"\0")
    start = len(header) + 8 * h
    offsets = struct.pack(f"<{h}Q", *(start + i * block for i in range(h)))
    return header + offsets + rows.tobytes()


def encode_image(path: str | Path, image: np.ndarray, text: dict[str, str] | None = None, png_bits: int = 16,
                 dither: bool = False) -> bytes:
    """The file bytes of (H, W) accessibility, or (H, W, 4) RGBA, for path's format, with
    text entries (keyword -> value) in its metadata; a PNG of png_bits bits, dithered where
    asked (an EXR is 32-bit float either way)."""
    fmt = format_for_path(path)
    if not np.isfinite(image).all():
        raise ValueError("refusing to write an AO map containing NaN or Inf")
    return png16_bytes(image, text, png_bits, dither) if fmt == "PNG" else exr32_bytes(image, text)


def read_text(path: str | Path, keyword: str) -> str | None:
    """A text entry of a PNG (tEXt) or EXR (string attribute) file this module wrote, or None
    (no such entry, another format, a truncated or unreadable file). Reads the header only."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(1 << 16)
    except OSError:
        return None
    if head.startswith(b"\x89PNG\r\n\x1a\n"):
        at = 8
        while at + 8 <= len(head):
            length, tag = struct.unpack(">I4s", head[at:at + 8])
            if tag in (b"IDAT", b"IEND"):
                return None
            payload = head[at + 8:at + 8 + length]
            if tag == b"tEXt" and payload.split(b"\0", 1)[0] == keyword.encode("latin-1"):
                return payload.split(b"\0", 1)[1].decode("latin-1")
            at += 12 + length
        return None
    if head.startswith(struct.pack("<i", 20000630)):
        return exr_text(head, keyword)
    return None


def exr_attribute(data: bytes, marker: bytes) -> bytes | None:
    """The value of an EXR header attribute (marker: name NUL type NUL), or None."""
    at = data.find(marker)
    if at < 0:
        return None
    (size,) = struct.unpack("<i", data[at + len(marker):at + len(marker) + 4])
    return data[at + len(marker) + 4:at + len(marker) + 4 + size]


def exr_text(data: bytes, keyword: str) -> str | None:
    """An EXR string attribute from the start of a file's bytes (imageio.read_text)."""
    value = exr_attribute(data, keyword.encode() + b"\0string\0")
    return None if value is None else value.decode(errors="replace")


def write_ao_file(path: str | Path, image: np.ndarray) -> None:
    """Write (H, W) accessibility, or (H, W, 4) RGBA, to .png (16-bit) or .exr (32-bit
    float), atomically."""
    atomic_write_bytes(Path(path), encode_image(path, image))
