# SPDX-License-Identifier: GPL-3.0-or-later
"""Lists: arrays a compute pass reads (or writes) by index, in the form this Blender offers.

- 'textures' (every release): a list is a 2D texture LIST_WIDTH wide (util.list_texture),
  entry i at texel (i % LIST_WIDTH, i / LIST_WIDTH); integers travel as float bits (only
  FLOAT buffers upload); a list holds at most LIST_WIDTH x the texture size limit entries.
- 'storage' (Blender 5.3 and newer: compat.storage_buffers): a list is a storage buffer,
  read as an array, integers as integers, bounded by the buffer size the driver allows.

A shader declares its lists through the form (declare), and reads them with the GLSL macros
of prelude(): LIST_VEC4(list, i), LIST_UINT(list, i), LIST_STORE(list, i, vec4). Its source
is the same for both forms. tests/test_ray_cast.py runs the ray cast in every form this
Blender has, against the CPU's.
"""
from __future__ import annotations

import contextlib
from typing import Iterator

import gpu
import numpy as np

from .. import compat
from . import util

LIST_WIDTH = util.LIST_WIDTH
# GLSL types of a list's entries, by kind.
KINDS = {"VEC4": "vec4", "UINT": "uint"}
FORM_NAMES = ("textures", "storage")


class TextureLists:
    """Lists as list textures (every release)."""

    name = "textures"

    def declare(self, info, slot: int, name: str, kind: str, write: bool = False) -> None:
        if write:
            info.image(slot, 'RGBA32F', 'FLOAT_2D', name, qualifiers={'WRITE'})
        else:
            info.sampler(slot, 'FLOAT_2D', name)

    def output_slot(self, inputs: int) -> int:
        """The slot of the first written list after `inputs` read ones: images number apart."""
        return 0

    def prelude(self) -> str:
        return ("#define LIST_AT(i) ivec2((i) % LIST_WIDTH, (i) / LIST_WIDTH)\n"
                "#define LIST_VEC4(list, i) texelFetch(list, LIST_AT(i), 0)\n"
                "#define LIST_UINT(list, i) floatBitsToUint(texelFetch(list, LIST_AT(i), 0).r)\n"
                "#define LIST_STORE(list, i, value) imageStore(list, LIST_AT(i), value)\n")

    def capacity(self) -> int:
        return LIST_WIDTH * gpu.capabilities.max_texture_size_get()

    def upload(self, values: np.ndarray, kind: str):
        """values: (n, 4) float for VEC4, (n,) integers for UINT."""
        return util.list_texture(values, 'RGBA32F' if kind == "VEC4" else 'R32F')

    def output(self, count: int):
        return gpu.types.GPUTexture((LIST_WIDTH, util.list_rows(count)), format='RGBA32F')

    def bind(self, shader, inputs: dict, outputs: dict, ints: dict, floats: dict) -> None:
        compat.set_shader_inputs(shader, samplers=inputs, ints=ints, floats=floats)
        for name, texture in outputs.items():
            shader.image(name, texture)

    def read(self, output, count: int) -> np.ndarray:
        """(count, 4) float32 of an output list."""
        return util.texture_to_numpy(output).reshape(-1, 4)[:count]


class StorageLists:
    """Lists as storage buffers (Blender 5.3 and newer)."""

    name = "storage"
    # Entries a list may hold: the 128 MiB every OpenGL 4.3 driver allows a storage block
    # (GL_MAX_SHADER_STORAGE_BLOCK_SIZE's minimum; Blender does not report the driver's own).
    MAX_BYTES = 1 << 27

    def declare(self, info, slot: int, name: str, kind: str, write: bool = False) -> None:
        compat.declare_storage_list(info, slot, KINDS[kind], name, write)

    def output_slot(self, inputs: int) -> int:
        """The slot of the first written list after `inputs` read ones: one numbering for all."""
        return inputs

    def prelude(self) -> str:
        return ("#define LIST_VEC4(list, i) list[i]\n"
                "#define LIST_UINT(list, i) list[i]\n"
                "#define LIST_STORE(list, i, value) list[i] = value\n")

    def capacity(self) -> int:
        return self.MAX_BYTES // 16

    def upload(self, values: np.ndarray, kind: str):
        if kind == "UINT":
            flat = np.ascontiguousarray(values, dtype=np.uint32).ravel()
            return compat.storage_buffer(gpu.types.Buffer('UINT', max(flat.size, 1), flat if flat.size else [0]))
        flat = np.ascontiguousarray(values, dtype=np.float32).ravel()
        return compat.storage_buffer(gpu.types.Buffer('FLOAT', max(flat.size, 4), flat if flat.size else [0.0] * 4))

    def output(self, count: int):
        return compat.storage_buffer(gpu.types.Buffer('FLOAT', 4 * max(count, 1)))

    def bind(self, shader, inputs: dict, outputs: dict, ints: dict, floats: dict) -> None:
        compat.set_shader_inputs(shader, samplers={}, ints=ints, floats=floats)
        for name, buffer in {**inputs, **outputs}.items():
            shader.storage_block(name, buffer)

    def read(self, output, count: int) -> np.ndarray:
        buf = output.read()
        buf.dimensions = len(buf)  # one flat run of floats; their bits kept (a face travels as int bits)
        return np.frombuffer(buf, dtype=np.float32).reshape(-1, 4)[:count].copy()


FORMS = {"textures": TextureLists(), "storage": StorageLists()}
# The form the passes use where several exist. Textures: on Mesa's llvmpipe the ray cast's
# dispatch takes 3x as long reading storage buffers (bench/list_forms_bench.py: 600k rays on the
# bunny, 0.51 s against 1.10 s in all, identical hits), and a list texture holds more entries
# (LIST_WIDTH x 16384 against 128 MiB). Storage buffers stay built and tested for the GPUs where a
# measurement (tools/gpu_bench.sh runs that benchmark) shows them faster.
PREFERRED = "textures"
_FORCED: list[str] = []


def available_forms() -> tuple[str, ...]:
    """The forms this Blender has: storage buffers from 5.3 on, textures on every release."""
    return FORM_NAMES if compat.storage_buffers() else ("textures",)


def chosen_form():
    """The form the passes use: PREFERRED where this Blender has it, else textures;
    using_form() overrides it."""
    name = _FORCED[-1] if _FORCED else PREFERRED
    return FORMS[name if name in available_forms() else "textures"]


@contextlib.contextmanager
def using_form(name: str) -> Iterator[None]:
    """Run the passes inside with lists in this form (tests and benchmarks compare them)."""
    if name not in available_forms():
        raise ValueError(f"lists as {name} need Blender 5.3 or newer")
    _FORCED.append(name)
    try:
        yield
    finally:
        _FORCED.pop()
