# SPDX-License-Identifier: GPL-3.0-or-later
"""Bent-normal maps in the spaces pipelines read (pure numpy): tangent space (MikkTSpace, as
Blender's Normal Map node decodes it) or object space, encoded 0.5 + 0.5 n.

Blender's Normal Map node decodes a tangent-space texel c as normalize(c.x T + c.y B + c.z N)
with the interpolated tangent T, the interpolated normal N and B = sign * cross(N, T) (the
MikkTSpace bitangent sign of the corners). Blender's own normal bake writes the inverse:
c = normalize([T B N]^-1 n) (render/intern/bake.cc, RE_bake_normal_world_to_tangent), so that
decoding gives back n exactly; so does this module. DirectX (Y-) maps flip the green channel.
"""
from __future__ import annotations

import numpy as np

from ..geometry import unit_vectors
from ..setting_spec import Choice

# The output's choices, one definition for the panel (operators/properties.py) and the CLI.
SPACE_CHOICES = (
    Choice("tangent", "Tangent", "the baked UV map's MikkTSpace, as Blender's Normal Map node reads it"),
    Choice("object", "Object", "the object's own axes"),
)
CONVENTION_CHOICES = (
    Choice("opengl", "OpenGL (Y+)", "green is +Y (Blender, glTF)"),
    Choice("directx", "DirectX (Y-)", "green is -Y"),
)
SPACES = tuple(c.value for c in SPACE_CHOICES)
CONVENTIONS = tuple(c.value for c in CONVENTION_CHOICES)



def tangent_frames(face: np.ndarray, bary: np.ndarray, tangents: np.ndarray, normals: np.ndarray
                   ) -> np.ndarray:
    """(m, 3, 3) rows T, B, N at m surface points (face (m,), bary (m, 3)): tangents (F, 3, 4)
    per corner (xyz and the bitangent sign, the space the normals are in), normals (F, 3, 3)
    the corner shading normals. T and N are interpolated, not normalized (as Blender's
    shader interpolates them), B = sign * cross(N, T)."""
    t = np.einsum("mk,mkd->md", bary, tangents[face, :, :3])
    n = np.einsum("mk,mkd->md", bary, normals[face])
    sign = np.where(tangents[face, 0, 3] < 0.0, -1.0, 1.0)
    b = sign[:, None] * np.cross(n, t)
    return np.stack([t, b, n], axis=1)


def to_tangent_space(vectors: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """(m, 3) unit tangent-space coordinates c of world vectors (m, 3) in frames (m, 3, 3)
    (rows T, B, N): normalize(c.x T + c.y B + c.z N) = the vector. A degenerate frame (no
    UV derivative) gives +Z, the flat normal."""
    basis = np.transpose(frames, (0, 2, 1))  # columns T, B, N
    det = np.linalg.det(basis)
    ok = np.abs(det) > 1e-12
    out = np.tile([0.0, 0.0, 1.0], (len(vectors), 1))
    if ok.any():
        out[ok] = unit_vectors(np.linalg.solve(basis[ok], vectors[ok][..., None])[..., 0])
    return out


def to_object_space(vectors: np.ndarray, linear: np.ndarray) -> np.ndarray:
    """(..., 3) unit world normals -> the object's space of linear map (3, 3) (object to
    world): normals map to world with the inverse transpose, so back with the transpose."""
    return unit_vectors(np.asarray(vectors, np.float64) @ np.asarray(linear, np.float64))


def encode(vectors: np.ndarray, convention: str = "opengl") -> np.ndarray:
    """(..., 3) unit vectors -> (..., 4) RGBA in [0, 1]: 0.5 + 0.5 n, alpha 1; DirectX flips Y."""
    if convention not in CONVENTIONS:
        raise ValueError(f"convention must be one of {CONVENTIONS}, got {convention!r}")
    v = np.asarray(vectors, np.float64).copy()
    if convention == "directx":
        v[..., 1] = -v[..., 1]
    rgba = np.ones(v.shape[:-1] + (4,))
    rgba[..., :3] = 0.5 + 0.5 * v
    return rgba


def bent_normal_map(bent: np.ndarray, covered: np.ndarray, filled: np.ndarray, margin: int, uvs: np.ndarray,
                    space: str, convention: str, linear: np.ndarray, tangents: np.ndarray | None = None,
                    normals: np.ndarray | None = None) -> np.ndarray:
    """(H, W, 4) float RGBA bent-normal image of a bake: bent (H, W, 3) world unit vectors
    (BakeResult.bent_normals), covered / filled (H, W) bool its masks; uvs (F, 3, 2) the
    target's UV triangles; linear (3, 3) its object-to-world map; tangent space needs
    tangents (F, 3, 4) and the corner shading normals (F, 3, 3), in world space.
    Tangent-space texels are converted where covered and grown over the margin in tangent
    space (margin texels have no surface point of their own); outside filled a texel is the
    unbent normal (+Z) in tangent space, zero (grey) in object space."""
    from .seams import finalize_vectors
    from .uv_raster import texel_surface_samples

    if space not in SPACES:
        raise ValueError(f"space must be one of {SPACES}, got {space!r}")
    if space == "object":
        return encode(np.where(filled[..., None], to_object_space(bent, linear), 0.0), convention)
    size = covered.shape[0]
    face, bary, _hits = texel_surface_samples(np.asarray(uvs, np.float64), size)
    valid = covered & (face >= 0)
    grid = np.zeros(covered.shape + (3,))
    frames = tangent_frames(face[valid], bary[valid], np.asarray(tangents, np.float64),
                            np.asarray(normals, np.float64))
    grid[valid] = to_tangent_space(bent[valid].astype(np.float64), frames)
    grown = finalize_vectors(grid, valid, filled, margin).astype(np.float64)
    grown[~filled] = (0.0, 0.0, 1.0)
    return encode(grown, convention)
