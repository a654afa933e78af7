# SPDX-License-Identifier: GPL-3.0-or-later
"""Whether an output file is whole: finished and readable in full, not just present.

--skip-existing keeps only whole files and `farm verify` passes only whole files: a PNG cut
short keeps its header (and the bake key in it), so the key alone cannot tell. The formats
are the ones core/imageio.py writes (16/8-bit PNG, uncompressed 32-bit EXR with its pixels'
digest), the .glb exports, and mesh files (whole when not empty).
"""
from __future__ import annotations

import json
import struct
import zlib
from pathlib import Path

from .imageio import EXR_PIXELS_KEY, FORMATS, exr_attribute, exr_text, pixels_digest


def image_is_whole(path: str | Path) -> bool:
    """Whether a PNG or EXR file this module wrote decodes in full: a PNG's chunks all
    present with their CRCs, IEND last, its image data inflating to every row; an EXR's
    size as its header says and its pixels' digest equal to the one it carries. A file cut
    short (a killed copy) or damaged is not whole, whatever its header holds."""
    try:
        data = Path(path).read_bytes()
    except OSError:
        return False
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return _png_is_whole(data)
    if data.startswith(struct.pack("<i", 20000630)):
        return _exr_is_whole(data)
    return False


def _png_is_whole(data: bytes) -> bool:
    at, idat, header = 8, [], None
    while at + 12 <= len(data):
        length, tag = struct.unpack(">I4s", data[at:at + 8])
        payload = data[at + 8:at + 8 + length]
        if len(payload) != length or data[at + 8 + length:at + 12 + length] != struct.pack(
                ">I", zlib.crc32(tag + payload)):
            return False
        if tag == b"IHDR":
            header = struct.unpack(">IIBB", payload[:10])
        elif tag == b"IDAT":
            idat.append(payload)
        elif tag == b"IEND":
            if at + 12 != len(data) or header is None:
                return False
            w, h, bits, colour = header
            channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour, 1)
            try:
                raw = zlib.decompress(b"".join(idat))
            except zlib.error:
                return False
            return len(raw) == h * (1 + w * channels * bits // 8)
        at += 12 + length
    return False


def _exr_is_whole(data: bytes) -> bool:
    digest = exr_text(data, EXR_PIXELS_KEY)
    if digest is None:
        return False
    header_end = _exr_header_end(data)
    if header_end is None:
        return False
    (x0, y0, x1, y1) = struct.unpack("<iiii", exr_attribute(data, b"dataWindow\0box2i\0") or b"\0" * 16)
    h = y1 - y0 + 1
    offsets_end = header_end + 8 * h
    if h <= 0 or offsets_end > len(data):
        return False
    (first,) = struct.unpack("<Q", data[header_end:header_end + 8])
    if first != offsets_end:
        return False
    rows = data[offsets_end:]
    block = len(rows) // h if h else 0
    return block > 8 and block * h == len(rows) and pixels_digest(rows) == digest


def _exr_header_end(data: bytes) -> int | None:
    """The offset just past an EXR header's attributes (name, type, size, value ... then a
    zero byte), or None where the header runs past the data."""
    at = 8
    while at < len(data):
        if data[at] == 0:
            return at + 1
        name_end = data.find(b"\0", at)
        type_end = data.find(b"\0", name_end + 1)
        if name_end < 0 or type_end < 0 or type_end + 5 > len(data):
            return None
        (size,) = struct.unpack("<i", data[type_end + 1:type_end + 5])
        at = type_end + 5 + size
    return None


def output_is_whole(path: str | Path) -> bool:
    """Whether an output file is finished and readable: a PNG or EXR decodes in full
    (image_is_whole); a .glb's header, length and JSON chunk are intact; any other file (a
    mesh) exists and is not empty. A folder in its place is not an output."""
    path = Path(path)
    if not path.is_file():
        return False
    if path.suffix.lower() in FORMATS:
        return image_is_whole(path)
    if path.suffix.lower() == ".glb":
        return _glb_is_whole(path)
    return path.stat().st_size > 0


def _glb_is_whole(path: Path) -> bool:
    try:
        data = path.read_bytes()
        magic, version, length = struct.unpack("<4sII", data[:12])
        chunk_length, chunk_type = struct.unpack("<I4s", data[12:20])
        if magic != b"glTF" or version != 2 or length != len(data) or chunk_type != b"JSON":
            return False
        json.loads(data[20:20 + chunk_length])
        return 20 + chunk_length <= len(data)
    except (OSError, struct.error, ValueError):
        return False
