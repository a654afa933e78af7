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
