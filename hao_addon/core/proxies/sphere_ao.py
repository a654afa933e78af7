# SPDX-License-Identifier: GPL-3.0-or-later
"""Ambient occlusion of sphere occluders (Shanmugam & Arikan 2007, section 5), pure numpy.

The paper's occlusion of a receiver (P, n) by a sphere <C, r> (equations 2 and 3) is
    A_psi = S_Omega(P, C, r) * max(n . PC_hat, 0),   S_Omega = 2 pi (1 - cos(asin(r / |PC|))),
the solid angle of the sphere's cap times the cosine towards its centre. Divided by pi it is
comparable with cosine-weighted occlusion (accessibility = 1 - occlusion). For a sphere wholly
above the horizon the exact value is sin^2(theta) cos(alpha) (the sphere's form factor); the
paper's 2 (1 - cos theta) cos(alpha) is that times 2 / (1 + cos theta): equal for small or
distant spheres, up to 2x for a sphere close to the receiver. Spheres partly below the horizon are where the
formula is only an approximation (tests/test_spheres.py measures it against quadrature).
Inside a sphere. Section 6 sets A_psi = 1 there to keep the near and far passes apart. On a
character, receivers lie on the surface of their own cluster, about half of them inside its
proxy sphere, and a constant would switch them between open and fully dark across the sphere's
boundary. Here the distance is clamped to r instead: the cap becomes the whole hemisphere
(S = 2 pi) and the occlusion min(2 max(n . PC_hat, 0), 1), continuous at the boundary: a
receiver facing away from the centre (an outer surface) is open, one facing it (inside a
fold) is dark.

d_far (equation 5): the distance at which a sphere of radius r facing the receiver head-on
occludes exactly epsilon:  d_far = r / sin(acos(1 - epsilon / (2 pi))).
"""
from __future__ import annotations

import numpy as np

from ..kernels import occlusion_weight


def far_distance(radius: np.ndarray, epsilon: float) -> np.ndarray:
    """d_far of equation 5 for sphere radii (any shape); epsilon in (0, 2 pi)."""
    if not 0.0 < epsilon < 2.0 * np.pi:
        raise ValueError(f"epsilon must be in (0, 2 pi), got {epsilon}")
    return np.asarray(radius, np.float64) / np.sin(np.arccos(1.0 - epsilon / (2.0 * np.pi)))


def sphere_occlusion(points: np.ndarray, normals: np.ndarray, centre: np.ndarray, radius: float) -> np.ndarray:
    """A_psi / pi (equations 2 and 3, as a fraction of the cosine-weighted hemisphere, at most
    1) of one sphere at (n, 3) receivers with (n, 3) unit normals; inside the sphere the
    distance is clamped to the radius (module docstring)."""
    pc = np.asarray(centre, np.float64) - np.asarray(points, np.float64)
    dist = np.linalg.norm(pc, axis=-1)
    safe = np.maximum(dist, 1e-300)
    sin_t = np.clip(radius / np.maximum(safe, radius), 0.0, 1.0)
    solid_angle = 2.0 * np.pi * (1.0 - np.sqrt(1.0 - sin_t * sin_t))
    cos_a = np.maximum((pc * np.asarray(normals, np.float64)).sum(-1) / safe, 0.0)
    return np.where(dist > 0.0, np.minimum(solid_angle * cos_a / np.pi, 1.0), 1.0)


def sphere_weight(distance: np.ndarray, radius: float, max_distance: float, falloff: str,
                  near_radius: float) -> np.ndarray:
    """What a sphere's occlusion counts at receivers `distance` from its centre (GLSL twin in
    sphere_far.frag): the distance falloff of the AO (kernels.occlusion_weight) at the
    distance halfway into the sphere, max(distance - radius / 2, 0), where most of its
    directions hit; and, with a near field covering occluders within near_radius (near+far),
    only the share of the sphere beyond that radius, clamp((distance + radius - near_radius)
    / (2 radius), 0, 1), so no occluder is counted by both."""
    d = np.asarray(distance, np.float64)
    w = occlusion_weight(np.maximum(d - 0.5 * radius, 0.0), max_distance, falloff)
    if near_radius > 0.0:
        w = w * np.clip((d + radius - near_radius) / (2.0 * max(radius, 1e-30)), 0.0, 1.0)
    return w


def spheres_accessibility(points: np.ndarray, normals: np.ndarray, centres: np.ndarray, radii: np.ndarray,
                          epsilon: float, combine: str = "multiply", max_distance: float = 0.0,
                          falloff: str = "wendland", near_radius: float = 0.0) -> np.ndarray:
    """Accessibility (n,) under K spheres (K, 3), (K,), each cut off beyond its d_far and
    weighted by sphere_weight. combine: 'add' (the paper: 1 - min(sum, 1)) or 'multiply'
    (prod (1 - occlusion_i), occluders treated as independent, which avoids the
    over-occlusion of overlapping ones)."""
    points = np.asarray(points, np.float64)
    reach = far_distance(radii, epsilon)
    total = np.zeros(len(points)) if combine == "add" else np.ones(len(points))
    for c, r, d in zip(np.asarray(centres, np.float64), np.asarray(radii, np.float64), reach):
        dist = np.linalg.norm(points - c, axis=1)
        near = dist <= d
        occ = np.zeros(len(points))
        occ[near] = sphere_occlusion(points[near], normals[near], c, r) * sphere_weight(dist[near], r, max_distance,
                                                                                         falloff, near_radius)
        if combine == "add":
            total += occ
        elif combine == "multiply":
            total *= 1.0 - np.minimum(occ, 1.0)
        else:
            raise ValueError(f"unknown combine '{combine}', expected 'add' or 'multiply'")
    return 1.0 - np.minimum(total, 1.0) if combine == "add" else total


def sphere_occlusion_quadrature(points: np.ndarray, normals: np.ndarray, centre: np.ndarray, radius: float,
                                samples: int = 128) -> np.ndarray:
    """Exact cosine-weighted occluded fraction of one sphere (horizon clipping included) by a
    samples x samples midpoint rule on Malley's disk, for testing sphere_occlusion."""
    from ..hao.ao_pattern import tangent_frames
    from ..directions import malley_quadrature
    local = malley_quadrature(samples)
    normals = np.asarray(normals, np.float64)
    t, s = tangent_frames(normals)
    out = np.empty(len(points))
    for i, p in enumerate(np.asarray(points, np.float64)):
        d = local @ np.stack([t[i], s[i], normals[i]])
        oc = p - np.asarray(centre, np.float64)
        b = d @ oc
        disc = b * b - (oc @ oc - radius * radius)
        hit = (disc > 0.0) & (-b + np.sqrt(np.maximum(disc, 0.0)) > 0.0)
        out[i] = 1.0 if oc @ oc <= radius * radius else hit.mean()
    return out
