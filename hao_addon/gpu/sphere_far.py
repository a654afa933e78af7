# SPDX-License-Identifier: GPL-3.0-or-later
"""Distant-occluder pass (Shanmugam & Arikan, section 5): sphere proxies splatted as
billboards that multiply their occlusion into the AO map (fragment pass).

Why multiplicative: adding the occlusion of overlapping spheres counts the directions they
share twice (the paper's over-occlusion, clamped at 1); treating them as independent
occluders, A = prod (1 - o_i), stays within [0, 1] and is closer to the ray-traced answer
(tests/test_spheres_gpu.py measures both on a cluster of spheres over a floor)."""
from __future__ import annotations

import gpu
import numpy as np

from ..core.proxies.sphere_ao import far_distance
from . import util
from .shaders import cached_shader, glsl_source, shader_variants


def _far_info(falloff: str) -> "gpu.types.GPUShaderCreateInfo":
    iface = gpu.types.GPUStageInterfaceInfo("hao_sphere_far_iface")
    iface.flat('VEC4', "sphere_data")
    iface.flat('FLOAT', "sphere_reach")
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, 'VEC2', "corner")
    info.vertex_in(1, 'VEC4', "sphere")
    info.vertex_in(2, 'FLOAT', "reach")
    info.vertex_out(iface)
    info.image(0, 'RGBA32F', 'FLOAT_2D', "low_position", qualifiers={'READ'})
    info.image(1, 'RGBA32F', 'FLOAT_2D', "low_normal", qualifiers={'READ'})
    info.fragment_out(0, 'VEC4', "far_out")
    info.push_constant('FLOAT', "max_distance")
    info.push_constant('FLOAT', "near_radius")
    if falloff == "wendland":
        info.define("WENDLAND_FALLOFF", "1")
    info.vertex_source(glsl_source("sphere_far.vert"))
    info.fragment_source(glsl_source("pcg3d.glsl", "hao_common.glsl", "sphere_far.frag"))
    return info


@shader_variants(falloff=("none", "wendland"))
def far_shader(falloff: str = "wendland") -> "gpu.types.GPUShader":
    return cached_shader(("hao_sphere_far", falloff), lambda: _far_info(falloff))


def billboard_rectangles(centres: np.ndarray, reach: np.ndarray, view_proj: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """NDC rectangles (K, 4) = (x0, y0, x1, y1), the exact bounds of the projection of each
    ball (centre, reach), and a (K,) mask of those that touch the screen.

    A screen line x_ndc = s is the plane (row0 - s row3) . X = 0; it touches the ball when its
    distance from the centre equals the radius, a quadratic in s whose roots bound the ball
    (perspective or orthographic alike). A ball reaching behind the camera plane (leading
    coefficient <= 0) covers the whole screen."""
    m = np.asarray(view_proj, np.float64)
    c = np.concatenate([np.asarray(centres, np.float64), np.ones((len(centres), 1))], axis=1)
    r2 = np.asarray(reach, np.float64) ** 2
    b = c @ m[3]
    v = m[3, :3]
    rect = np.empty((len(c), 4))
    whole = np.zeros(len(c), bool)
    for axis in (0, 1):
        a = c @ m[axis]
        u = m[axis, :3]
        qa = b * b - r2 * (v @ v)
        qb = -2.0 * (a * b - r2 * (u @ v))
        qc = a * a - r2 * (u @ u)
        disc = np.maximum(qb * qb - 4.0 * qa * qc, 0.0)
        ok = qa > 1e-12
        root = np.sqrt(disc)
        safe = np.where(ok, qa, 1.0)
        lo, hi = (-qb - root) / (2.0 * safe), (-qb + root) / (2.0 * safe)
        rect[:, axis], rect[:, axis + 2] = np.minimum(lo, hi), np.maximum(lo, hi)
        whole |= ~ok
    rect[whole] = (-1.0, -1.0, 1.0, 1.0)
    rect = np.clip(rect, -1.0, 1.0)
    visible = (rect[:, 2] > rect[:, 0]) & (rect[:, 3] > rect[:, 1])
    return rect, visible


class FarSpheresPass(util.GPUPass):
    """Multiplies sphere occlusion into an AO map texture (R32F at the AO-map resolution)."""

    def __init__(self) -> None:
        super().__init__()
        self.stats = dict(spheres_drawn=0, spheres_culled=0)
        self._fb = self._fb_target = None

    def run(self, low_gbuffer, ao_map, centres: np.ndarray, radii: np.ndarray, epsilon: float,
            view_proj: np.ndarray, max_distance: float = 0.0, falloff: str = "wendland",
            near_radius: float = 0.0) -> None:
        """low_gbuffer: the G-buffer at the AO-map resolution (LowGBufferPass); ao_map: R32F
        texture of that size, already holding an accessibility (1s for spheres alone, or the
        result to combine with); max_distance, falloff, near_radius: see
        core/proxies/sphere_ao.sphere_weight."""
        centres = np.asarray(centres, np.float64).reshape(-1, 3)
        radii = np.asarray(radii, np.float64).reshape(-1)
        reach = far_distance(radii, epsilon)
        rect, visible = billboard_rectangles(centres, reach, view_proj)
        keep = visible & (radii > 0.0)
        self.stats = dict(spheres_drawn=int(keep.sum()), spheres_culled=int((~keep).sum()))
        if not keep.any():
            return
        r = rect[keep]
        quad = np.array([[0, 1], [2, 1], [2, 3], [0, 1], [2, 3], [0, 3]])  # (x index, y index) per vertex
        corners = np.stack([r[:, quad[:, 0]], r[:, quad[:, 1]]], axis=2).reshape(-1, 2)
        sphere = np.repeat(np.concatenate([centres[keep], radii[keep, None]], axis=1), 6, axis=0)
        batch = util.make_batch('TRIS', {"corner": ('F32', corners), "sphere": ('F32', sphere),
                                         "reach": ('F32', np.repeat(reach[keep], 6))})
        if self._fb_target is not ao_map:  # the AO map is reallocated only on resize
            self._fb, self._fb_target = gpu.types.GPUFrameBuffer(color_slots=ao_map), ao_map
        with util.scoped_state(), self._fb.bind():
            util.set_overlay_pass_state(ao_map.width, ao_map.height, blend='MULTIPLY')
            shader = far_shader(falloff)
            shader.bind()
            shader.uniform_float("max_distance", max_distance)
            shader.uniform_float("near_radius", near_radius)
            shader.image("low_position", low_gbuffer.position)
            shader.image("low_normal", low_gbuffer.normal)
            batch.draw(shader)

    def _release(self) -> None:
        self._fb = self._fb_target = None
