# SPDX-License-Identifier: GPL-3.0-or-later
"""Procedural test scenes with known AO (pure numpy triangle soups with UVs).

Analytic answers (cosine-weighted accessibility A = 1 - occluded fraction):
- a lone plane: A = 1 on top.
- a sphere of radius R resting on a plane: at distance D from the sphere's centre a plane
  point sees the sphere with form factor (R/D)^2 cos(theta), cos(theta) = R/D, so
  A = 1 - (R/D)^3.
- a floor meeting a vertical wall that is infinite within reach: at distance x from the
  wall, with max distance d (no falloff) the occluded directions map (Malley) to the disk
  segment y > x/d, so A = 1 - (acos(s) - s sqrt(1 - s^2)) / pi with s = min(x/d, 1);
  unlimited distance gives A = 1/2.
"""
from __future__ import annotations

import numpy as np

from .directions import malley_quadrature
from .geometry import TriangleSoup
from .kernels import occlusion_weight


def grid_plane(size: float, cells: int, z: float = 0.0, uv_lo: float = 0.0, uv_hi: float = 1.0,
               name: str = "plane") -> TriangleSoup:
    """Square [-size/2, size/2]^2 at height z facing +z, cells x cells quads, UVs mapped
    linearly onto [uv_lo, uv_hi]^2."""
    t = np.linspace(0.0, 1.0, cells + 1)
    gx, gy = np.meshgrid(t, t, indexing="xy")
    i, j = np.meshgrid(np.arange(cells), np.arange(cells), indexing="xy")
    i, j = i.ravel(), j.ravel()
    corners = lambda di, dj: np.stack([gx[j + dj, i + di], gy[j + dj, i + di]], axis=1)  # noqa: E731
    a, b, c, d = corners(0, 0), corners(1, 0), corners(1, 1), corners(0, 1)
    uv = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    xy = (uv - 0.5) * size
    pos = np.concatenate([xy, np.full(xy.shape[:2] + (1,), z)], axis=2)
    return TriangleSoup(pos, uv_lo + uv * (uv_hi - uv_lo), name=name)


def uv_sphere(radius: float, centre, segments: int = 64, rings: int = 32, name: str = "sphere") -> TriangleSoup:
    """Closed UV sphere (outward normals, counter-clockwise), UVs equirectangular."""
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    pts = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    uvs = np.stack([ph / (2 * np.pi), 1.0 - th / np.pi], axis=-1)
    tris, tuv = [], []
    for r in range(rings):
        for s in range(segments):
            a, b, c, d = (r, s), (r + 1, s), (r + 1, s + 1), (r, s + 1)
            for tri in ((a, b, c), (a, c, d)):
                # Welded: the seam column and each pole share bit-identical positions,
                # so the sphere is closed (core.geometry.is_closed_surface).
                p = np.array([pts[k[0], 0 if k[0] in (0, rings) else k[1] % segments] for k in tri])
                if np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0])) < 1e-12:
                    continue  # pole triangles collapse
                tris.append(p)
                tuv.append([uvs[k] for k in tri])
    return TriangleSoup(np.array(tris) * radius + np.asarray(centre, float), np.array(tuv), name=name)


def torus(major: float, minor: float, centre, segments: int = 48, sides: int = 24,
          name: str = "torus") -> TriangleSoup:
    """Closed torus around the z axis (outward normals, counter-clockwise). Corners come
    from one shared vertex array, so welded positions are bit-identical across the UV seams
    and the surface tests as closed; UVs wrap once around each circle."""
    u = np.arange(segments) * (2.0 * np.pi / segments)
    v = np.arange(sides) * (2.0 * np.pi / sides)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    ring = major + minor * np.cos(vv)
    verts = np.stack([ring * np.cos(uu), ring * np.sin(uu), minor * np.sin(vv)], axis=-1)
    i, j = np.meshgrid(np.arange(segments), np.arange(sides), indexing="ij")
    i, j = i.ravel(), j.ravel()
    i1, j1 = (i + 1) % segments, (j + 1) % sides
    quad = lambda a, b: verts[a, b]  # noqa: E731
    uvq = lambda a, b: np.stack([a / segments, b / sides], axis=-1)  # noqa: E731
    # (i, j) -> (i+1, j) -> (i+1, j+1) is counter-clockwise seen from outside.
    pos = np.concatenate([np.stack([quad(i, j), quad(i1, j), quad(i1, j1)], 1),
                          np.stack([quad(i, j), quad(i1, j1), quad(i, j1)], 1)])
    uv = np.concatenate([np.stack([uvq(i, j), uvq(i + 1, j), uvq(i + 1, j + 1)], 1),
                         np.stack([uvq(i, j), uvq(i + 1, j + 1), uvq(i, j + 1)], 1)])
    return TriangleSoup(pos + np.asarray(centre, float), uv, name=name)


def box(lo, hi, name: str = "box") -> TriangleSoup:
    """Closed axis-aligned box [lo, hi] (outward normals, counter-clockwise, welded corners),
    each face mapped onto the whole UV square."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    corner = lambda i: np.where([(i >> a) & 1 for a in range(3)], hi, lo)  # noqa: E731
    # Each face: four corner indices (bit a = upper on axis a), counter-clockwise from outside.
    faces = [(0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)]
    tris, uvs = [], []
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    for f in faces:
        for a, b, c in ((0, 1, 2), (0, 2, 3)):
            tris.append([corner(f[a]), corner(f[b]), corner(f[c])])
            uvs.append([square[a], square[b], square[c]])
    return TriangleSoup(np.array(tris), np.array(uvs, float), name=name)


def wall(width: float, height: float, x: float, name: str = "wall") -> TriangleSoup:
    """Vertical rectangle in the plane x = const, facing -x (towards the floor at x < wall),
    spanning y in [-width/2, width/2], z in [0, height]."""
    y0, y1 = -width / 2, width / 2
    a, b, c, d = [x, y0, 0.0], [x, y1, 0.0], [x, y1, height], [x, y0, height]
    # Counter-clockwise seen from -x: normal (b - a) x (c - a) points to -x.
    pos = np.array([[a, c, b], [a, d, c]], dtype=float)
    uv = np.array([[[0, 0], [1, 1], [1, 0]], [[0, 0], [0, 1], [1, 1]]], dtype=float)
    return TriangleSoup(pos, uv, name=name)


def sphere_on_plane_accessibility(distance_to_centre: np.ndarray, radius: float) -> np.ndarray:
    """A = 1 - (R/D)^3 for plane points at distance D from the resting sphere's centre."""
    d = np.maximum(np.asarray(distance_to_centre, float), radius)
    return 1.0 - (radius / d) ** 3


def wall_accessibility(distance_to_wall: np.ndarray, max_distance: float, falloff: str = "none",
                       quadrature: int = 4096) -> np.ndarray:
    """Floor next to an infinite wall. Exact for falloff 'none'; for 'wendland' the 1D
    integral over the disk's y coordinate is evaluated by the midpoint rule (error < 1e-6).

    Under Malley's mapping a unit-disk point (X, Y) is the direction with cos(theta) =
    sqrt(1 - X^2 - Y^2); the ray towards the wall (Y > 0) hits it at t = x / Y, so
    A = 1 - (1/pi) * integral_0^1 rho(x / Y) * 2 sqrt(1 - Y^2) dY.
    """
    x = np.atleast_1d(np.asarray(distance_to_wall, float))
    if max_distance <= 0.0:
        return np.full_like(x, 0.5)
    if falloff == "none":
        s = np.clip(x / max_distance, 0.0, 1.0)
        return 1.0 - (np.arccos(s) - s * np.sqrt(1.0 - s * s)) / np.pi
    # Once per distinct distance: a map's texels repeat a few distances many times.
    distinct, index = np.unique(x, return_inverse=True)
    y = (np.arange(quadrature) + 0.5) / quadrature
    chord = 2.0 * np.sqrt(1.0 - y * y)
    rho = occlusion_weight(distinct[:, None] / y[None, :], max_distance, falloff)
    return (1.0 - (rho * chord).sum(axis=1) / quadrature / np.pi)[index.reshape(x.shape)]


def finite_wall_accessibility(distance_to_wall: np.ndarray, lateral: np.ndarray, width: float,
                              height: float) -> np.ndarray:
    """(N,) accessibility of floor points next to a finite wall (unlimited distance), exactly.
    The wall stands at distance x (N,) in front of the point, spans |y - lateral| <= width / 2
    sideways and 0 <= z <= height.

    With unlimited distance the occlusion is the wall's point-to-polygon form factor, given by
    Lambert's contour formula: F = (1/2pi) |sum_i theta_i n . (v_i x v_i+1)/|v_i x v_i+1||
    over the rectangle's edges, v_i its corners as seen from the point, theta_i the angle each
    edge spans, n the floor's normal (exact for a polygon above the point's horizon, as the
    wall is). The edge along the floor spans its angle in the horizon plane and counts whole."""
    x = np.atleast_1d(np.asarray(distance_to_wall, float))
    y0 = np.broadcast_to(np.asarray(lateral, float), x.shape)
    left, right = -width / 2 - y0, width / 2 - y0  # the wall's sides, relative to the point
    zeros = np.zeros_like(x)
    # Corners (N, 4, 3) in (sideways, forward, up), in order around the rectangle.
    corners = np.stack([np.stack([left, x, zeros], -1), np.stack([right, x, zeros], -1),
                        np.stack([right, x, zeros + height], -1), np.stack([left, x, zeros + height], -1)], 1)
    v = corners / np.linalg.norm(corners, axis=-1, keepdims=True)
    w = np.roll(v, -1, axis=1)
    cross = np.cross(v, w)
    sine = np.linalg.norm(cross, axis=-1)
    theta = np.arctan2(sine, (v * w).sum(-1))
    up = np.divide(cross[..., 2], sine, out=np.zeros_like(sine), where=sine > 0.0)
    return 1.0 - np.abs((theta * up).sum(axis=1)) / (2.0 * np.pi)


def sphere_on_plane_kernel_accessibility(rho: np.ndarray, radius: float, max_distance: float,
                                         quadrature: int = 256) -> np.ndarray:
    """Accessibility of plane points at horizontal distance rho from the contact point of a
    sphere of `radius` resting on the plane, with the Wendland kernel on the hit distance
    (support max_distance): 1 - (1/pi) int w(t(omega)) cos dA over the hemisphere, with the
    exact ray-sphere distance t and a quadrature x quadrature midpoint rule on Malley's disk
    (cosine-weighted). With w = 1 (max_distance -> inf) it reduces to 1 - (R/D)^3."""
    rho = np.atleast_1d(np.asarray(rho, np.float64))
    d = malley_quadrature(quadrature)
    out = np.empty(len(rho))
    for i, x in enumerate(rho):
        oc = np.array([x, 0.0, -radius])  # origin minus sphere centre (centre at (0, 0, R))
        b = d @ oc
        disc = b * b - (oc @ oc - radius * radius)
        t = -b - np.sqrt(np.maximum(disc, 0.0))
        hit = (disc > 0.0) & (t > 0.0)
        w = np.where(hit, occlusion_weight(np.where(hit, t, np.inf), max_distance, "wendland"), 0.0)
        out[i] = 1.0 - w.mean()
    return out
