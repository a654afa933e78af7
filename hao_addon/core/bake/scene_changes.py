# SPDX-License-Identifier: GPL-3.0-or-later
"""What changed between two bakes of the same target: the state a bake records of its scene
(SceneState) and the spheres holding every change between two states (changed_spheres), for
an incremental re-bake (hao_addon/rebake.py) to bound what each texel can have changed by
(core/bake/change_bound.py).

Each soup (the target or an occluder, by name) is recorded face by face: a 64-bit
fingerprint of what a bake sees of the face (corners, shading normals, alpha) and the face's
bounding sphere. Between two states of a soup with the same face count the changed faces are
those whose fingerprints differ; a soup whose face count changed, appeared or disappeared
changed in all its faces. Each soup's changed faces, before and after, are gathered into a
few spheres (grouped: a sculpted bump gives a small sphere, a moved prop its place before
and after). The settings' key (every setting that changes
pixels) and the target's UVs and face count are recorded whole: a change there re-bakes all.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from ..geometry import TriangleSoup

SPLIT_DEPTH = 4  # octant splits of a soup's changed faces at most (grouped)
_MIX = np.array([0x9E3779B97F4A7C15, 0xBF58476D1CE4E5B9, 0x94D049BB133111EB, 0xD6E8FEB86659FD93,
                 0xA0761D6478BD642F, 0xE7037ED1A0B428DB, 0x8EBC6AF09C88C6E3, 0x589965CC75374CC3,
                 0x1D8E4E27C47D124F], dtype=np.uint64)


@dataclass(frozen=True)
class SoupState:
    """One soup: fingerprints (F,) uint64 and bounding spheres (F, 4) float64 world, per face."""

    fingerprints: np.ndarray
    spheres: np.ndarray


@dataclass(frozen=True)
class SceneState:
    """A bake's scene: the settings' key, the target's layout fingerprint (UVs and face
    count), and every soup's faces by name (the target's under TARGET)."""

    settings_key: str
    target_layout: str
    soups: dict[str, SoupState] = field(default_factory=dict)
    # (target, occluders) as baked, where kept: a re-bake by difference bakes the scene
    # before the edit again where the edit can have changed it (hao_addon/rebake_difference.py).
    scene: tuple | None = field(default=None, compare=False, repr=False)


TARGET = "\0target"  # the target's entry in SceneState.soups (no object is called so)


def _digest(*arrays) -> str:
    h = hashlib.blake2b(digest_size=16)
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str(a.dtype).encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()


def face_fingerprints(*columns: np.ndarray) -> np.ndarray:
    """(F,) uint64 of per-face data (each (F, ...)): equal faces, equal prints; a change of
    any bit of a face's data changes its print (up to 2^-64 collisions)."""
    count = len(columns[0])
    data = np.concatenate([np.ascontiguousarray(c, np.float64).reshape(count, -1) for c in columns], axis=1)
    bits = data.view(np.uint64)
    h = np.full(count, 0xCBF29CE484222325, np.uint64)
    with np.errstate(over="ignore"):
        for j in range(bits.shape[1]):
            h ^= bits[:, j] * _MIX[j % len(_MIX)]
            h ^= h >> np.uint64(31)
            h *= _MIX[(j + 3) % len(_MIX)]
    return h


def face_spheres(positions: np.ndarray) -> np.ndarray:
    """(F, 4) each face's bounding sphere: its corners' box centre and farthest corner."""
    centre = 0.5 * (positions.min(axis=1) + positions.max(axis=1))
    radius = np.linalg.norm(positions - centre[:, None], axis=2).max(axis=1)
    return np.column_stack([centre, radius])


def soup_state(soup: TriangleSoup) -> SoupState:
    """soup's faces: what a bake sees of them (corners, shading normals, and what lets light
    through: alpha per face, its image, where the face samples it)."""
    columns = [soup.positions] + ([soup.normals] if soup.normals is not None else [])
    alpha = soup.alpha
    if alpha is not None:
        columns.append(np.asarray(alpha.constant, np.float64))
        if alpha.image_index is not None:
            images = int(_digest(*alpha.images)[:12], 16)  # an edited image changes its faces
            columns += [np.asarray(alpha.image_index, np.float64) + images, alpha.uvs]
    return SoupState(face_fingerprints(*columns), face_spheres(soup.positions))


def scene_state(target: TriangleSoup, occluders: list[TriangleSoup], settings_key: str) -> SceneState:
    """The state a bake of target (with UVs) against occluders records; settings_key: the
    bake's key of its settings (a change of any setting that changes pixels changes it)."""
    layout = _digest(target.uvs, np.array([len(target.positions)]))
    soups = {TARGET: soup_state(target)}
    for soup in occluders:
        soups[soup.name] = soup_state(soup)
    return SceneState(settings_key, layout, soups, (target, list(occluders)))


def changed_faces(before: SceneState, after: SceneState) -> list[np.ndarray]:
    """The spheres (m, 4) of the changed faces of each soup, before and after the edit (one
    array per soup and side)."""
    out = []
    for name in sorted(before.soups.keys() | after.soups.keys()):
        old, new = before.soups.get(name), after.soups.get(name)
        if old is None or new is None or len(old.fingerprints) != len(new.fingerprints):
            out += [s.spheres for s in (old, new) if s is not None]
            continue
        differ = old.fingerprints != new.fingerprints
        out += [side.spheres[differ] for side in (old, new) if differ.any()]
    return [part for part in out if len(part)]


def enclosing(spheres: np.ndarray) -> np.ndarray:
    """(4,) a sphere holding spheres (m, 4): their box's centre, the farthest reach from it."""
    centre = 0.5 * ((spheres[:, :3] - spheres[:, 3:]).min(0) + (spheres[:, :3] + spheres[:, 3:]).max(0))
    return np.array([*centre, float((np.linalg.norm(spheres[:, :3] - centre, axis=1) + spheres[:, 3]).max())])


def grouped(spheres: np.ndarray, depth: int = SPLIT_DEPTH) -> np.ndarray:
    """(k, 4) spheres holding spheres (m, 4): one, or split by octants of their box (down to
    depth levels) where the parts' sum of squared radii is smaller: the bound an edit puts on
    a texel grows with r^2 of each sphere (change_bound), so a prop moved across the scene is
    two spheres and a bump on a large mesh a small one, not a sphere over both."""
    whole = enclosing(spheres)
    if depth == 0 or len(spheres) == 1:
        return whole[None]
    mid = 0.5 * (spheres[:, :3].min(0) + spheres[:, :3].max(0))
    octant = ((spheres[:, :3] > mid) * np.array([1, 2, 4])).sum(axis=1)
    parts = [grouped(spheres[octant == k], depth - 1) for k in np.unique(octant)]
    split = np.concatenate(parts)
    return split if (split[:, 3] ** 2).sum() < whole[3] ** 2 else whole[None]


def changed_spheres(before: SceneState, after: SceneState) -> np.ndarray:
    """(k, 4) spheres, world, that hold every change from before to after: each soup's
    changed faces before and after, grouped."""
    parts = [grouped(part) for part in changed_faces(before, after)]
    return np.concatenate(parts) if parts else np.zeros((0, 4))
