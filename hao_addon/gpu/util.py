# SPDX-License-Identifier: GPL-3.0-or-later
"""Small helpers around Blender's ``gpu`` module: uploads, readback, state scoping, counting.

Traps handled here (see the probe report): ``attr_fill`` and ``Buffer`` reinterpret any dtype
silently, so everything is made contiguous float32/int32 first; ``np.asarray(Buffer)`` is a
transposed view, so readback flattens the Buffer and uses ``np.frombuffer``.
"""
from __future__ import annotations

import contextlib
import os
from typing import Iterator

import gpu
import numpy as np

# Live GPU-owning pass objects, so tests can check that every bake freed what it made.
_LIVE_PASSES: set[int] = set()


def live_pass_count() -> int:
    return len(_LIVE_PASSES)


class GPUPass:
    """Base of the passes: registers itself while it holds GPU resources."""

    def __init__(self) -> None:
        _LIVE_PASSES.add(id(self))
        self._freed = False

    def free(self) -> None:
        """Drop every GPU object this pass owns (textures and batches die with their last
        Python reference: the 4.2-5.0 API has no explicit free for them)."""
        if not self._freed:
            self._release()
            self._freed = True
            _LIVE_PASSES.discard(id(self))

    def _release(self) -> None:  # overridden
        pass



# Refuse bakes whose textures would exceed this (bytes); the gpu module cannot query free
# video memory, so the budget is a setting (environment HAO_GPU_MEMORY_BUDGET, in MiB).
def gpu_memory_budget() -> int:
    return int(float(os.environ.get("HAO_GPU_MEMORY_BUDGET", "4096")) * 2**20)


def check_texture_limits(map_size: int, view_side: int, bytes_needed: int) -> None:
    """Raise BakeInputError when a bake exceeds the GPU's texture size or the memory budget."""
    from ..core.errors import BakeInputError
    limit = gpu.capabilities.max_texture_size_get()
    if map_size > limit:
        raise BakeInputError(f"map size {map_size} exceeds this GPU's texture limit of {limit}")
    if view_side > limit:
        raise BakeInputError(f"the light views need {view_side} pixels per side, above this GPU's "
                             f"limit of {limit}: lower the view samples per texel or the map size")
    _check_budget(bytes_needed, "the bake")


def check_render_limits(width: int, height: int, bytes_needed: int) -> None:
    """Raise ViewInputError when a width x height render exceeds the GPU's texture size or the
    memory budget (checked before any texture is made)."""
    from ..core.errors import ViewInputError
    limit = gpu.capabilities.max_texture_size_get()
    if max(width, height) > limit:
        raise ViewInputError(f"a {width}x{height} image exceeds this GPU's texture limit of {limit} pixels per side")
    _check_budget(bytes_needed, f"a {width}x{height} render", ViewInputError)


def _check_budget(bytes_needed: int, what: str, error: type | None = None) -> None:
    """Raise `error` (default BakeInputError) when bytes_needed is above the GPU memory budget."""
    from ..core.errors import BakeInputError
    budget = gpu_memory_budget()
    if bytes_needed > budget:
        raise (error or BakeInputError)(f"{what} needs about {bytes_needed / 2**20:.0f} MiB of GPU memory, above the "
                             f"budget of {budget / 2**20:.0f} MiB (set HAO_GPU_MEMORY_BUDGET to raise it)")


def float_attr(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float32)


def make_batch(prim: str, attrs: dict[str, tuple[str, np.ndarray]]) -> "gpu.types.GPUBatch":
    """Batch from numpy arrays. attrs: name -> ('F32', (n, k) array); converted to float32."""
    fmt = gpu.types.GPUVertFormat()
    arrays = {}
    count = None
    for name, (comp, arr) in attrs.items():
        arr = float_attr(arr)
        arrays[name] = arr
        fmt.attr_add(id=name, comp_type=comp, len=1 if arr.ndim == 1 else arr.shape[1], fetch_mode='FLOAT')
        count = arr.shape[0]
    vbo = gpu.types.GPUVertBuf(fmt, count)
    for name, arr in arrays.items():
        vbo.attr_fill(id=name, data=arr)
    return gpu.types.GPUBatch(type=prim, buf=vbo)


# Entries per row of the passes' list textures (texel lists, rays, triangles): 4096 rows of
# 4096 hold a fully covered 4096^2 map within the 16384-texel texture limit; entry i sits at
# texel (i % LIST_WIDTH, i // LIST_WIDTH), a define of the same name in the shaders.
LIST_WIDTH = 4096


def list_rows(count: int) -> int:
    """Rows of a list texture of `count` entries (at least one)."""
    return max(1, -(-count // LIST_WIDTH))


def list_texture(values: np.ndarray, fmt: str) -> "gpu.types.GPUTexture":
    """A (LIST_WIDTH, rows) texture of `values`, zero-padded to whole rows: (n, 4) for
    RGBA32F, (n,) for R32F, float32, or integers < 2^32 sent as their bits (only FLOAT buffers
    upload; shaders read them with floatBitsToUint)."""
    channels = 4 if fmt == 'RGBA32F' else 1
    flat = values.astype(np.uint32).view(np.float32) if values.dtype.kind in "iu" else values.astype(np.float32)
    rows = list_rows(len(flat))
    full = np.zeros((rows * LIST_WIDTH, channels), np.float32)
    full[:len(flat)] = flat.reshape(len(flat), channels)
    return gpu.types.GPUTexture((LIST_WIDTH, rows), format=fmt, data=gpu.types.Buffer('FLOAT', full.size, full.ravel()))


def texture_to_numpy(tex: "gpu.types.GPUTexture", dtype=np.float32) -> np.ndarray:
    """Read a 2D texture into a (height, width[, channels]) numpy array (a copy)."""
    buf = tex.read()
    shape = tuple(buf.dimensions)
    n = 1
    for d in shape:
        n *= d
    buf.dimensions = n
    arr = np.frombuffer(buf, dtype=dtype).reshape(shape)
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[:, :, 0]
    return arr.copy()




def image_barrier() -> None:
    """Make image writes of earlier draws visible to later reads. gpu.compute.dispatch()
    issues GPU_memory_barrier(TEXTURE_FETCH | SHADER_IMAGE_ACCESS) after it runs; draws issue
    none, so a 1x1x1 dispatch of an empty kernel supplies the missing glMemoryBarrier."""
    from .shaders import barrier_shader
    shader = barrier_shader()
    gpu.compute.dispatch(shader, 1, 1, 1)
    gpu.shader.unbind()


@contextlib.contextmanager
def scoped_state() -> Iterator[None]:
    """Restore the drawing state a pass may change: blend, depth test, depth write,
    viewport; face culling and the scissor test have no getters and return to Blender's
    defaults (off; colour writes on), which Blender's own draw code expects between passes."""
    blend = gpu.state.blend_get()
    depth_test = gpu.state.depth_test_get()
    depth_mask = gpu.state.depth_mask_get()
    viewport = gpu.state.viewport_get()
    try:
        yield
    finally:
        gpu.state.blend_set(blend)
        gpu.state.depth_test_set(depth_test)
        gpu.state.depth_mask_set(depth_mask)
        gpu.state.face_culling_set('NONE')
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.scissor_test_set(False)
        gpu.state.viewport_set(*viewport)
        gpu.shader.unbind()


def set_overlay_pass_state(width: int, height: int, culling: str = 'NONE', blend: str = 'NONE') -> None:
    """State of a pass without depth buffer: viewport, no depth test or writes, culling and
    blend as given. Call inside scoped_state()."""
    gpu.state.viewport_set(0, 0, width, height)
    gpu.state.depth_test_set('NONE')
    gpu.state.depth_mask_set(False)
    gpu.state.face_culling_set(culling)
    gpu.state.blend_set(blend)


def snapshot_state() -> tuple:
    """What scoped_state restores, for tests that check a pass left no state behind."""
    return (gpu.state.blend_get(), gpu.state.depth_test_get(), gpu.state.depth_mask_get(),
            tuple(gpu.state.viewport_get()))
