# SPDX-License-Identifier: GPL-3.0-or-later
"""The one shader loader: GLSL bodies live in ``gpu_shaders/*.glsl``, interfaces in Python.

Blender's ``GPUShaderCreateInfo`` declares images, samplers, push constants and vertex
inputs; the files hold only function bodies (no ``#version``/``#extension``: Blender's
prelude comes first). Several files can be concatenated in an explicit order, which stands
in for ``#include``. Compile errors carry the driver's message: Blender prints it on the
process's stdout/stderr, not in the exception, so the descriptors are captured.
"""
from __future__ import annotations

import functools
import os
import sys
import tempfile
from pathlib import Path
from typing import Callable

import gpu
import numpy as np

SHADER_DIR = Path(__file__).resolve().parent.parent.parent / "gpu_shaders"


class ShaderCompileError(RuntimeError):
    """A shader failed to compile; the message holds the driver's log."""


@functools.lru_cache(maxsize=None)
def load_glsl(name: str) -> str:
    """Text of ``gpu_shaders/<name>``."""
    path = SHADER_DIR / name
    if not path.is_file():
        raise FileNotFoundError(f"shader source missing: {path}")
    return path.read_text(encoding="utf-8")


def glsl_source(*names: str) -> str:
    """Concatenate shader files in the given order (shared snippets first)."""
    return "\n".join(f"/* --- {n} --- */\n{load_glsl(n)}" for n in names)


# std140 members a numpy dtype field can stand for: (kind, trailing shape) -> GLSL type.
# Arrays of these need no padding under std140 (a stride of 16 or 64 bytes).
_STD140_TYPES = {("f", (4, 4)): "mat4", ("f", (4,)): "vec4", ("i", (4,)): "ivec4"}


def glsl_struct(name: str, dtype: np.dtype) -> str:
    """The GLSL struct of a uniform block whose bytes are `dtype` (one definition: the block's
    layout is the dtype, its GLSL is generated). Fields: float32 or int32 arrays of shape
    (4,), (4, 4), (N, 4) or (N, 4, 4), at std140 offsets (checked)."""
    lines, offset = [], 0
    for field in dtype.names:
        base, at = dtype.fields[field][:2]
        kind, shape = base.base.kind, base.shape
        glsl = _STD140_TYPES.get((kind, shape[-2:] if len(shape) >= 2 and shape[-2:] == (4, 4) else shape[-1:]))
        if glsl is None or base.base.itemsize != 4 or at != offset:
            raise TypeError(f"{name}.{field}: {base} at byte {at} has no std140 GLSL member")
        count = shape[:-2] if glsl == "mat4" else shape[:-1]
        lines.append(f"  {glsl} {field}{''.join(f'[{n}]' for n in count)};")
        offset += base.itemsize
    if offset != dtype.itemsize:
        raise TypeError(f"{name}: {dtype.itemsize - offset} bytes of padding at the end")
    return f"struct {name} {{\n" + "\n".join(lines) + "\n};\n"


def add_defines(info: "gpu.types.GPUShaderCreateInfo", defines: dict[str, float | int]) -> None:
    """Python constants into GLSL (``repr`` keeps every digit of a float)."""
    for name, value in defines.items():
        info.define(name, repr(float(value)) if isinstance(value, float) else str(int(value)))


def compile_with_log(info: "gpu.types.GPUShaderCreateInfo", label: str) -> "gpu.types.GPUShader":
    """``gpu.shader.create_from_info`` that raises ShaderCompileError with the driver log."""
    sys.stdout.flush()
    sys.stderr.flush()
    with tempfile.TemporaryFile(mode="w+b") as log_file:
        saved = os.dup(1), os.dup(2)
        os.dup2(log_file.fileno(), 1)
        os.dup2(log_file.fileno(), 2)
        try:
            try:
                return gpu.shader.create_from_info(info)
            finally:
                sys.stdout.flush()
                sys.stderr.flush()
                os.dup2(saved[0], 1)
                os.dup2(saved[1], 2)
                os.close(saved[0])
                os.close(saved[1])
        except Exception as exc:  # Blender raises a bare Exception on compile errors
            log_file.seek(0)
            log = "\n".join(line for line in log_file.read().decode(errors="replace").splitlines()
                            if "EGL" not in line)
            raise ShaderCompileError(f"shader '{label}' failed to compile: {exc}\n{log}") from None


# Every shader factory, with the values each of its parameters takes (shader_variants):
# the tests compile every variant from this list, not from a list of their own.
# (factory, the values of each parameter, which combinations exist)
SHADER_FACTORIES: list[tuple[Callable, dict[str, tuple], Callable[[dict], bool]]] = []
# Up to this many variants a factory's parameters are combined in full; beyond it, each value
# of each parameter once (beside the defaults) and all of them at their last value together.
FULL_PRODUCT_LIMIT = 16


def shader_variants(valid: Callable[[dict], bool] | None = None, **domains: tuple) -> Callable:
    """Declare a shader factory and the values each parameter takes (its variants); valid:
    which combinations exist (the terminator lift needs shading normals, say)."""
    def register(factory: Callable) -> Callable:
        SHADER_FACTORIES.append((factory, domains, valid or (lambda _arguments: True)))
        return factory
    return register


def variant_arguments(domains: dict[str, tuple], valid: Callable[[dict], bool]) -> list[dict]:
    """The argument sets of a factory's variants to compile: all combinations up to
    FULL_PRODUCT_LIMIT, else every value of every parameter once (on the defaults where that
    combination exists, else on the first that does) and all parameters at their last value.
    Combinations the factory's `valid` rules out are left out."""
    import itertools
    names = list(domains)
    product = [dict(zip(names, values)) for values in itertools.product(*(domains[n] for n in names))]
    if len(product) <= FULL_PRODUCT_LIMIT:
        return [arguments for arguments in product if valid(arguments)]
    base, last = ({n: domains[n][0] for n in names}, {n: domains[n][-1] for n in names})
    kept = [last] if valid(last) else []
    for name in names:
        for value in domains[name]:
            chosen = next((a for a in [{**base, name: value}, {**last, name: value}] + product
                           if a[name] == value and valid(a)), None)
            if chosen is not None and chosen not in kept:
                kept.append(chosen)
    return kept


_SHADER_CACHE: dict[tuple, "gpu.types.GPUShader"] = {}


def cached_shader(key: tuple, build: Callable[[], "gpu.types.GPUShaderCreateInfo"]) -> "gpu.types.GPUShader":
    """Compile a shader once per process (LLVM JIT costs 15-80 ms per variant)."""
    shader = _SHADER_CACHE.get(key)
    if shader is None:
        shader = compile_with_log(build(), label=str(key))
        _SHADER_CACHE[key] = shader
    return shader


def free_shaders() -> None:
    """Drop every cached shader (called from unregister)."""
    _SHADER_CACHE.clear()


def cached_shader_count() -> int:
    return len(_SHADER_CACHE)


@shader_variants()
def barrier_shader() -> "gpu.types.GPUShader":
    """An empty compute dispatch (util.memory_barrier's fence)."""
    def build():
        info = gpu.types.GPUShaderCreateInfo()
        info.local_group_size(1, 1, 1)
        info.compute_source("void main() {}")
        return info
    return cached_shader(("barrier",), build)
