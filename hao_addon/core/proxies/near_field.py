# SPDX-License-Identifier: GPL-3.0-or-later
"""Image-space near-field AO (Shanmugam & Arikan, section 4): camera quantities and a numpy
mirror of gpu_shaders/near_field.comp, which the tests compare with the GPU pass.

For a receiver P (normal n) the pass gathers M pixels q of the disk of radius r'_far (the
projection of r_far at P) from two layers, the front-face G-buffer and the nearest back
faces. Each pixel stands for a surface patch Q (normal n_q) of area s^2 / |n_q . v_q|
(s: the world size of a pixel at Q's depth, v_q: the direction to the eye). The paper reconstructs a pixel as a sphere pushed
back along -n; here the sphere's cross-section equals the patch's area seen from P,
area * (n_q . (P - Q) / |P - Q|), so that A_psi / pi of a small sphere is the patch's
differential form factor, and patches facing away from P are skipped: a ray from P through
a closed occluder enters through exactly one facing patch, so the two layers do not count
it twice. A sample's occlusion (not its sphere) is weighted by (disk pixels) / M: occlusion
is not linear in a sphere's size, so inflating the sphere would bias the estimate low. The
sum over a convex occluder then tends to its form factor (the sphere-on-plane test checks
1 - (R/D)^3). Occlusion is clamped at 1."""
from __future__ import annotations

import numpy as np

from ..kernels import occlusion_weight

from ..hao.ao_pattern import GOLDEN_FRACTION, pcg3d


def camera_terms(view_proj: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """From a (4, 4) world -> clip matrix: its row 3 (clip w of a point: the depth for a
    perspective camera), the vertical focal scale (projection[1][1]; world pixel size at
    clip w is 2 w / (scale * height)), and the eye as (x, y, z, 1), or for an orthographic
    camera the direction towards it as (x, y, z, 0)."""
    m = np.asarray(view_proj, np.float64)
    row3 = m[3].copy()
    forward = row3[:3]
    if np.linalg.norm(forward) > 1e-12:  # perspective: w = -z_view = forward . x + c
        back = forward / np.linalg.norm(forward)
        y = m[1, :3]
        scale = float(np.sqrt(max(y @ y - (y @ back) ** 2, 0.0)))
        eye = np.linalg.solve(m[[0, 1, 3], :3], -m[[0, 1, 3], 3])
        return row3, scale, np.append(eye, 1.0)
    z = m[2, :3]
    toward = -z / np.linalg.norm(z)  # clip z grows away from the camera
    return row3, float(np.linalg.norm(m[1, :3])), np.append(toward, 0.0)


def near_field_reference(front_pos: np.ndarray, front_nrm: np.ndarray, back_pos: np.ndarray, back_nrm: np.ndarray,
                         picks: np.ndarray, view_proj: np.ndarray, r_far: float, samples: int,
                         max_distance: float = 0.0, falloff: str = "wendland") -> np.ndarray:
    """Accessibility at the G-buffer pixels `picks` ((n, 2) integer x, y). G-buffers: (H, W, 4)
    position (w: coverage) and normal arrays, row 0 at the bottom, as the GPU pass reads them.
    r_far: the radius sampled; each sample's occlusion is weighted by the AO's distance
    falloff (kernels.occlusion_weight with max_distance, 0 = unlimited) at its distance."""
    row3, proj_scale, eye = camera_terms(view_proj)
    h, w = front_pos.shape[:2]
    px, py = picks[:, 0], picks[:, 1]
    p = front_pos[py, px, :3].astype(np.float64)
    n = front_nrm[py, px, :3].astype(np.float64)
    w_p = p @ row3[:3] + row3[3]
    radius_px = r_far * proj_scale * 0.5 * h / np.maximum(w_p, 1e-6)
    weight = np.maximum(np.pi * radius_px ** 2 / samples, 1.0)
    key = np.floor(p.astype(np.float32) / np.float32(0.125 * r_far)).astype(np.int64).astype(np.uint32)
    jit = pcg3d(key + np.array([7, 11, 13], np.uint32))[:, :2].astype(np.float64) / 4294967296.0
    occ = np.zeros(len(p))
    layers = ((front_pos, front_nrm), (back_pos, back_nrm))
    for i in range(samples):
        rr = np.sqrt((i + jit[:, 1]) / samples) * radius_px
        phi = 2.0 * np.pi * np.mod(i * GOLDEN_FRACTION + jit[:, 0], 1.0)
        qx = px + np.floor(np.cos(phi) * rr + 0.5).astype(int)
        qy = py + np.floor(np.sin(phi) * rr + 0.5).astype(int)
        inside = (qx >= 0) & (qy >= 0) & (qx < w) & (qy < h)
        qxc, qyc = np.clip(qx, 0, w - 1), np.clip(qy, 0, h - 1)
        for pos, nrm in layers:
            qp = pos[qyc, qxc].astype(np.float64)
            nq = nrm[qyc, qxc, :3].astype(np.float64)
            v = p - qp[:, :3]
            d = np.linalg.norm(v, axis=1)
            facing = (nq * v).sum(1) / np.maximum(d, 1e-12)
            ok = inside & (qp[:, 3] != 0.0) & (d <= r_far) & (d >= 1e-6) & (facing > 0.0)
            w_q = qp[:, :3] @ row3[:3] + row3[3]
            pixel = 2.0 * w_q / (proj_scale * h)
            to_eye = (eye[:3] - qp[:, :3]) if eye[3] > 0.5 else np.broadcast_to(eye[:3], qp[:, :3].shape)
            to_eye = to_eye / np.maximum(np.linalg.norm(to_eye, axis=1, keepdims=True), 1e-30)
            patch = pixel ** 2 / np.maximum(np.abs((nq * to_eye).sum(1)), 0.2)
            r = np.sqrt(np.maximum(patch * facing, 0.0) / np.pi)
            pc = qp[:, :3] - nq * r[:, None] - p
            dist = np.linalg.norm(pc, axis=1)
            sin_t = np.minimum(r / np.maximum(dist, np.maximum(r, 1e-300)), 1.0)
            solid_angle = 2.0 * np.pi * (1.0 - np.sqrt(np.maximum(1.0 - sin_t ** 2, 0.0)))
            cos_a = np.maximum((n * pc).sum(1) / np.maximum(dist, 1e-12), 0.0)
            falloff_w = occlusion_weight(d, max_distance, falloff)
            occ += weight * falloff_w * np.where(ok, np.where(dist > 0.0, np.minimum(solid_angle * cos_a / np.pi, 1.0),
                                                              1.0), 0.0)
    return 1.0 - np.minimum(occ, 1.0)
